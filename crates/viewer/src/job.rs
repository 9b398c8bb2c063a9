//! The background half of an edit: the tree and hierarchy for a program (the library's
//! `Prepared`), the boxes certified pixels search, and where the shader is new the viewer's
//! ray caster: the interpreting shader's (compiled once per run) drawing the new formula at
//! once where it can, else the formula's own, warmed up where the platform can wait for it.
//! It runs on a thread natively and in slices of the window's frames in a web page (the
//! platform's `BuildWork`).

use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};

use web_time::Instant;

use fourfold::CompiledFormula;
use fourfold::render::{Gpu, Prepared, Program, RayCaster, Target};
use fourfold::scene::Scene;
use fourfold::tree::{BuildError, Hierarchy, TreeStats};

/// The colour target of the viewer's ray caster. RGBA8, not half floats: egui samples these
/// textures every UI frame, and on a software GPU sampling RGBA16F cost several times more
/// (docs/benchmarks.md). The running mean of the accumulated passes is then rounded to 1/255
/// at each pass, which stays within a few levels of the exact mean.
pub const VIEW_TARGET: Target = Target {
    format: wgpu::TextureFormat::Rgba8Unorm,
    accumulate: true,
};

/// How a platform readies a new ray caster for its first draw: given the GPU, the caster,
/// its hierarchy and the scene its first frames draw.
pub type WarmUp = fn(&Gpu, &mut RayCaster, &Hierarchy, &Scene) -> Result<(), String>;

/// What a build needs besides the tree, and makes of it.
pub struct JobInputs {
    pub generation: u64,
    pub program: Program,
    pub scene: Scene,
    pub gpu: Option<Gpu>,
    /// Make the ray caster too (the shader is new, or brute force changes).
    pub make_pipeline: bool,
    /// Make it without pipelines: frames build those they draw with (see
    /// `Session::previews_on_cpu`).
    pub pipeline_at_first_draw: bool,
    /// The brute-force setting the pipeline is warmed up for.
    pub brute_force: bool,
    /// The interpreting shader's caster, once built (`build_interpreter`): a new shader's
    /// first frames draw with it while the formula's own shader compiles.
    pub interpreter: Option<Arc<RayCaster>>,
}

/// A built tree as the viewer keeps it: the ray caster's hierarchy, the one certified
/// pixels search, and the tree's stats.
pub type Built = (Arc<Hierarchy>, Arc<Hierarchy>, TreeStats);

/// What a finished build hands back.
pub struct JobResult {
    pub generation: u64,
    pub program: Program,
    pub params: Vec<f64>,
    pub tree: Result<Built, String>,
    pub caster: Option<Result<RayCaster, String>>,
    pub tree_ms: f64,
    /// The caster's pipeline and its warm-up draw.
    pub pipeline_ms: f64,
    /// Of `pipeline_ms`, the warm-up draw (a driver may compile at the first draw).
    pub warm_up_ms: f64,
    /// The brute-force setting the pipeline was warmed up for.
    pub brute_force: bool,
    /// The formula's own pipelines for `caster`, where they are being built beside the
    /// window (natively; a page builds the certified one at its first certified frame).
    pub settling: Option<Settling>,
}

/// The formula's own pipelines being built and warmed up on the build's thread after the
/// caster they belong to was handed over, so that the edit's first preview does not wait
/// for their compile (hundreds of milliseconds on llvmpipe, about half a second on a GPU's
/// driver; the settled picture does, if still): where the caster interprets, a caster of
/// the formula's own shader (`RayCaster::take_shader`), else the certified pipeline in a
/// sibling (`RayCaster::adopt`). Dropping it abandons the build if it has not started.
pub struct Settling {
    pub receiver: Receiver<Result<RayCaster, String>>,
    /// Never sent on: its receiver on the build's thread sees it dropped with the Settling.
    pub wanted: Sender<()>,
}

impl Settling {
    /// The caster holding the pipelines once they are built; Err if they never will be
    /// (with why, where the GPU said), None while they are being built.
    pub fn poll(&self) -> Option<Result<RayCaster, Option<String>>> {
        match self.receiver.try_recv() {
            Ok(built) => Some(built.map_err(Some)),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => Some(Err(None)),
        }
    }
}

impl JobInputs {
    /// The result of a build: the tree, and the ray caster where one is to be made, warmed
    /// up by `warm_up` (the platform's: a native build can wait for the GPU, a page not).
    pub fn finish(&self, prepared: Result<Prepared, BuildError>, warm_up: WarmUp) -> JobResult {
        let (tree, params, tree_ms) = match prepared {
            Ok(p) => {
                // Made with every tree (about a tenth of its build, off the window's frames
                // natively) so that the switch shows certified pixels at once.
                let certifying = Arc::new(Hierarchy::for_certifying(
                    &p.tree,
                    &self.program.formula,
                    &p.params,
                ));
                let build_ms = p.build_ms;
                let Prepared {
                    params,
                    tree,
                    hierarchy,
                    ..
                } = p;
                (
                    Ok((Arc::new(hierarchy), certifying, tree.stats)),
                    params,
                    build_ms,
                )
            }
            Err(e) => (Err(e.to_string()), Vec::new(), 0.0),
        };
        let t = Instant::now();
        let mut warm_up_ms = 0.0;
        let caster = match (&self.gpu, &tree) {
            (Some(gpu), Ok((hierarchy, _, _))) if self.make_pipeline => {
                let first = first_frames(&self.scene, self.brute_force);
                let shader = &self.program.shader;
                Some(match self.interpreted(gpu, hierarchy, &first) {
                    Some(caster) => Ok(caster),
                    None if self.pipeline_at_first_draw => {
                        RayCaster::without_pipelines(gpu, shader, hierarchy, VIEW_TARGET)
                            .map_err(|e| e.to_string())
                    }
                    None => RayCaster::for_scene(gpu, shader, hierarchy, VIEW_TARGET, &first)
                        .map_err(|e| e.to_string())
                        .and_then(|mut caster| {
                            let w = Instant::now();
                            warm_up(gpu, &mut caster, hierarchy, &first)?;
                            warm_up_ms = ms(w);
                            Ok(caster)
                        }),
                })
            }
            _ => None,
        };
        let pipeline_ms = if caster.is_some() { ms(t) } else { 0.0 };
        JobResult {
            brute_force: self.brute_force,
            generation: self.generation,
            program: self.program.clone(),
            params,
            tree,
            caster,
            tree_ms,
            pipeline_ms,
            warm_up_ms,
            settling: None,
        }
    }

    /// A caster of the interpreting shader drawing the program over `hierarchy`, where the
    /// interpreter is built, has the pipeline `first` draws with, and holds the formula's
    /// tapes (None: the formula's own shader draws from the first frame).
    fn interpreted(&self, gpu: &Gpu, hierarchy: &Hierarchy, first: &Scene) -> Option<RayCaster> {
        let interpreter = self.interpreter.as_ref()?;
        if !interpreter.has_pipeline_for(first, hierarchy) {
            return None;
        }
        interpreter
            .interpret(gpu, &self.program.formula, hierarchy)
            .ok()
    }

    /// Builds the interpreting shader's pipeline for this job's first frames where it lacks
    /// it (a slice's, a slab's, brute force's...), so that the next new formula drawn so
    /// draws with it at once (this one drew with its own shader).
    pub fn complete_interpreter(&self) {
        if let (Some(interpreter), Some(gpu)) = (&self.interpreter, &self.gpu) {
            let first = first_frames(&self.scene, self.brute_force);
            interpreter.build_pipeline_for(gpu, &first, &Hierarchy::default());
        }
    }

    /// What a caster of the formula's own shader is built from, to take over from an
    /// interpreting one.
    pub fn own_caster(&self) -> CasterPlan {
        CasterPlan::new(self.program.shader.clone(), &self.scene, self.brute_force)
    }

    /// What the settled picture draws where it differs from the first frames: certified,
    /// where the scene is (None where it is not).
    pub fn settled_scene(&self) -> Option<Scene> {
        let first = first_frames(&self.scene, self.brute_force);
        self.scene.render.certified.then(|| settled_frames(&first))
    }
}

pub fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// What the first frames of a picture of `scene` draw: plain (certified pixels come once the
/// view is still), brute force or not as the pipeline is made for. Their pipeline is built
/// with the caster, not in a frame.
pub fn first_frames(scene: &Scene, brute_force: bool) -> Scene {
    let mut first = scene.clone();
    first.render.certified = false;
    first.render.brute_force = brute_force;
    first
}

/// What the settled picture of `first` (`first_frames`) draws: the same, certified.
pub fn settled_frames(first: &Scene) -> Scene {
    let mut settled = first.clone();
    settled.render.certified = true;
    settled
}

/// A caster to build beside the window, with the pipelines a scene's frames draw with: its
/// first frames' and, where the scene is certified, its settled picture's. (A formula's own
/// caster, which takes over from an interpreting one with `RayCaster::take_shader`; the
/// projection's beside a slice.)
pub struct CasterPlan {
    shader: Arc<fourfold::render::Shader>,
    first: Scene,
    settled: Option<Scene>,
}

impl CasterPlan {
    /// For `scene`'s frames drawn with `shader`, brute force or not as `brute_force` says.
    pub fn new(shader: Arc<fourfold::render::Shader>, scene: &Scene, brute_force: bool) -> Self {
        let first = first_frames(scene, brute_force);
        let settled = scene.render.certified.then(|| settled_frames(&first));
        Self {
            shader,
            first,
            settled,
        }
    }

    /// The caster for `hierarchy`, its pipelines built and warmed up over it.
    pub fn build(
        &self,
        gpu: &Gpu,
        hierarchy: &Hierarchy,
        warm_up: WarmUp,
    ) -> Result<RayCaster, String> {
        let mut caster =
            RayCaster::for_scene(gpu, &self.shader, hierarchy, VIEW_TARGET, &self.first)
                .map_err(|e| e.to_string())?;
        warm_up(gpu, &mut caster, hierarchy, &self.first)?;
        if let Some(settled) = &self.settled {
            warm_up(gpu, &mut caster, hierarchy, settled)?;
        }
        Ok(caster)
    }
}

/// The interpreting shader's caster, its pipeline for the first frames of `scene` built and
/// warmed up by drawing `formula` over `hierarchy` (a driver may compile at the first draw
/// that reaches the pixels' code); None where the GPU refused it: edits then draw with
/// their own shaders.
pub fn build_interpreter(
    gpu: &Gpu,
    scene: &Scene,
    formula: &CompiledFormula,
    hierarchy: &Hierarchy,
    warm_up: WarmUp,
) -> Option<RayCaster> {
    let shader = fourfold::render::shader::interpreter().ok()?;
    let first = first_frames(scene, scene.render.brute_force);
    let empty = Hierarchy::default();
    let mut caster = RayCaster::for_scene(gpu, &shader, &empty, VIEW_TARGET, &first).ok()?;
    match caster.interpret(gpu, formula, hierarchy) {
        Ok(mut drawing) => warm_up(gpu, &mut drawing, hierarchy, &first).ok()?,
        // (Too many registers: the pipeline alone.)
        Err(_) => warm_up(gpu, &mut caster, &empty, &first).ok()?,
    }
    Some(caster)
}
