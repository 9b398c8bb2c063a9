//! What the viewer knows, apart from how it is drawn: the scene being edited, the last formula
//! that compiled (and its validated shader), the tree built for it, and the background job
//! that builds the next one. The egui layer (`app.rs`) only reads this and calls its methods,
//! so tests can drive it the way the window does.
//!
//! An edit flows one way: text → parse + gradient → WGSL + naga validation (on the UI thread:
//! milliseconds) → tree build, hierarchy and pipeline creation (a background thread, cancelled
//! when a newer edit arrives; in the web page, slices of the UI's frames, replaced by a newer
//! edit) → swap. Until the swap the last good picture stays.

use std::sync::Arc;
#[cfg(not(target_arch = "wasm32"))]
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
#[cfg(not(target_arch = "wasm32"))]
use std::sync::mpsc::{Receiver, TryRecvError, channel};

use web_time::{Duration, Instant};

use crate::formula::CompiledFormula;
use crate::render::codegen::{self, Shader};
use crate::render::{Gpu, Prepared, RayCaster, Target, TileLists};
use crate::scene::Scene;
use crate::syntax::SourceError;
use crate::tree::{BuildError, Hierarchy, TreeStats};

/// The colour target of the viewer's ray caster. RGBA8, not half floats: egui samples these
/// textures every UI frame, and on a software GPU sampling RGBA16F cost ~30-50 ms per frame
/// at 1280x800 (measured with FOURFOLD_TRACE=1). The running mean of the accumulated passes
/// is then rounded to 1/255 at each pass, which stays within a few levels of the exact mean.
pub const VIEW_TARGET: Target = Target {
    format: wgpu::TextureFormat::Rgba8Unorm,
    accumulate: true,
};

/// Milliseconds of each stage of the last edit, from the changed text to the swap.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EditTimes {
    /// Parse and symbolic gradient (one call: `CompiledFormula::compile`).
    pub compile_ms: f64,
    /// WGSL generation and naga validation.
    pub codegen_ms: f64,
    /// Tree build and hierarchy (background).
    pub tree_ms: f64,
    /// Render pipeline creation (background; 0 when only the tree changed).
    pub pipeline_ms: f64,
    /// From the changed text to the new tree and pipeline being ready.
    pub ready_ms: f64,
}

/// The running count of expensive things, for tests and the status line.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Formulas compiled (parse + gradient).
    pub compiles: u64,
    /// Render pipelines created (one per new shader).
    pub pipelines: u64,
    /// Trees built to completion.
    pub trees: u64,
}

/// What a finished background job hands back.
struct JobResult {
    generation: u64,
    formula: Arc<CompiledFormula>,
    shader: Arc<Shader>,
    params: Vec<f64>,
    /// The ray caster's hierarchy, the one certified pixels search (where this viewer draws
    /// them), and the tree's stats.
    tree: Result<(Hierarchy, Option<Hierarchy>, TreeStats), String>,
    caster: Option<Result<RayCaster, String>>,
    tree_ms: f64,
    pipeline_ms: f64,
    /// The brute-force setting the pipeline was warmed up for.
    brute_force: bool,
}

/// What a build needs besides the tree, and makes of it.
struct JobInputs {
    generation: u64,
    formula: Arc<CompiledFormula>,
    shader: Arc<Shader>,
    scene: Scene,
    gpu: Option<Gpu>,
    /// Make the ray caster too (the shader is new, or brute force changes).
    make_pipeline: bool,
    /// The brute-force setting the pipeline is warmed up for.
    brute_force: bool,
}

/// A background build in flight.
struct Job {
    generation: u64,
    work: Work,
    started: Instant,
    compile_ms: f64,
    codegen_ms: f64,
}

/// Where a build runs: on a thread beside the window's, or (in the web page, which has one
/// thread) in slices of the window's own frames.
enum Work {
    #[cfg(not(target_arch = "wasm32"))]
    Thread {
        cancel: Arc<AtomicBool>,
        progress: Arc<AtomicU64>,
        receiver: Receiver<JobResult>,
    },
    #[cfg(target_arch = "wasm32")]
    Slices(Box<(crate::render::PrepareSteps, JobInputs)>),
}

/// How long a UI frame spends on a build run in slices, at least and at most: as long as the
/// rest of the frame takes (see `Session::slice_budget`), so the page keeps at least half
/// its frame rate while the tree grows, and a slow page (a software GPU) still builds fast.
pub const SLICE_BUDGET: std::ops::RangeInclusive<Duration> =
    Duration::from_millis(10)..=Duration::from_millis(100);

/// The picture-making state of the viewer.
pub struct Session {
    /// The scene as the user has set it; `scene.formula` is the last text that compiled.
    pub scene: Scene,
    /// The text in the editor (may not compile).
    pub text: String,
    /// The caret message of the text, if it does not compile (or why its picture failed).
    pub error: Option<String>,
    /// Where in the text the compile error is, for the editor to point at it.
    pub error_at: Option<SourceError>,
    /// The compiled formula of the picture on screen (or being built).
    pub formula: Option<Arc<CompiledFormula>>,
    pub shader: Option<Arc<Shader>>,
    /// The parameter values the current tree was built with.
    pub tree_params: Vec<f64>,
    pub stats: Option<TreeStats>,
    pub times: EditTimes,
    pub counters: Counters,
    /// Bumped whenever the picture must be redrawn from scratch (new tree, pipeline or
    /// settings); the renderer compares it with the generation it drew.
    pub picture_generation: u64,
    pub caster: Option<RayCaster>,
    pub hierarchy: Option<Arc<Hierarchy>>,
    /// The boxes certified pixels search (`Hierarchy::for_certifying`).
    pub certifying: Option<Arc<Hierarchy>>,
    /// The boxes the ray caster marches, in words (worked out once per tree, for the
    /// status line).
    pub marched: Option<String>,
    job: Option<Job>,
    generation: u64,
    /// The edit whose timing runs from its text change (`Instant`) to its first frame.
    pub edit_started: Option<Instant>,
    /// How long the next UI frame may spend on a build run in slices (the window sets it
    /// from its frame time, within [`SLICE_BUDGET`]).
    pub slice_budget: Duration,
    /// A brute-force setting waiting for its pipeline (warmed up in the background, so that
    /// the window never waits for a driver compiling it at its first draw).
    pub pending_brute_force: Option<bool>,
}

impl Session {
    pub fn new(mut scene: Scene) -> Self {
        scene.render.certified &= super::CERTIFIED_PIXELS;
        let text = scene.formula.clone();
        Self {
            scene,
            text,
            error: None,
            error_at: None,
            formula: None,
            shader: None,
            tree_params: Vec::new(),
            stats: None,
            times: EditTimes::default(),
            counters: Counters::default(),
            picture_generation: 0,
            caster: None,
            hierarchy: None,
            certifying: None,
            marched: None,
            job: None,
            generation: 0,
            edit_started: None,
            slice_budget: *SLICE_BUDGET.start(),
            pending_brute_force: None,
        }
    }

    /// True while a tree or pipeline is being built.
    pub fn building(&self) -> bool {
        self.job.is_some()
    }

    /// Nodes made so far by the build in flight.
    pub fn build_progress(&self) -> Option<u64> {
        self.job.as_ref().map(|j| match &j.work {
            #[cfg(not(target_arch = "wasm32"))]
            Work::Thread { progress, .. } => progress.load(Ordering::Relaxed),
            #[cfg(target_arch = "wasm32")]
            Work::Slices(slices) => slices.0.nodes(),
        })
    }

    /// The parameter names of the current formula, in uniform order.
    pub fn param_names(&self) -> Vec<String> {
        self.formula
            .as_ref()
            .map(|f| f.param_names().iter().map(|s| s.to_string()).collect())
            .unwrap_or_default()
    }

    /// Parameter values for the current formula, from the scene.
    pub fn param_values(&self) -> Vec<f64> {
        match &self.formula {
            Some(f) => self.scene.param_values(&f.param_names()),
            None => Vec::new(),
        }
    }

    /// The editor text changed: compile it; on success start building its picture, on failure
    /// keep the last good one and show the error.
    pub fn set_text(&mut self, text: &str, gpu: Option<&Gpu>) {
        self.text = text.to_string();
        let started = Instant::now();
        let compiled = CompiledFormula::compile(text);
        let compile_ms = ms(started);
        self.counters.compiles += 1;
        let formula = match compiled {
            Ok(f) => f,
            Err(e) => {
                self.error = Some(e.render("formula", text));
                self.error_at = Some(e);
                return;
            }
        };
        self.error_at = None;
        let t = Instant::now();
        let shader = match codegen::generate(&formula) {
            Ok(s) => s,
            Err(e) => {
                self.error = Some(format!("the shader for this formula is invalid: {e}"));
                return;
            }
        };
        let codegen_ms = ms(t);
        self.error = None;
        let text = text.trim().to_string();
        if self.scene.formula != text {
            // The scene's explanation was about its own formula.
            self.scene.description.clear();
        }
        self.scene.formula = text;
        // New parameters get 1.0 (or their old value), as on the command line.
        for name in formula.param_names() {
            self.scene.params.entry(name.to_string()).or_insert(1.0);
        }
        self.start_job(
            Arc::new(formula),
            Arc::new(shader),
            true,
            gpu,
            started,
            compile_ms,
            codegen_ms,
        );
    }

    /// Parameters, domain or tree settings changed: rebuild the tree for the same shader.
    pub fn rebuild_tree(&mut self, gpu: Option<&Gpu>) {
        let (Some(formula), Some(shader)) = (self.formula.clone(), self.shader.clone()) else {
            // Nothing compiled yet: compile the scene's formula instead.
            let text = self.text.clone();
            self.set_text(&text, gpu);
            return;
        };
        self.start_job(formula, shader, false, gpu, Instant::now(), 0.0, 0.0);
    }

    /// Switches brute force on or off once a caster warmed up for it is ready (until then the
    /// picture keeps its mode).
    pub fn set_brute_force(&mut self, on: bool, gpu: Option<&Gpu>) {
        if self
            .pending_brute_force
            .unwrap_or(self.scene.render.brute_force)
            == on
        {
            return;
        }
        match (self.formula.clone(), self.shader.clone()) {
            (Some(formula), Some(shader)) if gpu.is_some() => {
                self.pending_brute_force = Some(on);
                self.start_job(formula, shader, true, gpu, Instant::now(), 0.0, 0.0);
            }
            _ => self.scene.render.brute_force = on,
        }
    }

    /// Replaces the whole scene (a preset or a file) and builds it.
    pub fn load_scene(&mut self, mut scene: Scene, gpu: Option<&Gpu>) {
        scene.render.certified &= super::CERTIFIED_PIXELS;
        let text = scene.formula.clone();
        self.scene = scene;
        self.formula = None;
        self.shader = None;
        self.set_text(&text, gpu);
    }

    #[allow(clippy::too_many_arguments)]
    fn start_job(
        &mut self,
        formula: Arc<CompiledFormula>,
        shader: Arc<Shader>,
        new_shader: bool,
        gpu: Option<&Gpu>,
        started: Instant,
        compile_ms: f64,
        codegen_ms: f64,
    ) {
        #[cfg(not(target_arch = "wasm32"))]
        if let Some(Job {
            work: Work::Thread { cancel, .. },
            ..
        }) = self.job.take()
        {
            cancel.store(true, Ordering::Relaxed);
        }
        self.generation += 1;
        let generation = self.generation;
        // When the shader is new, the pipeline is made here too, off the UI thread.
        // (Also while a brute-force switch waits for its pipeline: this job replaces the one
        // that was making it.)
        let inputs = JobInputs {
            generation,
            formula,
            shader,
            scene: self.scene.clone(),
            gpu: gpu.cloned(),
            make_pipeline: new_shader
                || self.caster.is_none()
                || self.pending_brute_force.is_some(),
            brute_force: self
                .pending_brute_force
                .unwrap_or(self.scene.render.brute_force),
        };
        let work = match start_work(inputs) {
            Ok(work) => work,
            Err(e) => {
                self.error = Some(e);
                self.job = None;
                return;
            }
        };
        self.job = Some(Job {
            generation,
            work,
            started,
            compile_ms,
            codegen_ms,
        });
        self.edit_started = Some(started);
    }

    /// Takes a finished build, if any; returns true when the picture changed.
    pub fn poll(&mut self, gpu: Option<&Gpu>) -> bool {
        let Some(job) = &mut self.job else {
            return false;
        };
        let result = match &mut job.work {
            #[cfg(not(target_arch = "wasm32"))]
            Work::Thread { receiver, .. } => match receiver.try_recv() {
                Ok(r) => r,
                Err(TryRecvError::Empty) => return false,
                Err(TryRecvError::Disconnected) => {
                    // Cancelled (a newer job replaced it) or the thread died.
                    self.job = None;
                    return false;
                }
            },
            #[cfg(target_arch = "wasm32")]
            Work::Slices(slices) => {
                let (steps, inputs) = &mut **slices;
                match steps.step(&inputs.formula, self.slice_budget) {
                    Ok(None) => return false,
                    Ok(Some(prepared)) => inputs.finish(Ok(prepared)),
                    Err(e) => inputs.finish(Err(e)),
                }
            }
        };
        let job = self.job.take().expect("checked above");
        if result.generation != job.generation {
            return false;
        }
        let (hierarchy, certifying, stats) = match result.tree {
            Ok(t) => t,
            Err(e) => {
                self.error = Some(e);
                return false;
            }
        };
        let new_caster = result.caster.is_some();
        match result.caster {
            Some(Ok(caster)) => {
                self.caster = Some(caster);
                self.counters.pipelines += 1;
            }
            Some(Err(e)) => {
                self.error = Some(e);
                return false;
            }
            None => {
                if let (Some(caster), Some(gpu)) = (&mut self.caster, gpu)
                    && let Err(e) = caster.set_hierarchy(gpu, &hierarchy)
                {
                    self.error = Some(e.to_string());
                    return false;
                }
            }
        }
        self.counters.trees += 1;
        if new_caster || self.pending_brute_force.is_none() {
            self.scene.render.brute_force = result.brute_force;
            self.pending_brute_force = None;
        }
        self.formula = Some(result.formula);
        self.shader = Some(result.shader);
        self.tree_params = result.params;
        self.marched = Some(hierarchy.march_summary());
        self.hierarchy = Some(Arc::new(hierarchy));
        self.certifying = certifying.map(Arc::new);
        self.stats = Some(stats);
        self.times = EditTimes {
            compile_ms: job.compile_ms,
            codegen_ms: job.codegen_ms,
            tree_ms: result.tree_ms,
            pipeline_ms: result.pipeline_ms,
            ready_ms: ms(job.started),
        };
        self.picture_generation += 1;
        true
    }

    /// Blocks until the build in flight is done (tests, benchmarks, export).
    pub fn wait(&mut self, gpu: Option<&Gpu>) -> bool {
        let mut changed = false;
        while self.job.is_some() {
            changed |= self.poll(gpu);
            #[cfg(not(target_arch = "wasm32"))]
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        changed
    }

    /// A one-line summary of the tree for the status bar.
    pub fn tree_summary(&self) -> String {
        let Some(s) = &self.stats else {
            return "no tree yet".to_string();
        };
        if s.leaves == 0 {
            return "no surface in this domain (the tree kept no box)".to_string();
        }
        let mut line = format!("{} nodes, {} leaves", s.nodes, s.leaves);
        if let Some(cut) = self
            .marched
            .as_ref()
            .filter(|_| !self.scene.render.brute_force)
        {
            line.push_str(&format!(" (marched as {cut})"));
        }
        if s.budget_hit {
            line.push_str(", node budget hit (tree coarser than max level)");
        }
        if s.singular_boxes > 0 {
            line.push_str(&format!(", {} singular boxes", s.singular_boxes));
        }
        line.push_str(&format!(", built in {:.0} ms", s.build_ms));
        line
    }
}

/// Starts a build: on a thread of its own where there are threads, else in slices.
#[cfg(not(target_arch = "wasm32"))]
fn start_work(inputs: JobInputs) -> Result<Work, String> {
    let cancel = Arc::new(AtomicBool::new(false));
    let progress = Arc::new(AtomicU64::new(0));
    let (sender, receiver) = channel();
    let (thread_cancel, thread_progress) = (cancel.clone(), progress.clone());
    std::thread::Builder::new()
        .name("fourfold build".into())
        .spawn(move || {
            let report = |_level: u32, nodes: u64| thread_progress.store(nodes, Ordering::Relaxed);
            let settings = inputs.scene.tree.into();
            let prepared = Prepared::build(
                &inputs.formula,
                &inputs.scene,
                settings,
                &thread_cancel,
                Some(&report),
            );
            if !matches!(prepared, Err(BuildError::Cancelled)) {
                let _ = sender.send(inputs.finish(prepared));
            }
        })
        .map_err(|e| format!("could not start the tree build: {e}"))?;
    Ok(Work::Thread {
        cancel,
        progress,
        receiver,
    })
}

/// Starts a build: on a thread of its own where there are threads, else in slices.
#[cfg(target_arch = "wasm32")]
fn start_work(inputs: JobInputs) -> Result<Work, String> {
    let settings = inputs.scene.tree.into();
    let steps =
        Prepared::steps(&inputs.formula, &inputs.scene, settings).map_err(|e| e.to_string())?;
    Ok(Work::Slices(Box::new((steps, inputs))))
}

impl JobInputs {
    /// The result of a build: the tree, and the ray caster where one is to be made.
    fn finish(&self, prepared: Result<Prepared, BuildError>) -> JobResult {
        let (tree, params, tree_ms) = match prepared {
            Ok(p) => {
                // Made with every tree (about a tenth of its build, on the build's thread) so
                // that the switch shows certified pixels at once; not where none are drawn.
                let certifying =
                    super::CERTIFIED_PIXELS.then(|| Hierarchy::for_certifying(&p.tree));
                (
                    Ok((p.hierarchy, certifying, p.tree.stats)),
                    p.params,
                    p.build_ms,
                )
            }
            Err(e) => (Err(e.to_string()), Vec::new(), 0.0),
        };
        let t = Instant::now();
        let caster = match (&self.gpu, &tree) {
            (Some(gpu), Ok((hierarchy, _, _))) if self.make_pipeline => Some(
                RayCaster::with_target(gpu, &self.shader, hierarchy, VIEW_TARGET)
                    .map_err(|e| e.to_string())
                    .and_then(|mut caster| {
                        // One 1x1 draw here, so that a driver that compiles the shader at its
                        // first draw (llvmpipe) does it off the UI thread. (The browser compiles
                        // at pipeline creation, and a page cannot wait for a read-back.)
                        if cfg!(target_arch = "wasm32") {
                            Ok(caster)
                        } else {
                            warm_up(gpu, &mut caster, hierarchy, self.brute_force).map(|()| caster)
                        }
                    }),
            ),
            _ => None,
        };
        let pipeline_ms = if caster.is_some() { ms(t) } else { 0.0 };
        JobResult {
            brute_force: self.brute_force,
            generation: self.generation,
            formula: self.formula.clone(),
            shader: self.shader.clone(),
            params,
            tree,
            caster,
            tree_ms,
            pipeline_ms,
        }
    }
}

/// Draws one pixel with the pipeline the viewer will draw with: brute force, or tile lists
/// (empty ones bound).
fn warm_up(
    gpu: &Gpu,
    caster: &mut RayCaster,
    hierarchy: &Hierarchy,
    brute_force: bool,
) -> Result<(), String> {
    let mut scene = Scene::from_formula("0");
    scene.render.brute_force = brute_force;
    let camera = crate::render::Camera::new(&scene.domain, &scene.view, 1, 1);
    caster.set_tiles(gpu, Some(&TileLists::build(&Hierarchy::default(), &camera)));
    let uniforms = crate::render::Uniforms::new(
        &camera,
        &scene.render,
        &scene.domain,
        hierarchy,
        &[],
        Default::default(),
    );
    caster
        .render_rgba(gpu, &uniforms)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
