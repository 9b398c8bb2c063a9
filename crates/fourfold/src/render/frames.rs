//! An animation's frames started one at a time on one painter, without waiting for any: the
//! tree is rebuilt only when a parameter changes, and with `fit` one zoom and pan frames the
//! manifold in every frame (of the first frame's tree). `fourfold animate` and the desktop
//! wait for each picture (`headless::draw`); a web page polls it over its frames.

use crate::formula::CompiledFormula;
use crate::render::Prepared;
use crate::render::animation::Animation;
use crate::render::picture::{Device, Painter, PendingPicture};
use crate::render::view::{FrameOptions, Rotation4, framing};
use crate::scene::Scene;

/// The frames of an animation of a scene, started in order.
pub struct AnimationFrames {
    /// The scene, framed where `fit` asked.
    scene: Scene,
    animation: Animation,
    size: [u32; 2],
    prepared: Prepared,
    painter: Painter,
    next: u32,
}

impl AnimationFrames {
    /// Builds the first frame's tree, frames the scene where `fit` asks, and makes the
    /// painter the frames draw with on `device`.
    pub fn new(
        scene: &Scene,
        formula: &CompiledFormula,
        animation: &Animation,
        size: [u32; 2],
        fit: bool,
        device: Device<'_>,
    ) -> Result<Self, String> {
        let mut scene = scene.clone();
        let first = animation.scene_at(&scene, 0);
        let prepared = Prepared::new(formula, &first).map_err(|e| e.to_string())?;
        let [width, height] = size;
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
        let first = animation.scene_at(&scene, 0);
        let painter = Painter::for_formula(device, formula, &prepared.hierarchy, &first)
            .map_err(|e| e.to_string())?;
        Ok(Self {
            scene,
            animation: animation.clone(),
            size,
            prepared,
            painter,
            next: 0,
        })
    }

    /// The frame the next [`AnimationFrames::start_next`] starts (the animation's frame
    /// count once all are started).
    pub fn next(&self) -> u32 {
        self.next
    }

    /// Starts the next frame's picture (its tree rebuilt first where its parameters
    /// changed); None once every frame is started.
    pub fn start_next(
        &mut self,
        formula: &CompiledFormula,
    ) -> Result<Option<PendingPicture>, String> {
        let k = self.next;
        if k >= self.animation.frames {
            return Ok(None);
        }
        let at = self.animation.scene_at(&self.scene, k);
        if k > 0 && at.params != self.animation.scene_at(&self.scene, k - 1).params {
            self.prepared = Prepared::new(formula, &at).map_err(|e| e.to_string())?;
            self.painter
                .set_hierarchy(&self.prepared.hierarchy)
                .map_err(|e| e.to_string())?;
        }
        let options = FrameOptions {
            rotation: Some(self.animation.rotation(&at, k)),
            ..FrameOptions::default()
        };
        let source = self.prepared.source(formula, at.render.certified);
        let pending = self
            .painter
            .start(source, &at, self.size, options)
            .map_err(|e| e.to_string())?;
        self.next += 1;
        Ok(Some(pending))
    }
}
