//! A new formula's first preview drawn on the CPU by the core's twin of the ray caster,
//! where the GPU would first compile the formula's shader. In a page on a software GPU
//! (Chromium's SwiftShader) that compile takes most of a second in the GPU process, ahead
//! of every frame queued after it; the twin draws a small preview in tens of milliseconds,
//! and the GPU's own stages follow.

use web_time::{Duration, Instant};

use fourfold::CompiledFormula;
use fourfold::render::{FrameOptions, Gpu, twin, view};
use fourfold::scene::Scene;
use fourfold::tree::Hierarchy;

use super::stages::DIVS;
use super::textures::StageTexture;

/// The milliseconds a preview on the CPU may hold the window's thread.
pub const BUDGET_MS: f64 = 40.0;

/// How long the GPU's stages wait after a preview on the CPU of a formula whose pipeline is
/// not built: a keystroke within it brings another formula, and a compile queued for this
/// one cannot be taken back; it would hold up the next preview on screen by as long as it
/// takes.
pub const GPU_HOLD_MS: f64 = 250.0;

/// The twin's speed before one of its previews is measured, in rays times instructions
/// of the formula's tape per millisecond: a page's (WebAssembly, one thread), low, so that
/// the first preview is small.
const FIRST_GUESS_SPEED: f64 = 10_000.0;

/// How fast the twin draws previews, and what it drew.
#[derive(Debug, Clone, Default)]
pub struct CpuPreviews {
    /// The last preview's rays times instructions of its formula's tape (F and ∇F) per
    /// millisecond: a longer formula's rays cost more, in proportion at first sight.
    speed: Option<f64>,
    /// Previews drawn on the CPU so far.
    pub drawn: u64,
    /// The last one's divisor of the screen's size.
    pub last: Option<u32>,
    /// When the GPU's stages began to wait (see [`GPU_HOLD_MS`]); None: they do not.
    held_from: Option<Instant>,
}

impl CpuPreviews {
    /// The finest divisor of a picture of `size` (screen pixels) that the twin previews
    /// with `rays` rays a pixel, of a formula of `instructions`, within [`BUDGET_MS`] at
    /// its measured speed, no finer than `finest`; None when not even the coarsest fits.
    pub fn divisor(
        &self,
        size: [u32; 2],
        rays: u32,
        instructions: usize,
        finest: u32,
    ) -> Option<u32> {
        let speed = self.speed.unwrap_or(FIRST_GUESS_SPEED);
        let cost = |div: u32| {
            let pixels = f64::from(size[0].div_ceil(div)) * f64::from(size[1].div_ceil(div));
            pixels * f64::from(rays) * instructions.max(1) as f64
        };
        DIVS.iter()
            .copied()
            .filter(|&div| div >= finest)
            .rev()
            .find(|&div| cost(div) <= BUDGET_MS * speed)
    }

    /// How long the GPU's stages still wait (see [`GPU_HOLD_MS`]); None: they do not.
    pub fn gpu_held(&self) -> Option<Duration> {
        Duration::from_secs_f64(GPU_HOLD_MS / 1e3).checked_sub(self.held_from?.elapsed())
    }

    /// The GPU's stages wait from now (`hold`: its pipeline would compile first), or not.
    pub fn hold_gpu(&mut self, hold: bool) {
        self.held_from = hold.then(Instant::now);
    }

    /// Draws `scene`'s frame of `formula` over `hierarchy`, with `rays` rays a pixel, at
    /// the screen's size over `div` (`texture`'s), with the twin, into `texture`.
    pub fn draw(
        &mut self,
        gpu: &Gpu,
        (texture, div): (&StageTexture, u32),
        (formula, params, hierarchy): (&CompiledFormula, &[f64], &Hierarchy),
        scene: &Scene,
        rays: u32,
    ) {
        let options = FrameOptions {
            rays: Some(rays),
            ..FrameOptions::default()
        };
        let size = [texture.width, texture.height];
        let (_, uniforms) = view::frame(scene, hierarchy, params, size, options);
        let started = Instant::now();
        let rgba = twin::render_rgba(formula, params, hierarchy, None, &uniforms);
        let ms = started.elapsed().as_secs_f64() * 1e3;
        let work = f64::from(size[0]) * f64::from(size[1]) * f64::from(rays);
        // (A few milliseconds' reading says little of a costly formula: counted as one.)
        self.speed = Some(work * formula.tape_all.len().max(1) as f64 / ms.max(1.0));
        self.drawn += 1;
        self.last = Some(div);
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * size[0]),
                rows_per_image: Some(size[1]),
            },
            wgpu::Extent3d {
                width: size[0],
                height: size[1],
                depth_or_array_layers: 1,
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_preview_is_as_fine_as_the_twin_s_measured_speed_allows() {
        let mut previews = CpuPreviews::default();
        // At the first guess, 40 ms hold 400 000 rays × instructions: 10 000 rays of a
        // formula of 40, 2 500 pixels at 4 rays: 50×32 of 800×500 (division 16; 8 gives
        // 100×63).
        assert_eq!(previews.divisor([800, 500], 4, 40, 2), Some(16));
        assert_eq!(previews.divisor([800, 500], 4, 200, 2), Some(32));
        // Measured ten times faster: 20 000 rays, division 16 (8: 100×63 pixels, 25 200).
        previews.speed = Some(20_000.0);
        assert_eq!(previews.divisor([800, 500], 4, 40, 2), Some(16));
        // A formula of a quarter of the instructions: division 8.
        assert_eq!(previews.divisor([800, 500], 4, 10, 2), Some(8));
        // Never finer than the GPU's preview would be.
        assert_eq!(previews.divisor([800, 500], 4, 10, 16), Some(16));
        // A formula too costly for even the coarsest preview is left to the GPU.
        assert_eq!(previews.divisor([800, 500], 4, 1_000, 2), None);
    }
}
