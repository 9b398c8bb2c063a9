//! Drawing an animation: its frames one after the other on one device (the tree rebuilt only
//! when a parameter changes), handed to a writer, with a stop flag checked between frames.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::formula::CompiledFormula;
use crate::render::animation::Animation;
use crate::render::picture::{Device, Painter};
use crate::render::verdict::VerdictCounts;
use crate::render::view::{FrameOptions, Rotation4, framing};
use crate::render::{Gpu, Prepared, shader};
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
    let mut scene = scene.clone();
    let mut prepared =
        Prepared::new(formula, &animation.scene_at(&scene, 0)).map_err(|e| e.to_string())?;
    if fit {
        let rotations: Vec<Rotation4> = (0..animation.frames)
            .map(|k| animation.rotation(&scene, k))
            .collect();
        if let Some(view) = framing::fit_through(
            &prepared.hierarchy,
            &scene.domain,
            &scene.view,
            &rotations,
            width,
            height,
        ) {
            scene.view.zoom = view.zoom;
            scene.view.pan = view.pan;
        }
    }
    let shader = shader::generate(formula).map_err(|e| e.to_string())?;
    let device = match device {
        FrameDevice::Gpu(gpu) => Device::Gpu(gpu),
        FrameDevice::Cpu => Device::Cpu,
    };
    let first = animation.scene_at(&scene, 0);
    let mut painter =
        Painter::new(device, &shader, &prepared.hierarchy, &first).map_err(|e| e.to_string())?;
    let mut drawn = Drawn {
        verdicts: scene.render.certified.then(VerdictCounts::default),
        ..Drawn::default()
    };
    for k in 0..animation.frames {
        if stop.load(Ordering::Relaxed) {
            return Ok(drawn);
        }
        let at = animation.scene_at(&scene, k);
        if k > 0 && at.params != animation.scene_at(&scene, k - 1).params {
            prepared = Prepared::new(formula, &at).map_err(|e| e.to_string())?;
            painter
                .set_hierarchy(&prepared.hierarchy)
                .map_err(|e| e.to_string())?;
        }
        let options = FrameOptions {
            rotation: Some(animation.rotation(&at, k)),
            ..FrameOptions::default()
        };
        let picture = painter
            .start(
                prepared.source(formula, at.render.certified),
                &at,
                [width, height],
                options,
            )
            .and_then(|pending| pending.wait())
            .map_err(|e| e.to_string())?;
        drawn.cut += picture.cut_pixels.len();
        if let (Some(total), Some(counts)) = (&mut drawn.verdicts, picture.verdict_counts()) {
            *total += counts;
        }
        frame(k, picture.rgba)?;
        drawn.frames = k + 1;
    }
    Ok(drawn)
}
