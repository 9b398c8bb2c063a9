//! The stages of a picture: a preview sized to fit a frame at the measured speed, a half
//! resolution pass, then the full picture and the passes averaged into it, each drawn in
//! squares; and what a picture depends on, which starts it again when it changes.

use fourfold::scene::{Domain, RenderSettings, Scene, View};

/// Full-resolution passes averaged into the picture once it is complete.
pub const ACCUMULATED_PASSES: u32 = 16;

/// Everything the picture on screen depends on besides the session's picture generation: a
/// different key starts the picture again.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewKey {
    pub view: View,
    pub render: RenderSettings,
    pub domain: Domain,
    /// The picture's size in pixels.
    pub size: [u32; 2],
}

impl ViewKey {
    pub fn new(scene: &Scene, size: [u32; 2]) -> Self {
        Self {
            view: scene.view,
            render: scene.render,
            domain: scene.domain,
            size,
        }
    }
}

/// One stage of a picture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Stage {
    /// Pixels are `div`× larger than the screen's.
    pub(super) div: u32,
    pub(super) rays: u32,
    /// Frame index (ray offsets) and blend weight of the pass.
    pub(super) frame: u32,
    pub(super) weight: f64,
}

/// Side of the squares a stage is drawn in, pixels.
pub(super) const UNIT: u32 = 8;

/// The divisors of the stage textures: preview sizes and the full picture.
pub(super) const DIVS: [u32; 6] = [32, 16, 8, 4, 2, 1];

/// The stages of a picture of `size` with the scene's `rays`, at `rays_per_ms` (a preview
/// alone while the user interacts).
pub(super) fn plan(size: [u32; 2], rays: u32, rays_per_ms: f64, interacting: bool) -> Vec<Stage> {
    let rays = rays.max(1);
    let pixels = |div: u32| f64::from(size[0].div_ceil(div)) * f64::from(size[1].div_ceil(div));
    // The preview: the finest divisor whose pass fits in ~one frame at the measured speed.
    let preview_rays = rays.min(4);
    let budget = if interacting { 30.0 } else { 60.0 } * rays_per_ms;
    let preview = DIVS
        .iter()
        .copied()
        .rev()
        .find(|&d| pixels(d) * f64::from(preview_rays) <= budget)
        .unwrap_or(DIVS[0]);
    let mut stages = vec![Stage {
        div: preview,
        rays: preview_rays,
        frame: 0,
        weight: 1.0,
    }];
    if !interacting {
        if preview > 2 {
            stages.push(Stage {
                div: 2,
                rays: rays.min(8),
                frame: 0,
                weight: 1.0,
            });
        }
        for k in 0..ACCUMULATED_PASSES {
            stages.push(Stage {
                div: 1,
                rays,
                frame: k,
                weight: 1.0 / f64::from(k + 1),
            });
        }
        // A preview that is already the full picture needs no separate first pass.
        if stages[0].div == 1 {
            stages.remove(0);
        }
    }
    stages
}

/// The index of the stage texture of divisor `div`.
pub(super) fn texture_index(div: u32) -> usize {
    DIVS.iter()
        .position(|&d| d == div)
        .unwrap_or(DIVS.len() - 1)
}
