//! The one preparation of a picture, shared by the CLI, the viewer, the benchmarks and the
//! tests: a compiled formula and a scene → the parameter values, the 16-tree and the sphere
//! hierarchy the ray caster marches; then, per view, the camera and the frame's settings.

use std::sync::OnceLock;
use std::sync::atomic::AtomicBool;

use web_time::{Duration, Instant};

use crate::formula::CompiledFormula;
use crate::scene::{ColorBy, Scene};
use crate::tree::{BuildError, BuildSettings, Hierarchy, Progress, Region, Tree16, TreeSteps};

use super::view::{Camera, FrameOptions, Rotation4, Section, Uniforms, frame};

/// What the ray caster draws a scene from, apart from the view.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The parameter values, in the formula's order (1.0 where the scene has none).
    pub params: Vec<f64>,
    pub tree: Tree16,
    pub hierarchy: Hierarchy,
    /// The part of the domain the tree was built within ([`Prepared::for_picture`]), or
    /// `None`: all of it.
    pub region: Option<Region>,
    /// Milliseconds for the tree and the hierarchy.
    pub build_ms: f64,
    /// The boxes certified pixels search (`Hierarchy::for_certifying`), made when first
    /// asked for.
    certifying: OnceLock<Hierarchy>,
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
        Self::build_within(formula, scene, None, settings, cancel, progress)
    }

    /// For one picture of the scene's own view (`render`'s, Python's): where it is a slice
    /// or a slab, the tree holds only the boxes that meet its hyperplane or band
    /// ([`view_region`]), which is all that picture's rays reach. With `fit` (the view framed
    /// to all of M first) the tree covers the domain. A view turned or moved afterwards needs
    /// a preparation of its own.
    pub fn for_picture(
        formula: &CompiledFormula,
        scene: &Scene,
        fit: bool,
        cancel: &AtomicBool,
    ) -> Result<Self, BuildError> {
        let region = if fit { None } else { view_region(scene) };
        Self::build_within(formula, scene, region, scene.tree.into(), cancel, None)
    }

    fn build_within(
        formula: &CompiledFormula,
        scene: &Scene,
        region: Option<Region>,
        settings: BuildSettings,
        cancel: &AtomicBool,
        progress: Option<Progress<'_>>,
    ) -> Result<Self, BuildError> {
        let started = Instant::now();
        let params = scene.param_values(&formula.param_names());
        let tree = Tree16::build_within(
            formula,
            &params,
            &scene.domain.to_box(),
            region,
            settings,
            cancel,
            progress,
        )?;
        let hierarchy = Hierarchy::for_formula(&tree, formula, &params);
        Ok(Self {
            params,
            tree,
            hierarchy,
            region,
            build_ms: started.elapsed().as_secs_f64() * 1e3,
            certifying: OnceLock::new(),
        })
    }

    /// The boxes certified pixels search: the tree's, finer than the ray caster's cut
    /// (`formula` is the one the tree was built for).
    pub fn certifying(&self, formula: &CompiledFormula) -> &Hierarchy {
        self.certifying
            .get_or_init(|| Hierarchy::for_certifying(&self.tree, formula, &self.params))
    }

    /// The same preparation in steps of about `budget` each (see [`PrepareSteps`]).
    pub fn steps(
        formula: &CompiledFormula,
        scene: &Scene,
        settings: BuildSettings,
    ) -> Result<PrepareSteps, BuildError> {
        let params = scene.param_values(&formula.param_names());
        let tree = TreeSteps::new(formula, &params, &scene.domain.to_box(), settings)?;
        Ok(PrepareSteps { params, tree })
    }

    /// The tree's statistics with the settings it was built with and the hierarchy the
    /// ray caster marches, as JSON (what `fourfold tree --json` prints and the Python
    /// package reads): `bytes` is the hierarchy's, `tree_bytes` the tree's.
    pub fn tree_report(&self, settings: BuildSettings) -> serde_json::Value {
        let mut value = serde_json::to_value(&self.tree.stats).expect("stats serialise");
        value["tree_bytes"] = value["bytes"].clone();
        value["bytes"] = self.hierarchy.bytes().into();
        value["march_level"] = self.hierarchy.march_level.into();
        value["gpu_nodes"] = self.hierarchy.nodes.len().into();
        value["max_level"] = settings.max_level.into();
        value["min_level"] = settings.min_level.into();
        value["node_budget"] = settings.node_budget.into();
        value
    }

    /// The camera of the scene's view at `width`×`height`, and the settings of a frame
    /// drawn through it (see [`frame`]).
    pub fn frame(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: FrameOptions,
    ) -> (Camera, Uniforms) {
        frame(
            scene,
            &self.hierarchy,
            &self.params,
            [width, height],
            options,
        )
    }
}

/// The part of the domain a picture of the scene's view reaches: a slice's hyperplane or a
/// slab's band across n2 (from the domain's centre, as the camera places them), widened by
/// [`crate::tree::REGION_MARGIN`] of the domain's half-diagonal plus its centre's largest
/// coordinate (in magnitude), far more than a ray's points worked out in f32 stray; `None` for a projection,
/// and for a picture coloured by the hidden direction (its colours span M's range along n2).
pub fn view_region(scene: &Scene) -> Option<Region> {
    if scene.render.color_by == ColorBy::Hidden {
        return None;
    }
    let (offset, half) = match Section::of(&scene.view) {
        Section::Plane => return None,
        Section::Slice { offset } => (offset, 0.0),
        Section::Slab { center, half } => (center, half),
    };
    let n2 = Rotation4::from_angles(scene.view.angles).row(3);
    let centre = scene.domain.center();
    let far = centre.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    let reach = scene.domain.half_diagonal() + far;
    Some(Region::band(n2, centre, offset, half, reach))
}

/// A preparation that runs a little at a time, between the frames of a window that has no
/// other thread to give it (the web page): the tree is refined in slices of a level, then the
/// hierarchy is made in one go (a few milliseconds at the viewer's levels).
pub struct PrepareSteps {
    params: Vec<f64>,
    tree: TreeSteps,
}

/// Boxes refined between two looks at the clock: a few milliseconds of work on one core.
const BOXES_PER_SLICE: usize = 64;

impl PrepareSteps {
    /// Works for about `budget`; the prepared scene once it is complete. `formula` must be
    /// the one the steps were made for.
    pub fn step(
        &mut self,
        formula: &CompiledFormula,
        budget: Duration,
    ) -> Result<Option<Prepared>, BuildError> {
        let started = Instant::now();
        let never = AtomicBool::new(false);
        loop {
            if let Some(tree) = self
                .tree
                .step(formula, &self.params, &never, BOXES_PER_SLICE)?
            {
                let t = Instant::now();
                let hierarchy = Hierarchy::for_formula(&tree, formula, &self.params);
                let build_ms = tree.stats.build_ms + t.elapsed().as_secs_f64() * 1e3;
                return Ok(Some(Prepared {
                    params: std::mem::take(&mut self.params),
                    tree,
                    hierarchy,
                    region: None,
                    build_ms,
                    certifying: OnceLock::new(),
                }));
            }
            if started.elapsed() >= budget {
                return Ok(None);
            }
        }
    }

    /// Nodes made so far.
    pub fn nodes(&self) -> u64 {
        self.tree.nodes()
    }
}
