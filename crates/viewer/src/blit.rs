//! Paints the picture into egui's frame with a plain textured triangle: one texture sample
//! per window pixel. egui's own image shader converts colours between gamma and linear space
//! per pixel, a large share of each UI frame on a software GPU.

use eframe::{egui, egui_wgpu};

const SHADER: &str = r#"
@group(0) @binding(0) var picture: texture_2d<f32>;
@group(0) @binding(1) var filtering: sampler;

override SRGB_TARGET: bool = false;

struct Out {
    @builtin(position) pos: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> Out {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    var out: Out;
    out.pos = vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
    out.uv = vec2<f32>(x, y);
    return out;
}

@fragment
fn fs_main(in: Out) -> @location(0) vec4<f32> {
    let c = textureSample(picture, filtering, in.uv);
    if (SRGB_TARGET) {
        // The picture holds display (sRGB) values; an sRGB target encodes them on write.
        let lo = c.rgb / 12.92;
        let hi = pow((c.rgb + 0.055) / 1.055, vec3<f32>(2.4));
        return vec4<f32>(select(hi, lo, c.rgb <= vec3<f32>(0.04045)), 1.0);
    }
    return vec4<f32>(c.rgb, 1.0);
}
"#;

/// The blit pipeline for egui's target, kept in egui_wgpu's callback resources.
pub struct Blit {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

impl Blit {
    /// None if the device rejects it (then egui paints the picture itself).
    pub fn new(device: &wgpu::Device, target: wgpu::TextureFormat) -> Option<Self> {
        let (made, error) = fourfold::platform::validated(device, || {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("fourfold picture blit"),
                source: wgpu::ShaderSource::Wgsl(SHADER.into()),
            });
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fourfold picture blit"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: true },
                            view_dimension: wgpu::TextureViewDimension::D2,
                            multisampled: false,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                        count: None,
                    },
                ],
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("fourfold picture blit"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let constants = [("SRGB_TARGET", if target.is_srgb() { 1.0 } else { 0.0 })];
            let pipeline = fourfold::render::gpu::fullscreen_pipeline(
                device,
                fourfold::render::gpu::Fullscreen {
                    label: "fourfold picture blit",
                    module: &module,
                    layout: &pipeline_layout,
                    target: wgpu::ColorTargetState {
                        format: target,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    },
                    fragment: "fs_main",
                    cache: None,
                },
                &constants,
            );
            let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("fourfold picture blit"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            });
            Self {
                pipeline,
                layout,
                sampler,
            }
        });
        error.is_none().then_some(made)
    }

    /// The bind group that shows `view`.
    pub fn bind(&self, device: &wgpu::Device, view: &wgpu::TextureView) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fourfold picture blit"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        })
    }
}

/// One layer of the picture: the whole texture maps onto `full` (window points), and only the
/// part inside the callback's rectangle (the layer) is drawn.
pub struct Layer {
    pub bind_group: wgpu::BindGroup,
    pub full: egui::Rect,
}

impl egui_wgpu::CallbackTrait for Layer {
    fn paint(
        &self,
        info: egui::PaintCallbackInfo,
        render_pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let Some(blit) = resources.get::<Blit>() else {
            return;
        };
        let ppp = info.pixels_per_point;
        let [sw, sh] = info.screen_size_px.map(|v| v as f32);
        // The texture spans `full`; the scissor keeps the drawing to the layer (clipped).
        let (x, y) = (self.full.min.x * ppp, self.full.min.y * ppp);
        let (w, h) = (self.full.width() * ppp, self.full.height() * ppp);
        if w < 1.0 || h < 1.0 {
            return;
        }
        render_pass.set_viewport(x, y, w, h, 0.0, 1.0);
        let clip = info.viewport.intersect(info.clip_rect);
        let x0 = (clip.min.x * ppp).round().clamp(0.0, sw);
        let y0 = (clip.min.y * ppp).round().clamp(0.0, sh);
        let x1 = (clip.max.x * ppp).round().clamp(0.0, sw);
        let y1 = (clip.max.y * ppp).round().clamp(0.0, sh);
        if x1 <= x0 || y1 <= y0 {
            return;
        }
        render_pass.set_scissor_rect(x0 as u32, y0 as u32, (x1 - x0) as u32, (y1 - y0) as u32);
        render_pass.set_pipeline(&blit.pipeline);
        render_pass.set_bind_group(0, &self.bind_group, &[]);
        render_pass.draw(0..3, 0..1);
    }
}
