//! The one preparation of a picture, shared by the CLI, the viewer, the benchmarks and the
//! tests: a compiled formula and a scene → the parameter values, the 16-tree and the sphere
//! hierarchy the ray caster marches; then, per view, the camera and the frame's settings.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use crate::formula::CompiledFormula;
use crate::scene::Scene;
use crate::tree::{BuildError, BuildSettings, Hierarchy, Progress, Tree16};

use super::camera::Camera;
use super::uniforms::{FrameOptions, Uniforms};

/// What the ray caster draws a scene from, apart from the view.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The parameter values, in the formula's order (1.0 where the scene has none).
    pub params: Vec<f64>,
    pub tree: Tree16,
    pub hierarchy: Hierarchy,
    /// Milliseconds for the tree and the hierarchy.
    pub build_ms: f64,
}

impl Prepared {
    /// Builds the tree with the scene's settings, to completion.
    pub fn new(formula: &CompiledFormula, scene: &Scene) -> Result<Self, BuildError> {
        Self::build(
            formula,
            scene,
            scene.tree.into(),
            &AtomicBool::new(false),
            None,
        )
    }

    /// Builds the tree with `settings` over the scene's domain; `cancel` is polled often
    /// (once set, the build returns [`BuildError::Cancelled`]) and `progress` hears of each
    /// level.
    pub fn build(
        formula: &CompiledFormula,
        scene: &Scene,
        settings: BuildSettings,
        cancel: &AtomicBool,
        progress: Option<Progress<'_>>,
    ) -> Result<Self, BuildError> {
        let started = Instant::now();
        let params = scene.param_values(&formula.param_names());
        let tree = Tree16::build(
            formula,
            &params,
            &scene.domain.to_box(),
            settings,
            cancel,
            progress,
        )?;
        let hierarchy = Hierarchy::for_formula(&tree, formula, &params);
        Ok(Self {
            params,
            tree,
            hierarchy,
            build_ms: started.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// The camera of the scene's view at `width`×`height`, and the settings of a frame
    /// drawn through it.
    pub fn frame(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: FrameOptions,
    ) -> (Camera, Uniforms) {
        let camera = Camera::new(&scene.domain, &scene.view, width, height);
        let uniforms = Uniforms::new(
            &camera,
            &scene.render,
            &scene.domain,
            &self.hierarchy,
            &self.params,
            options,
        );
        (camera, uniforms)
    }
}
