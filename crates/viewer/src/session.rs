//! What the viewer knows, apart from how it is drawn: the scene being edited, the last formula
//! that compiled (and its validated shader), the tree built for it, and the background job
//! that builds the next one. The egui layer (`app/`) only reads this and calls its methods,
//! so tests can drive it the way the window does.
//!
//! An edit flows one way: text → the library's `Program` (parse, gradient, WGSL + naga
//! validation: milliseconds, on the UI thread) → tree, hierarchy and pipeline (`job.rs`: a
//! background thread, cancelled when a newer edit arrives; in the web page, slices of the
//! UI's frames, replaced by a newer edit) → swap. Until the swap the last good picture
//! stays.

use std::sync::Arc;

use web_time::{Duration, Instant};

use fourfold::render::{Gpu, Program, ProgramError, RayCaster};
use fourfold::scene::Scene;
use fourfold::syntax::SourceError;
use fourfold::tree::{Hierarchy, TreeStats};

use crate::job::{JobInputs, Settling, ms};
use crate::platform::{self, BuildWork};

mod measures;
mod summary;
pub use measures::{Counters, EditTimes};

/// A background build in flight.
struct Job {
    generation: u64,
    work: BuildWork,
    started: Instant,
    compile_ms: f64,
    codegen_ms: f64,
    /// It makes a new ray caster (the shader is new, or brute force changes).
    makes_pipeline: bool,
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
    /// The compiled formula and shader of the picture on screen (or being built).
    pub program: Option<Program>,
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
    /// The formula's own pipelines, while they are built beside the window (natively,
    /// after the caster itself: an edit's first preview does not wait for them).
    settling: Option<Settling>,
    /// The interpreting shader's caster, built once (natively) after the first picture.
    interpreter: Interpreter,
    /// Whether new formulas' first frames draw with it, as set (None: the default).
    interpret: Option<bool>,
    /// A variant's pipelines built beside the window failed for this caster: frames build
    /// what they lack themselves (and the GPU's error is said).
    beside_failed: bool,
    /// New formulas' casters build their pipelines when frames first draw with them, and
    /// their first preview is drawn on the CPU meanwhile (`progressive::cpu_preview`): a
    /// page's choice (`platform::CPU_PREVIEWS`), or a test's.
    pub previews_on_cpu: bool,
}

/// The interpreting shader's caster (`job::build_interpreter`): the first frames of a new
/// formula draw with it while its own shader compiles.
enum Interpreter {
    /// Not built yet (no picture yet, or no GPU), nor found unwanted.
    Unstarted,
    Building(platform::Background<Option<Arc<RayCaster>>>),
    Ready(Arc<RayCaster>),
    /// Every formula draws with its own shader (the platform's or the adapter's choice,
    /// or `interpret_new_formulas`), or the GPU refused the interpreting one.
    Off,
}

impl Session {
    pub fn new(scene: Scene) -> Self {
        let text = scene.formula.clone();
        Self {
            scene,
            text,
            error: None,
            error_at: None,
            program: None,
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
            settling: None,
            interpreter: Interpreter::Unstarted,
            interpret: None,
            beside_failed: false,
            previews_on_cpu: platform::CPU_PREVIEWS,
        }
    }

    /// Whether the settled picture's certified pipeline is still being built, or a new
    /// caster that replaces this one (the certified pass waits: built inside a frame, its
    /// compile would stall the window).
    pub fn certified_pipeline_pending(&self) -> bool {
        self.settling.is_some() || self.job.as_ref().is_some_and(|j| j.makes_pipeline)
    }

    /// Takes the formula's own pipelines built beside the window, once they are there.
    fn adopt_settled_pipeline(&mut self, gpu: Option<&Gpu>) {
        let (Some(settling), Some(caster)) = (&self.settling, &mut self.caster) else {
            return;
        };
        match settling.poll() {
            None => return,
            Some(Ok(built)) if caster.interprets() => match (gpu, &self.program) {
                (Some(gpu), Some(program)) => {
                    caster.take_shader(gpu, built);
                    // (The formula's numbers may have changed since the own caster was
                    // made: the same shader, with the constants of the one on screen.)
                    if let Err(e) = caster.set_formula(gpu, &program.formula, &program.shader) {
                        self.error = Some(e.to_string());
                    }
                }
                _ => return,
            },
            Some(Ok(sibling)) => {
                caster.adopt(sibling);
            }
            // The formula's own shader failed: the interpreting one draws on, plain (it
            // cannot certify).
            Some(Err(why)) if caster.interprets() => {
                let why = why.unwrap_or_else(|| "its build stopped".into());
                self.error = Some(format!(
                    "the formula's own shader failed ({why}): its picture is not certified"
                ));
            }
            // Its build failed: the frames build what they lack when they first draw.
            Some(Err(_)) => self.beside_failed = true,
        }
        self.settling = None;
    }

    /// Whether the caster has the pipeline the picture's plain frames draw with, for the
    /// scene as it is now (a slice's, a slab's, more hit slots...). Where it, or the settled
    /// picture's certified one, is missing, builds them beside the window, once, rather
    /// than inside a frame (a driver compiles one for a fraction of a second): the picture
    /// waits for the plain one, the certified pass for the other.
    pub fn ready_to_draw(&mut self, gpu: Option<&Gpu>) -> bool {
        let (Some(gpu), Some(caster), Some(hierarchy)) = (gpu, &self.caster, &self.hierarchy)
        else {
            return true;
        };
        if self.previews_on_cpu {
            // (The preview is drawn on the CPU; the GPU's stages after it build the
            // pipelines they lack.)
            return true;
        }
        let first = crate::job::first_frames(&self.scene, self.scene.render.brute_force);
        let plain = caster.has_pipeline_for(&first, hierarchy);
        if caster.interprets() {
            // Its formula's own caster is coming (then asked again), or failed.
            return plain || self.settling.is_none();
        }
        if self.beside_failed {
            return true;
        }
        let mut wanted = Vec::new();
        if !plain {
            wanted.push(first.clone());
        }
        let settled = crate::job::settled_frames(&first);
        if self.scene.render.certified && !caster.has_pipeline_for(&settled, hierarchy) {
            wanted.push(settled);
        }
        // (What is in flight is taken first, and the caster asked again.)
        if wanted.is_empty() || self.settling.is_some() || self.job.is_some() {
            return plain;
        }
        match platform::pipelines_beside(gpu, caster, hierarchy, wanted) {
            Some(settling) => self.settling = Some(settling),
            None => return true,
        }
        plain
    }

    /// Whether new formulas' first frames draw with the interpreting shader: by default
    /// where the platform does and the adapter is a GPU's; on or off here (tests, the edit
    /// bench's comparison).
    pub fn interpret_new_formulas(&mut self, on: bool) {
        self.interpret = Some(on);
        self.interpreter = match std::mem::replace(&mut self.interpreter, Interpreter::Off) {
            kept @ (Interpreter::Building(_) | Interpreter::Ready(_)) if on => kept,
            _ if on => Interpreter::Unstarted,
            _ => Interpreter::Off,
        };
    }

    /// Whether new formulas' first frames draw with the interpreting shader on `gpu`: as
    /// set, else where the platform does and the adapter is a GPU's.
    pub fn interprets_new_formulas(&self, gpu: &Gpu) -> bool {
        self.interpret
            .unwrap_or(platform::INTERPRETS && !gpu.software)
    }

    /// Whether the interpreting shader is built (new formulas' first frames draw with it).
    pub fn interpreter_ready(&self) -> bool {
        matches!(self.interpreter, Interpreter::Ready(_))
    }

    /// Whether the picture on screen is drawn by the interpreting shader (its formula's
    /// own is being compiled).
    pub fn interpreting(&self) -> bool {
        self.caster.as_ref().is_some_and(RayCaster::interprets)
    }

    /// Starts building the interpreting shader's caster (once, after the first picture,
    /// where it is wanted), or takes it once built.
    fn keep_interpreter(&mut self, gpu: Option<&Gpu>) {
        match &mut self.interpreter {
            Interpreter::Unstarted => {
                let (Some(gpu), Some(program), Some(hierarchy)) =
                    (gpu.cloned(), &self.program, &self.hierarchy)
                else {
                    return;
                };
                // On a CPU's adapter the formula's own shader is ready in half a second and
                // draws 24-52 times faster than the interpreter (docs/benchmarks.md).
                if !self.interprets_new_formulas(&gpu) {
                    self.interpreter = Interpreter::Off;
                    return;
                }
                let scene = self.scene.clone();
                let (formula, hierarchy) = (program.formula.clone(), hierarchy.clone());
                self.interpreter = Interpreter::Building(platform::Background::start(
                    "fourfold interpreter",
                    move || {
                        let warm_up = platform::warm_up;
                        crate::job::build_interpreter(&gpu, &scene, &formula, &hierarchy, warm_up)
                            .map(Arc::new)
                    },
                ));
            }
            Interpreter::Building(work) => match work.poll() {
                None => {}
                Some(Some(Some(caster))) => self.interpreter = Interpreter::Ready(caster),
                Some(_) => self.interpreter = Interpreter::Off,
            },
            Interpreter::Ready(_) | Interpreter::Off => {}
        }
    }

    /// Blocks until the interpreting shader is built or given up (tests, benchmarks).
    pub fn wait_for_interpreter(&mut self, gpu: Option<&Gpu>) {
        while matches!(
            self.interpreter,
            Interpreter::Unstarted | Interpreter::Building(_)
        ) {
            if gpu.is_none() || self.hierarchy.is_none() {
                return;
            }
            self.keep_interpreter(gpu);
            platform::pause();
        }
    }

    /// True while a tree or pipeline is being built.
    pub fn building(&self) -> bool {
        self.job.is_some()
    }

    /// Nodes made so far by the build in flight.
    pub fn build_progress(&self) -> Option<u64> {
        self.job.as_ref().map(|j| j.work.progress())
    }

    /// The parameter names of the current formula, in uniform order.
    pub fn param_names(&self) -> Vec<String> {
        self.program
            .as_ref()
            .map(|p| {
                p.formula
                    .param_names()
                    .iter()
                    .map(|s| s.to_string())
                    .collect()
            })
            .unwrap_or_default()
    }

    /// Parameter values for the current formula, from the scene.
    pub fn param_values(&self) -> Vec<f64> {
        match &self.program {
            Some(p) => self.scene.param_values(&p.formula.param_names()),
            None => Vec::new(),
        }
    }

    /// The editor text changed: compile it; on success start building its picture, on failure
    /// keep the last good one and show the error.
    pub fn set_text(&mut self, text: &str, gpu: Option<&Gpu>) {
        self.text = text.to_string();
        let started = Instant::now();
        self.counters.compiles += 1;
        let program = match Program::new(text) {
            Ok(p) => p,
            Err(ProgramError::Formula(e)) => {
                self.error = Some(e.render("formula", text));
                self.error_at = Some(e);
                return;
            }
            Err(e @ ProgramError::Shader(_)) => {
                self.error_at = None;
                self.error = Some(e.to_string());
                return;
            }
        };
        self.error_at = None;
        self.error = None;
        let text = text.trim().to_string();
        if self.scene.formula != text {
            // The scene's explanation was about its own formula.
            self.scene.description.clear();
        }
        self.scene.formula = text;
        // New parameters get 1.0 (or their old value), as on the command line.
        for name in program.formula.param_names() {
            self.scene.params.entry(name.to_string()).or_insert(1.0);
        }
        let timings = (program.compile_ms, program.codegen_ms);
        // A formula whose numbers alone changed has the same shader (`shader::constants`):
        // the caster on screen draws it, with no compile.
        let new_shader = self
            .program
            .as_ref()
            .is_none_or(|p| p.shader.source != program.shader.source);
        self.start_job(program, new_shader, gpu, started, timings);
    }

    /// Parameters, domain or tree settings changed: rebuild the tree for the same shader.
    pub fn rebuild_tree(&mut self, gpu: Option<&Gpu>) {
        let Some(program) = self.program.clone() else {
            // Nothing compiled yet: compile the scene's formula instead.
            let text = self.text.clone();
            self.set_text(&text, gpu);
            return;
        };
        self.start_job(program, false, gpu, Instant::now(), (0.0, 0.0));
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
        match self.program.clone() {
            Some(program) if gpu.is_some() => {
                self.pending_brute_force = Some(on);
                self.start_job(program, true, gpu, Instant::now(), (0.0, 0.0));
            }
            _ => self.scene.render.brute_force = on,
        }
    }

    /// Replaces the whole scene (a preset or a file) and builds it.
    pub fn load_scene(&mut self, scene: Scene, gpu: Option<&Gpu>) {
        let text = scene.formula.clone();
        self.scene = scene;
        self.program = None;
        self.set_text(&text, gpu);
    }

    /// Starts building the picture of `program` (its shader `new_shader`) for the scene as
    /// it is; `timings` are the edit's compile and codegen milliseconds.
    fn start_job(
        &mut self,
        program: Program,
        new_shader: bool,
        gpu: Option<&Gpu>,
        started: Instant,
        (compile_ms, codegen_ms): (f64, f64),
    ) {
        if let Some(job) = self.job.take() {
            job.work.cancel();
        }
        self.generation += 1;
        let generation = self.generation;
        // When the shader is new, the pipeline is made here too, off the UI thread.
        // (Also while a brute-force switch waits for its pipeline: this job replaces the one
        // that was making it.)
        let makes_pipeline =
            new_shader || self.caster.is_none() || self.pending_brute_force.is_some();
        let inputs = JobInputs {
            generation,
            program,
            scene: self.scene.clone(),
            gpu: gpu.cloned(),
            make_pipeline: makes_pipeline,
            pipeline_at_first_draw: self.previews_on_cpu,
            brute_force: self
                .pending_brute_force
                .unwrap_or(self.scene.render.brute_force),
            interpreter: match &self.interpreter {
                Interpreter::Ready(caster) if new_shader => Some(caster.clone()),
                _ => None,
            },
        };
        let work = match BuildWork::start(inputs) {
            Ok(work) => work,
            Err(e) => {
                self.error = Some(e);
                self.job = None;
                return;
            }
        };
        if makes_pipeline {
            // The caster it replaces needs no certified pipeline now (one not started yet
            // is not built: its compile would only slow this build's).
            self.settling = None;
        }
        self.job = Some(Job {
            generation,
            work,
            started,
            compile_ms,
            codegen_ms,
            makes_pipeline,
        });
        self.edit_started = Some(started);
    }

    /// Takes a finished build, if any; returns true when the picture changed.
    pub fn poll(&mut self, gpu: Option<&Gpu>) -> bool {
        self.adopt_settled_pipeline(gpu);
        if self.caster.is_some() {
            self.keep_interpreter(gpu);
        }
        let Some(job) = &mut self.job else {
            return false;
        };
        let result = match job.work.poll(self.slice_budget) {
            Some(Ok(result)) => result,
            Some(Err(())) => {
                // Cancelled (a newer job replaced it) or the thread died.
                self.job = None;
                return false;
            }
            None => return false,
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
                self.settling = result.settling;
                self.beside_failed = false;
                self.counters.pipelines += 1;
            }
            Some(Err(e)) => {
                self.error = Some(e);
                return false;
            }
            None => {
                if let (Some(caster), Some(gpu)) = (&mut self.caster, gpu) {
                    let program = &result.program;
                    let set = caster
                        .set_hierarchy(gpu, &hierarchy)
                        .and_then(|()| caster.set_formula(gpu, &program.formula, &program.shader));
                    if let Err(e) = set {
                        self.error = Some(e.to_string());
                        return false;
                    }
                }
            }
        }
        self.counters.trees += 1;
        if new_caster || self.pending_brute_force.is_none() {
            self.scene.render.brute_force = result.brute_force;
            self.pending_brute_force = None;
        }
        self.program = Some(result.program);
        self.tree_params = result.params;
        self.marched = Some(hierarchy.march_summary());
        self.hierarchy = Some(hierarchy);
        self.certifying = Some(certifying);
        self.stats = Some(stats);
        self.times = EditTimes {
            compile_ms: job.compile_ms,
            codegen_ms: job.codegen_ms,
            tree_ms: result.tree_ms,
            pipeline_ms: result.pipeline_ms,
            warm_up_ms: result.warm_up_ms,
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
            platform::pause();
        }
        changed
    }

    /// The share link's `#…` part: the scene on screen, with only the parameters its formula
    /// has (the scene keeps the values of earlier formulas' parameters, for undo).
    pub fn link_fragment(&self) -> String {
        let names = self.param_names();
        let mut scene = self.scene.clone();
        if self.program.is_some() {
            scene.params.retain(|name, _| names.contains(name));
        }
        scene.to_link()
    }
}
