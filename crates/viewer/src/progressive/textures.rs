//! The textures a picture's stages are drawn into, one per divisor of the screen's size,
//! registered with egui (and with the viewer's blit where the renderer has it).

use eframe::{egui, egui_wgpu};

use fourfold::render::{Gpu, RayCaster};

use super::stages::DIVS;

/// A texture the ray caster draws into and egui shows.
pub struct StageTexture {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    pub id: egui::TextureId,
    /// For the app's own blit (see blit.rs), where egui's renderer has it.
    pub blit: Option<wgpu::BindGroup>,
    pub width: u32,
    pub height: u32,
}

/// The stage textures of a picture of `size` (screen pixels) in `caster`'s target format.
pub(super) fn make(
    gpu: &Gpu,
    caster: &RayCaster,
    renderer: &mut egui_wgpu::Renderer,
    size: [u32; 2],
) -> Vec<StageTexture> {
    // (A view wider or taller than the device's largest texture is drawn at that side and
    // stretched.)
    let max_side = gpu.device.limits().max_texture_dimension_2d;
    DIVS.iter()
        .map(|&div| {
            let width = size[0].div_ceil(div).clamp(1, max_side);
            let height = size[1].div_ceil(div).clamp(1, max_side);
            let texture = caster.target_texture(
                gpu,
                width,
                height,
                wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::COPY_DST,
            );
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let id = renderer.register_native_texture(&gpu.device, &view, wgpu::FilterMode::Linear);
            let blit = renderer
                .callback_resources
                .get::<crate::blit::Blit>()
                .map(|b| b.bind(&gpu.device, &view));
            StageTexture {
                texture,
                view,
                id,
                blit,
                width,
                height,
            }
        })
        .collect()
}
