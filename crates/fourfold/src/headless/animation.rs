//! Drawing an animation: its frames ([`AnimationFrames`]) one after the other on one device,
//! each waited for and handed to a writer, with a stop flag checked between frames.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::formula::CompiledFormula;
use crate::render::animation::Animation;
use crate::render::picture::Device;
use crate::render::verdict::VerdictCounts;
use crate::render::{AnimationFrames, Gpu};
use crate::scene::Scene;

/// Where frames are drawn.
pub enum FrameDevice<'a> {
    Gpu(&'a Gpu),
    /// The CPU reference renderer.
    Cpu,
}

/// What `draw` drew.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Drawn {
    pub frames: u32,
    /// With `[render] certified`: the verdicts of every frame's pixels, summed.
    pub verdicts: Option<VerdictCounts>,
    /// Pixels, summed over the frames, whose work the GPU driver cut short.
    pub cut: usize,
}

/// Draws the animation's frames of `scene` at `width`×`height` one after the other, handing
/// each to `frame` (its index and RGBA8 rows); stops early, with the frames drawn so far,
/// once `stop` is set. With `fit`, one zoom and pan frames the manifold in every frame (of
/// the first frame's tree).
#[allow(clippy::too_many_arguments)]
pub fn draw(
    scene: &Scene,
    formula: &CompiledFormula,
    animation: &Animation,
    width: u32,
    height: u32,
    fit: bool,
    device: FrameDevice<'_>,
    stop: &AtomicBool,
    mut frame: impl FnMut(u32, Vec<u8>) -> Result<(), String>,
) -> Result<Drawn, String> {
    let device = match device {
        FrameDevice::Gpu(gpu) => Device::Gpu(gpu),
        FrameDevice::Cpu => Device::Cpu,
    };
    let mut frames = AnimationFrames::new(scene, formula, animation, [width, height], fit, device)?;
    let mut drawn = Drawn {
        verdicts: scene.render.certified.then(VerdictCounts::default),
        ..Drawn::default()
    };
    loop {
        if stop.load(Ordering::Relaxed) {
            return Ok(drawn);
        }
        let k = frames.next();
        let Some(pending) = frames.start_next(formula)? else {
            return Ok(drawn);
        };
        let picture = pending.wait().map_err(|e| e.to_string())?;
        drawn.cut += picture.cut_pixels.len();
        if let (Some(total), Some(counts)) = (&mut drawn.verdicts, picture.verdict_counts()) {
            *total += counts;
        }
        frame(k, picture.rgba)?;
        drawn.frames = k + 1;
    }
}
