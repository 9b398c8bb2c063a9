//! The GPU ray caster on wgpu: a pipeline per shader (per formula), the hierarchy in a
//! storage buffer (per tree), and the frame's settings (`Uniforms`) in a small read-only
//! storage buffer rather than a uniform buffer (lavapipe rebuilds a shader whose loops a
//! uniform buffer steers at every write: docs/architecture.md, "The GPU"). Offscreen
//! rendering returns an RGBA image; the viewer draws with the same pipeline into its own
//! target.

use std::sync::{Arc, Mutex};

use bytemuck::Zeroable;
use wgpu::util::DeviceExt;

use crate::gpu_layout::{BoxRecord, NodeBounds, SphereNode};
use crate::tree::Hierarchy;

use super::codegen::Shader;
use super::tiles::TileLists;
use super::uniforms::{FLAG_CERTIFIED, FLAG_RANDOM, FLAG_SLAB, FLAG_SLICE, Tiling, Uniforms};

/// Storage buffers the ray caster's shader reads (bindings 0-4).
pub const STORAGE_BUFFERS: u32 = 7;

/// The colour format the ray caster writes.
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found ({0}). On Linux without a GPU, install Mesa's software Vulkan \
         driver: apt-get install -y mesa-vulkan-drivers (or render with --cpu)"
    )]
    NoAdapter(String),
    #[error("the GPU device could not be created: {0}")]
    Device(String),
    #[error("the GPU rejected the shader or pipeline: {0}")]
    Pipeline(String),
    #[error(
        "the tree has {nodes} nodes (a {bytes}-byte buffer), over this GPU's storage-buffer limit of {limit} bytes; lower max_level or node_budget"
    )]
    TooLarge {
        nodes: usize,
        bytes: u64,
        limit: u64,
    },
    #[error("reading the picture back from the GPU failed: {0}")]
    Readback(String),
    #[error(
        "a {width}x{height} image is over this GPU's limit ({reason}); use a smaller --size, \
         at most {max_side}x{max_side} here, or render with --cpu"
    )]
    ImageTooLarge {
        width: u32,
        height: u32,
        max_side: u32,
        reason: String,
    },
}

/// Whether this device can draw and read back a `width`×`height` picture: its sides within
/// the largest texture side, and its read-back buffer (rows padded to 256 bytes) within the
/// largest buffer.
pub fn check_image_size(width: u32, height: u32, limits: &wgpu::Limits) -> Result<(), GpuError> {
    let max_side = limits.max_texture_dimension_2d;
    let row = (u64::from(width) * 4).div_ceil(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT))
        * u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let bytes = row * u64::from(height);
    let reason = if width > max_side || height > max_side {
        format!("its largest texture side is {max_side} pixels")
    } else if bytes > limits.max_buffer_size {
        format!(
            "reading it back takes {bytes} bytes, over its largest buffer of {} bytes",
            limits.max_buffer_size
        )
    } else {
        return Ok(());
    };
    // The largest square within both limits.
    let by_buffer = ((limits.max_buffer_size / 4) as f64).sqrt() as u32 / 64 * 64;
    Err(GpuError::ImageTooLarge {
        width,
        height,
        max_side: max_side.min(by_buffer.max(1)),
        reason,
    })
}

/// A device and queue, with a description of the adapter. Cloning shares them.
#[derive(Clone)]
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter: String,
}

impl Gpu {
    /// How many words tile lists (offsets and entries) may hold on this device: MAX_ENTRIES,
    /// or less where the device's storage-buffer limit is lower.
    pub fn tile_entry_budget(&self) -> usize {
        let words = self.device.limits().max_storage_buffer_binding_size / 4;
        usize::try_from(words).map_or(super::tiles::MAX_ENTRIES, |w| {
            w.min(super::tiles::MAX_ENTRIES)
        })
    }

    /// Opens the first adapter wgpu finds (any backend, or those named in WGPU_BACKEND),
    /// headless.
    pub fn new() -> Result<Self, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        if limits.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS {
            return Err(GpuError::Device(format!(
                "{} reads at most {} storage buffers in a shader, and the ray caster needs {}; \
                 use a Vulkan, Metal or DX12 adapter (WGPU_BACKEND=vulkan, or on Linux without \
                 a GPU: apt-get install -y mesa-vulkan-drivers), or render with --cpu",
                info.name, limits.max_storage_buffers_per_shader_stage, STORAGE_BUFFERS
            )));
        }
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("fourfold"),
            // Where the adapter has them: GPU timestamps around a frame's pass
            // (`RayCaster::render_rgba_timed`).
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            // The adapter's own limits where fourfold can use more than the defaults: tile
            // lists and trees in storage buffers, and the largest picture (`render --size`).
            required_limits: wgpu::Limits {
                max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
                max_buffer_size: limits.max_buffer_size,
                max_texture_dimension_2d: limits.max_texture_dimension_2d,
                max_storage_buffers_per_shader_stage: STORAGE_BUFFERS,
                ..wgpu::Limits::downlevel_defaults()
            },
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device(e.to_string()))?;
        Ok(Self {
            device,
            queue,
            adapter: format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type),
        })
    }

    /// Whether frames can be timed on the GPU (`RayCaster::render_rgba_timed`).
    pub fn has_timestamps(&self) -> bool {
        self.device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// From a device someone else made (the viewer's).
    pub fn from_parts(device: wgpu::Device, queue: wgpu::Queue, adapter: String) -> Self {
        Self {
            device,
            queue,
            adapter,
        }
    }
}

/// The colour target a [`RayCaster`] draws into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Target {
    pub format: wgpu::TextureFormat,
    /// Blend each pass into the target with a constant weight c: target = c·new + (1−c)·old.
    /// With c = 1/(k+1) on pass k the target holds the running mean of the passes (the
    /// viewer's accumulation); c = 1 overwrites.
    pub accumulate: bool,
}

impl Target {
    /// What `render_rgba` and the CLI use: RGBA8, overwrite.
    pub const OFFSCREEN: Target = Target {
        format: TARGET_FORMAT,
        accumulate: false,
    };
}

/// Where and how one pass draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pass {
    /// x, y, width, height of the pixels to draw; the rest of the target is kept.
    pub region: Option<[u32; 4]>,
    /// The weight c of this pass when the target accumulates (ignored otherwise).
    pub weight: f64,
}

impl Default for Pass {
    fn default() -> Self {
        Self {
            region: None,
            weight: 1.0,
        }
    }
}

/// Where a pixel's leaves come from: the shader's pipeline constant MODE. Each is its own
/// pipeline, so a pixel runs only its mode's code (a SIMD rasterizer runs every branch).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The brute-force baseline: no hierarchy, the domain as one box.
    BruteForce = 0,
    /// The boxes of the pixel's tile list (the default).
    Tiles = 1,
    /// A walk of the whole sphere hierarchy (when no tile lists are bound).
    Walk = 2,
}

/// A compiled pipeline for one shader, and the buffers for one hierarchy.
pub struct RayCaster {
    target: Target,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    /// Per [`Variant`] (`Variant::index`); the tile pipeline for the default settings is
    /// built at once, the others when first used.
    pipelines: [std::sync::OnceLock<wgpu::RenderPipeline>; Variant::COUNT],
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    nodes: wgpu::Buffer,
    /// Per node, `Hierarchy::slope` and `Hierarchy::curvature` (read by the walk and,
    /// through their records, the tiles).
    bounds: wgpu::Buffer,
    tiles: wgpu::Buffer,
    /// The records of the boxes the tile lists index.
    boxes: wgpu::Buffer,
    /// `Uniforms::tiling` for the tile lists bound (zero: walk the hierarchy).
    tiling: Tiling,
    /// The certifying tile lists and their box records (certified pixels), and their
    /// `Uniforms::cert_tiling` (zero: none bound).
    cert_tiles: wgpu::Buffer,
    cert_boxes: wgpu::Buffer,
    cert_tiling: Tiling,
    bind_group: wgpu::BindGroup,
    /// Where the tile lists have boxes to march (`TileLists::rects`); a pass draws the
    /// background elsewhere.
    rects: Vec<[u32; 4]>,
    /// Draws the background (built when first used).
    background: std::sync::OnceLock<wgpu::RenderPipeline>,
}

impl RayCaster {
    /// Builds the pipeline for `shader` (already validated by naga) and uploads `hierarchy`,
    /// for offscreen RGBA8 pictures.
    pub fn new(gpu: &Gpu, shader: &Shader, hierarchy: &Hierarchy) -> Result<Self, GpuError> {
        Self::with_target(gpu, shader, hierarchy, Target::OFFSCREEN)
    }

    /// As [`RayCaster::new`], drawing into `target`.
    pub fn with_target(
        gpu: &Gpu,
        shader: &Shader,
        hierarchy: &Hierarchy,
        target: Target,
    ) -> Result<Self, GpuError> {
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("fourfold ray caster"),
            source: wgpu::ShaderSource::Wgsl(shader.source.as_str().into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fourfold bindings"),
            entries: &(0..STORAGE_BUFFERS).map(storage_entry).collect::<Vec<_>>(),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("fourfold pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let settings = crate::scene::RenderSettings::default();
        let variant = Variant {
            mode: Mode::Tiles,
            slots: slot_tier(settings.hits),
            random: settings.sampling == crate::scene::Sampling::Random,
            section: 0,
            certified: false,
        };
        let pipeline = build_pipeline(device, &module, &pipeline_layout, target, variant);
        if let Some(error) = scope_error(scope) {
            return Err(GpuError::Pipeline(error.to_string()));
        }
        let pipelines: [std::sync::OnceLock<wgpu::RenderPipeline>; Variant::COUNT] =
            std::array::from_fn(|_| std::sync::OnceLock::new());
        let _ = pipelines[variant.index()].set(pipeline);
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fourfold uniforms"),
            size: std::mem::size_of::<Uniforms>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (nodes, bounds) = node_buffers(gpu, hierarchy)?;
        let tiles = view_buffer(gpu, 0);
        let boxes = view_buffer(gpu, 0);
        let cert_tiles = view_buffer(gpu, 0);
        let cert_boxes = view_buffer(gpu, 0);
        let bind_group = bind_group(
            device,
            &layout,
            [
                &uniforms,
                &nodes,
                &tiles,
                &boxes,
                &bounds,
                &cert_tiles,
                &cert_boxes,
            ],
        );
        Ok(Self {
            target,
            module,
            pipeline_layout,
            pipelines,
            layout,
            uniforms,
            nodes,
            bounds,
            tiles,
            boxes,
            tiling: Tiling::zeroed(),
            cert_tiles,
            cert_boxes,
            cert_tiling: Tiling::zeroed(),
            bind_group,
            rects: Default::default(),
            background: Default::default(),
        })
    }

    /// Replaces the hierarchy (a new tree for the same formula: parameters, domain, levels).
    pub fn set_hierarchy(&mut self, gpu: &Gpu, hierarchy: &Hierarchy) -> Result<(), GpuError> {
        (self.nodes, self.bounds) = node_buffers(gpu, hierarchy)?;
        self.rebind(gpu);
        // Old tile lists index the old hierarchy.
        self.set_tiles(gpu, None);
        self.set_cert_tiles(gpu, None);
        Ok(())
    }

    /// Binds per-tile box lists and box records for one view (or none: each pixel walks the hierarchy).
    /// Lists over the device's storage-buffer limit are dropped for the walk. The buffers
    /// are rewritten in place (a new view costs no allocation) and grow when too small;
    /// a pass already submitted keeps what it read.
    pub fn set_tiles(&mut self, gpu: &Gpu, lists: Option<&TileLists>) {
        let Some(l) = usable(gpu, lists) else {
            // The walk reads neither buffer, and draws the whole target.
            self.tiling = Tiling::zeroed();
            return;
        };
        self.tiling = tiling_of(l);
        self.rects = l.rects();
        let grew_tiles = write_or_grow(gpu, &mut self.tiles, bytemuck::cast_slice(&l.data));
        let grew_boxes = write_or_grow(gpu, &mut self.boxes, bytemuck::cast_slice(&l.boxes));
        if grew_tiles || grew_boxes {
            self.rebind(gpu);
        }
    }

    /// Binds the certifying lists of one view: the tile lists of
    /// `Prepared::certifying`'s boxes, which certified pixels search (or none: they search
    /// the marched boxes instead). As [`RayCaster::set_tiles`].
    pub fn set_cert_tiles(&mut self, gpu: &Gpu, lists: Option<&TileLists>) {
        let Some(l) = usable(gpu, lists) else {
            self.cert_tiling = Tiling::zeroed();
            return;
        };
        self.cert_tiling = tiling_of(l);
        let grew_tiles = write_or_grow(gpu, &mut self.cert_tiles, bytemuck::cast_slice(&l.data));
        let grew_boxes = write_or_grow(gpu, &mut self.cert_boxes, bytemuck::cast_slice(&l.boxes));
        if grew_tiles || grew_boxes {
            self.rebind(gpu);
        }
    }

    /// Makes the bind group anew for the buffers held now (after any of them is replaced).
    fn rebind(&mut self, gpu: &Gpu) {
        self.bind_group = bind_group(
            &gpu.device,
            &self.layout,
            [
                &self.uniforms,
                &self.nodes,
                &self.tiles,
                &self.boxes,
                &self.bounds,
                &self.cert_tiles,
                &self.cert_boxes,
            ],
        );
    }

    /// Whether tile lists are bound.
    pub fn tiled(&self) -> bool {
        self.tiling.bound != 0
    }

    /// Records one pass: the whole target, or only `pass.region` (the rest is kept), blended
    /// with `pass.weight` when the target accumulates. The uniforms are written to the queue,
    /// so one submission should hold one set of uniforms.
    pub fn encode_pass(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        uniforms: &Uniforms,
        pass: Pass,
    ) {
        self.record_pass(gpu, encoder, target, uniforms, pass, None);
    }

    /// As [`RayCaster::encode_pass`], writing GPU timestamps at the pass's start and end
    /// into queries 0 and 1 of `timestamps`, if given.
    fn record_pass(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        uniforms: &Uniforms,
        pass: Pass,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        let mut uniforms = *uniforms;
        uniforms.tiling = self.tiling;
        uniforms.cert_tiling = self.cert_tiling;
        gpu.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
        let mode = if uniforms.brute_force() {
            Mode::BruteForce
        } else if self.tiled() {
            Mode::Tiles
        } else {
            Mode::Walk
        };
        // With tile lists, the ray caster runs only where they have boxes to march; the
        // background goes elsewhere where the pass overwrites (a pass blended into the
        // running mean of passes of the same view finds it there already, and blending it
        // with itself keeps it).
        let overwrite = !self.target.accumulate || pass.weight >= 1.0;
        let whole = pass.region.is_none() && !self.target.accumulate;
        let load = if !whole {
            wgpu::LoadOp::Load
        } else if mode == Mode::Tiles {
            let [r, g, b, _] = uniforms.background.map(f64::from);
            wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 })
        } else {
            wgpu::LoadOp::Clear(wgpu::Color::BLACK)
        };
        let mut rpass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("fourfold frame"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps.map(|query_set| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            }),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let ray_caster = self.pipeline(gpu, Variant::of(mode, &uniforms));
        rpass.set_pipeline(ray_caster);
        rpass.set_bind_group(0, &self.bind_group, &[]);
        let (width, height) = (uniforms.size.width, uniforms.size.height);
        if self.target.accumulate {
            let c = pass.weight.clamp(0.0, 1.0);
            rpass.set_blend_constant(wgpu::Color {
                r: c,
                g: c,
                b: c,
                a: c,
            });
        }
        // The pixels to draw, as a rectangle (x0, y0, x1, y1).
        let region = pass.region.map_or([0, 0, width, height], |[x, y, w, h]| {
            [x, y, x.saturating_add(w), y.saturating_add(h)]
        });
        // One triangle over the target, drawn within scissor rectangles: the region, or
        // with tile lists its parts in `rects` (a SIMD rasterizer runs the ray caster's
        // loop bodies once for a group of pixels even where none of them enters a loop).
        let draw = |rpass: &mut wgpu::RenderPass<'_>, rect: [u32; 4]| {
            let x0 = rect[0].max(region[0]).min(width);
            let y0 = rect[1].max(region[1]).min(height);
            let x1 = rect[2].min(region[2]).min(width);
            let y1 = rect[3].min(region[3]).min(height);
            if x0 < x1 && y0 < y1 {
                rpass.set_scissor_rect(x0, y0, x1 - x0, y1 - y0);
                rpass.draw(0..3, 0..1);
            }
        };
        if mode != Mode::Tiles {
            draw(&mut rpass, region);
            return;
        }
        if overwrite && !whole {
            rpass.set_pipeline(self.background_pipeline(gpu));
            draw(&mut rpass, region);
            rpass.set_pipeline(ray_caster);
        }
        for &rect in &self.rects {
            draw(&mut rpass, rect);
        }
    }

    /// The pipeline of `fs_background`, built on first use.
    fn background_pipeline(&self, gpu: &Gpu) -> &wgpu::RenderPipeline {
        self.background.get_or_init(|| {
            fullscreen_pipeline(
                &gpu.device,
                "fourfold background",
                &self.module,
                &self.pipeline_layout,
                color_target(self.target),
                "fs_background",
                &[],
            )
        })
    }

    /// The pipeline of `variant`, built on first use (the shader module was validated when
    /// the first pipeline was built, so the others build too).
    fn pipeline(&self, gpu: &Gpu, variant: Variant) -> &wgpu::RenderPipeline {
        self.pipelines[variant.index()].get_or_init(|| {
            build_pipeline(
                &gpu.device,
                &self.module,
                &self.pipeline_layout,
                self.target,
                variant,
            )
        })
    }

    /// A `width`×`height` texture in this caster's target format.
    pub fn target_texture(
        &self,
        gpu: &Gpu,
        width: u32,
        height: u32,
        usage: wgpu::TextureUsages,
    ) -> wgpu::Texture {
        gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("fourfold target"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.target.format,
            usage,
            view_formats: &[],
        })
    }

    /// Renders one frame offscreen and reads it back as tightly packed rows, 4 bytes a pixel
    /// (the RGBA8 formats, which both targets use).
    pub fn render_rgba(&self, gpu: &Gpu, uniforms: &Uniforms) -> Result<Vec<u8>, GpuError> {
        self.render_rgba_timed(gpu, uniforms).map(|(rgba, _)| rgba)
    }

    /// As [`RayCaster::render_rgba`], with the milliseconds the GPU took for the frame's
    /// pass, from timestamps written at its start and end (None where the device has no
    /// timestamp queries, `Gpu::has_timestamps`). That excludes the upload, the read-back
    /// and the CPU's work around them.
    pub fn render_rgba_timed(
        &self,
        gpu: &Gpu,
        uniforms: &Uniforms,
    ) -> Result<(Vec<u8>, Option<f64>), GpuError> {
        let timer = gpu.has_timestamps().then(|| Timer::new(gpu));
        let frame = self.submit_rgba(gpu, uniforms, timer.as_ref())?;
        let pixels = read_back(gpu, &frame.readback, |data| frame.rows(data))?;
        let gpu_ms = match &timer {
            Some(timer) => timer.read(gpu)?,
            None => None,
        };
        Ok((pixels, gpu_ms))
    }

    /// Renders one frame offscreen and starts reading it back without waiting (a web page
    /// cannot wait for the GPU): poll the result until it is there.
    pub fn start_rgba(&self, gpu: &Gpu, uniforms: &Uniforms) -> Result<PendingRgba, GpuError> {
        let frame = self.submit_rgba(gpu, uniforms, None)?;
        Ok(PendingRgba::map(frame))
    }

    /// Records and submits one frame and its copy into a mappable buffer.
    fn submit_rgba(
        &self,
        gpu: &Gpu,
        uniforms: &Uniforms,
        timer: Option<&Timer>,
    ) -> Result<FrameCopy, GpuError> {
        let (width, height) = (uniforms.size.width, uniforms.size.height);
        check_image_size(width, height, &gpu.device.limits())?;
        let texture = self.target_texture(
            gpu,
            width,
            height,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        self.record_pass(
            gpu,
            &mut encoder,
            &view,
            uniforms,
            Pass::default(),
            timer.map(|t| &t.queries),
        );
        if let Some(timer) = timer {
            timer.resolve(&mut encoder);
        }
        let copy = FrameCopy::record(gpu, &mut encoder, &texture);
        gpu.queue.submit([encoder.finish()]);
        Ok(copy)
    }
}

/// Starts reading back an RGBA8 texture made with COPY_SRC (the viewer's picture, for its
/// certified pixels' verdicts) without waiting: poll the result until it is there.
pub fn start_texture_read(gpu: &Gpu, texture: &wgpu::Texture) -> PendingRgba {
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    let frame = FrameCopy::record(gpu, &mut encoder, texture);
    gpu.queue.submit([encoder.finish()]);
    PendingRgba::map(frame)
}

/// A frame copied into a mappable buffer, its rows padded to the copy alignment.
struct FrameCopy {
    readback: wgpu::Buffer,
    width: u32,
    height: u32,
    padded_row: u32,
}

impl FrameCopy {
    /// Records the copy of all of `texture` (RGBA8, COPY_SRC) into a new mappable buffer.
    fn record(gpu: &Gpu, encoder: &mut wgpu::CommandEncoder, texture: &wgpu::Texture) -> Self {
        let (width, height) = (texture.width(), texture.height());
        let padded_row = (width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fourfold readback"),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(height),
                },
            },
            texture.size(),
        );
        Self {
            readback,
            width,
            height,
            padded_row,
        }
    }

    /// The rows without their padding, 4 bytes a pixel.
    fn rows(&self, data: &[u8]) -> Vec<u8> {
        let row = (self.width * 4) as usize;
        let mut pixels = Vec::with_capacity(row * self.height as usize);
        for y in 0..self.height as usize {
            let start = y * self.padded_row as usize;
            pixels.extend_from_slice(&data[start..start + row]);
        }
        pixels
    }
}

/// A frame on its way back from the GPU (see [`RayCaster::start_rgba`]).
pub struct PendingRgba {
    frame: FrameCopy,
    state: Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>,
}

impl PendingRgba {
    /// Starts mapping the copied frame; `poll` finds it once mapped.
    fn map(frame: FrameCopy) -> Self {
        let state = Arc::new(Mutex::new(None));
        let mapped = state.clone();
        frame
            .readback
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |r| {
                *mapped.lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
            });
        Self { frame, state }
    }

    /// The frame's width and height.
    pub fn size(&self) -> [u32; 2] {
        [self.frame.width, self.frame.height]
    }

    /// The pixels (tightly packed RGBA8 rows) once the GPU has written them, else None.
    pub fn poll(&self, gpu: &Gpu) -> Option<Result<Vec<u8>, GpuError>> {
        // (Natively this lets wgpu call the map callback; in a browser the page's event loop
        // does.)
        let _ = gpu.device.poll(wgpu::PollType::Poll);
        let mapped = self
            .state
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()?;
        Some(
            mapped
                .map_err(|e| GpuError::Readback(e.to_string()))
                .and_then(|()| {
                    let slice = self.frame.readback.slice(..);
                    let data = slice
                        .get_mapped_range()
                        .map_err(|e| GpuError::Readback(format!("{e:?}")))?;
                    let pixels = self.frame.rows(&data);
                    drop(data);
                    self.frame.readback.unmap();
                    Ok(pixels)
                }),
        )
    }
}

/// Two GPU timestamps (a pass's start and end) and the buffers that bring them back.
struct Timer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl Timer {
    const BYTES: u64 = 2 * wgpu::QUERY_SIZE as u64;

    fn new(gpu: &Gpu) -> Self {
        let buffer = |usage| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fourfold timestamps"),
                size: Self::BYTES,
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            queries: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("fourfold frame timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolved: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
        }
    }

    /// Records copying the timestamps to the mappable buffer (after the pass).
    fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.queries, 0..2, &self.resolved, 0);
        encoder.copy_buffer_to_buffer(&self.resolved, 0, &self.readback, 0, Self::BYTES);
    }

    /// The milliseconds between the two timestamps (None if they are out of order).
    fn read(&self, gpu: &Gpu) -> Result<Option<f64>, GpuError> {
        let ticks = read_back(gpu, &self.readback, |data| {
            let stamps: [u64; 2] = bytemuck::pod_read_unaligned(data);
            stamps[1].checked_sub(stamps[0])
        })?;
        let period_ns = f64::from(gpu.queue.get_timestamp_period());
        Ok(ticks.map(|t| t as f64 * period_ns / 1e6))
    }
}

/// `read` of the contents of a mappable buffer, once the GPU has finished writing it.
pub(crate) fn read_back<T>(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    read: impl FnOnce(&[u8]) -> T,
) -> Result<T, GpuError> {
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = sender.send(r);
    });
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    receiver
        .recv()
        .map_err(|e| GpuError::Readback(e.to_string()))?
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| GpuError::Readback(format!("{e:?}")))?;
    let out = read(&data);
    drop(data);
    buffer.unmap();
    Ok(out)
}

/// target = c·new + (1−c)·old, c the blend constant.
const ACCUMULATE: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Constant,
        dst_factor: wgpu::BlendFactor::OneMinusConstant,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Constant,
        dst_factor: wgpu::BlendFactor::OneMinusConstant,
        operation: wgpu::BlendOperation::Add,
    },
};

/// The hierarchy's nodes (binding 1) and their slope and curvature bounds (binding 4,
/// unbounded where none).
fn node_buffers(
    gpu: &Gpu,
    hierarchy: &Hierarchy,
) -> Result<(wgpu::Buffer, wgpu::Buffer), GpuError> {
    let limit = gpu.device.limits().max_storage_buffer_binding_size;
    // The larger of the two.
    let bytes = (hierarchy.nodes.len() * std::mem::size_of::<NodeBounds>()) as u64;
    if bytes > limit {
        return Err(GpuError::TooLarge {
            nodes: hierarchy.nodes.len(),
            bytes,
            limit,
        });
    }
    // An empty tree still needs non-empty buffers; the shader reads node_count = 0.
    let placeholder = [SphereNode {
        center: [0.0; 4],
        skip: 1,
        meta: 0,
    }];
    let nodes: &[SphereNode] = if hierarchy.nodes.is_empty() {
        &placeholder
    } else {
        &hierarchy.nodes
    };
    let bounds: Vec<NodeBounds> = (0..nodes.len()).map(|i| hierarchy.bounds(i)).collect();
    let buffer = |label: &str, contents: &[u8]| {
        gpu.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
    };
    Ok((
        buffer("fourfold hierarchy", bytemuck::cast_slice(nodes)),
        buffer("fourfold node bounds", bytemuck::cast_slice(&bounds)),
    ))
}

/// The shader's pipeline constant SLOTS, the hit slots it keeps: one pipeline per value.
/// Fewer slots cost less per hit (K = 4 by default: 10–15% of a frame on lavapipe).
const SLOT_TIERS: [u32; 3] = [4, 8, 16];

/// The index in SLOT_TIERS of the fewest slots that hold `hits` (K).
fn slot_tier(hits: u32) -> usize {
    SLOT_TIERS
        .iter()
        .position(|&s| hits <= s)
        .unwrap_or(SLOT_TIERS.len() - 1)
}

/// What a ray-caster pipeline is specialised for, by the shader's pipeline constants: each
/// is its own pipeline, so that a pixel runs only its own code (a SIMD rasterizer runs
/// every branch).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Variant {
    /// MODE: where a pixel's boxes come from.
    mode: Mode,
    /// The index in SLOT_TIERS of SLOTS, the hit slots kept.
    slots: usize,
    /// SAMPLING: the chapter's random rays (1) or stratified ones (0). Chosen at run time
    /// by the shader's flag, the random rays' code cost a stratified frame 4-5% on llvmpipe.
    random: bool,
    /// SECTION: the whole observer plane (0), a slab of it (1) or a slice (2), so that a
    /// whole plane's frame runs no slab or slice code.
    section: u8,
    /// CERTIFY: classify every pixel rigorously (docs/method.md §5.9).
    certified: bool,
}

impl Variant {
    const COUNT: usize = 3 * SLOT_TIERS.len() * 2 * 3 * 2;

    /// The variant that draws with `uniforms` in `mode`.
    fn of(mode: Mode, uniforms: &Uniforms) -> Self {
        Self {
            mode,
            slots: slot_tier(uniforms.size.hits),
            random: uniforms.control.flags & FLAG_RANDOM != 0,
            section: if uniforms.control.flags & FLAG_SLICE != 0 {
                2
            } else {
                u8::from(uniforms.control.flags & FLAG_SLAB != 0)
            },
            certified: uniforms.control.flags & FLAG_CERTIFIED != 0,
        }
    }

    fn index(self) -> usize {
        let sampled = (self.mode as usize * SLOT_TIERS.len() + self.slots) * 2;
        let sectioned = (sampled + usize::from(self.random)) * 3 + usize::from(self.section);
        sectioned * 2 + usize::from(self.certified)
    }
}

fn build_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    target: Target,
    variant: Variant,
) -> wgpu::RenderPipeline {
    fullscreen_pipeline(
        device,
        "fourfold ray caster",
        module,
        layout,
        color_target(target),
        "fs_main",
        &[
            ("MODE", f64::from(variant.mode as u32)),
            ("SLOTS", f64::from(SLOT_TIERS[variant.slots])),
            ("SAMPLING", f64::from(u32::from(variant.random))),
            ("SECTION", f64::from(variant.section)),
            ("CERTIFY", f64::from(u32::from(variant.certified))),
        ],
    )
}

/// How a ray caster's pipelines write `target`.
fn color_target(target: Target) -> wgpu::ColorTargetState {
    wgpu::ColorTargetState {
        format: target.format,
        blend: target.accumulate.then_some(ACCUMULATE),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// A pipeline drawing one triangle over the viewport with `vs_main` (no vertex buffers) and
/// shading it with the entry point `fragment`, given pipeline constants for the fragment
/// stage.
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    target: wgpu::ColorTargetState,
    fragment: &str,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            targets: &[Some(target)],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Binding `binding` of the ray caster: a read-only storage buffer (all of them are), read
/// by the fragment stage, and the settings (binding 0) by the vertex stage too (which hands
/// the most read of them to the fragment stage as flat values).
fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    let visibility = if binding == 0 {
        wgpu::ShaderStages::VERTEX_FRAGMENT
    } else {
        wgpu::ShaderStages::FRAGMENT
    };
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A storage buffer for a view's data (tile lists or box records) that `write_or_grow`
/// rewrites: `bytes` long (a binding can't be empty), zeroed.
fn view_buffer(gpu: &Gpu, bytes: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fourfold view data"),
        size: bytes.max(std::mem::size_of::<BoxRecord>() as u64),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// Writes `data` (at most the device's storage-buffer limit) at the start of `buffer`,
/// first replacing it by a larger one (the next power of two, within the limit) if it is
/// too small; returns whether it was replaced (the bind group must then be made anew).
fn write_or_grow(gpu: &Gpu, buffer: &mut wgpu::Buffer, data: &[u8]) -> bool {
    let len = data.len() as u64;
    let grow = len > buffer.size();
    if grow {
        let limit = gpu.device.limits().max_storage_buffer_binding_size;
        *buffer = view_buffer(gpu, len.next_power_of_two().min(limit));
    }
    gpu.queue.write_buffer(buffer, 0, data);
    grow
}

/// Tile lists that fit the device's storage-buffer limit (and hold anything).
fn usable<'a>(gpu: &Gpu, lists: Option<&'a TileLists>) -> Option<&'a TileLists> {
    let limit = gpu.device.limits().max_storage_buffer_binding_size;
    lists.filter(|l| {
        (l.data.len() as u64) * 4 <= limit
            && std::mem::size_of_val(l.boxes.as_slice()) as u64 <= limit
            && !l.data.is_empty()
    })
}

/// `Uniforms::tiling` for bound lists.
fn tiling_of(l: &TileLists) -> Tiling {
    Tiling {
        tile: l.tile,
        tiles_per_row: l.tiles_x,
        bound: 1,
        entries_start: l.tiles_x * l.tiles_y + 1,
    }
}

/// Bindings 0 to 6: uniforms, hierarchy, tile lists, box records, node bounds, certifying
/// tile lists and their box records.
fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: [&wgpu::Buffer; STORAGE_BUFFERS as usize],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .zip(0u32..)
        .map(|(buffer, binding)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("fourfold bind group"),
        layout,
        entries: &entries,
    })
}

/// The validation error a scope caught. Natively the scope is waited for; a web page cannot
/// wait, so there the error goes to the browser's console (as its WebGPU does with errors
/// no scope catches) and none is returned.
pub fn scope_error(scope: wgpu::ErrorScopeGuard) -> Option<wgpu::Error> {
    #[cfg(not(target_arch = "wasm32"))]
    return pollster::block_on(scope.pop());
    #[cfg(target_arch = "wasm32")]
    {
        wasm_bindgen_futures::spawn_local(async move {
            if let Some(error) = scope.pop().await {
                web_sys::console::error_1(&format!("fourfold: {error}").into());
            }
        });
        None
    }
}
