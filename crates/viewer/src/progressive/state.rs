//! The progressive renderer's state: which stage of which picture is being drawn, how fast
//! squares go, and what is on screen.

use std::collections::VecDeque;
use std::sync::{Arc, OnceLock};

use eframe::{egui, egui_wgpu};
use web_time::Instant;

use fourfold::CompiledFormula;
use fourfold::render::gpu::{PendingRgba, start_texture_read};
use fourfold::render::verdict::{VerdictCounts, take_marks};
use fourfold::render::view;
use fourfold::render::{Camera, FrameOptions, Gpu, Pass, RayCaster, Uniforms};
use fourfold::scene::Scene;
use fourfold::tree::Hierarchy;

use super::binning::Binner;
use super::cpu_preview::CpuPreviews;
use super::paint::{Paint, Progress, layers};
use super::stages::{self, Stage, UNIT, ViewKey, texture_index};
use super::textures::{self, StageTexture};
use crate::platform;

/// The most squares one run may hold where the window cannot wait for the GPU: 16384
/// pixels, seconds of certified squares on M on Chromium's SwiftShader.
const PAGE_RUN_SQUARES: u32 = 256;

/// Runs on their way through the GPU at most: where the word that a run is done comes a
/// frame or more later, a second one keeps the GPU busy meanwhile.
const RUNS_IN_FLIGHT: usize = if platform::WAITS_FOR_GPU { 1 } else { 2 };

/// The milliseconds of plain runs that set the measured throughput (`rays_per_ms`).
const MEASURED_MS: f64 = 20.0;

/// A run of squares on its way through the GPU: timed from its submission to the queue's
/// word that it is done (at once natively, where the window waits for it; a frame or more
/// later in a page).
struct Run {
    squares: u32,
    rays: f64,
    /// Certified pixels (a certified pass costs several plain ones a ray).
    certified: bool,
    /// The milliseconds it was sized to take.
    planned_ms: f64,
    submitted: Instant,
    done: Arc<OnceLock<Instant>>,
}

/// What a progressive picture draws: a ray caster with its hierarchy and parameter values,
/// seen as `scene` says, for the session's picture `generation` (a new one starts again).
pub struct Subject<'a> {
    pub caster: &'a mut RayCaster,
    pub hierarchy: &'a Arc<Hierarchy>,
    /// The boxes certified pixels search (`Hierarchy::for_certifying`), where the scene
    /// certifies.
    pub certifying: Option<&'a Arc<Hierarchy>>,
    /// The caster's certified pipeline is still being built beside the window: the
    /// certified pass waits for it (`Session::certified_pipeline_pending`).
    pub certifier_pending: bool,
    pub params: &'a [f64],
    /// The formula the caster draws, where new pictures preview on the CPU
    /// (`Session::previews_on_cpu`; None: they do not).
    pub formula: Option<&'a CompiledFormula>,
    pub scene: &'a Scene,
    pub generation: u64,
}

/// The progressive renderer's state.
pub struct Progressive {
    /// Screen size in pixels.
    size: [u32; 2],
    textures: Vec<StageTexture>,
    stages: Vec<Stage>,
    stage: usize,
    tile: u32,
    next_tile: u32,
    /// Measured milliseconds per square in this stage (None: not measured yet).
    unit_ms: Option<f64>,
    /// The highest stage completed for the current plan (None: nothing yet).
    completed: Option<usize>,
    /// The texture of the last completed stage of any plan: what is on screen.
    shown: Option<usize>,
    /// What the stages were planned for (the view, the session's picture generation and
    /// whether the user was interacting); a different one restarts. Plans made so far.
    key: Option<(ViewKey, u64, bool)>,
    plans: u64,
    /// Measured throughput (rays per millisecond), for sizing previews: the plain runs' rays
    /// over their milliseconds, sky and M alike, as a preview over the whole picture spends
    /// them (one run's speed is anywhere from a square of sky's to a square on M's).
    rays_per_ms: f64,
    /// The plain runs' rays and milliseconds since `rays_per_ms` was last set.
    measured: [f64; 2],
    stage_started: Option<Instant>,
    /// Wall time of the last complete full-resolution stage, and of the last preview.
    pub full_ms: Option<f64>,
    pub preview_ms: Option<f64>,
    /// Whether the current plan's preview was drawn on the CPU.
    pub preview_from_cpu: bool,
    /// Set when the first stage of a new picture generation completed.
    pub first_frame_of: Option<u64>,
    generation: u64,
    /// The tile lists the ray caster holds, and their binning.
    pub binner: Binner,
    /// A certified view's verdicts: read back from its first full-resolution stage, and
    /// the counts once they are in (None: not certified, or not yet).
    verdict_read: Option<PendingRgba>,
    pub verdicts: Option<VerdictCounts>,
    /// The runs the GPU has not finished yet (only where the window cannot wait for it),
    /// oldest first, and when the last one landed was done.
    in_flight: VecDeque<Run>,
    last_done: Option<Instant>,
    /// Whether the last step stopped to wait for a run in flight (or for the hold after a
    /// preview on the CPU), and the window to wake when it is over.
    waiting: bool,
    wake: Option<egui::Context>,
    /// New pictures' previews drawn on the CPU while their pipeline is not built (see
    /// `Subject::formula`).
    pub cpu_previews: CpuPreviews,
}

impl Default for Progressive {
    fn default() -> Self {
        Self {
            size: [0, 0],
            textures: Vec::new(),
            stages: Vec::new(),
            stage: 0,
            tile: UNIT,
            next_tile: 0,
            unit_ms: None,
            completed: None,
            shown: None,
            key: None,
            plans: 0,
            rays_per_ms: 50.0,
            measured: [0.0; 2],
            stage_started: None,
            full_ms: None,
            preview_ms: None,
            preview_from_cpu: false,
            first_frame_of: None,
            generation: 0,
            binner: Binner::default(),
            verdict_read: None,
            verdicts: None,
            in_flight: VecDeque::new(),
            last_done: None,
            waiting: false,
            wake: None,
            cpu_previews: CpuPreviews::default(),
        }
    }
}

impl Progressive {
    /// A progressive picture that asks `ctx` for a frame whenever the GPU is done with a
    /// run of its squares.
    pub fn waking(ctx: egui::Context) -> Self {
        Self {
            wake: Some(ctx),
            ..Self::default()
        }
    }

    /// Whether the last step stopped to wait for the GPU, or for the hold after a preview
    /// on the CPU; the window is woken when it is over.
    pub fn waiting(&self) -> bool {
        self.waiting
    }

    /// Rays per millisecond measured so far.
    pub fn throughput(&self) -> f64 {
        self.rays_per_ms
    }

    /// True when there is nothing left to draw for the current picture.
    pub fn converged(&self) -> bool {
        self.completed == Some(self.stages.len().saturating_sub(1)) && !self.stages.is_empty()
    }

    /// Where the drawing is: the stage, and squares done in it (for FOURFOLD_TRACE).
    pub fn position(&self) -> (usize, u32) {
        (self.stage, self.next_tile)
    }

    /// 0..1: how far the current picture is.
    pub fn fraction(&self) -> f32 {
        if self.stages.is_empty() {
            return 0.0;
        }
        let done = self.completed.map_or(0, |c| c + 1);
        done as f32 / self.stages.len() as f32
    }

    /// Whether the full-resolution picture (with the scene's rays) is on screen.
    pub fn full_quality(&self) -> bool {
        self.completed
            .is_some_and(|c| self.stages.get(c).is_some_and(|s| s.div == 1))
    }

    /// Makes sure the textures match `size` (screen pixels); registers them with egui.
    fn ensure_textures(
        &mut self,
        gpu: &Gpu,
        caster: &RayCaster,
        renderer: &mut egui_wgpu::Renderer,
        size: [u32; 2],
    ) {
        if self.size == size && !self.textures.is_empty() {
            return;
        }
        for t in self.textures.drain(..) {
            renderer.free_texture(&t.id);
        }
        self.size = size;
        self.textures = textures::make(gpu, caster, renderer, size);
        self.key = None;
        self.completed = None;
        self.shown = None;
    }

    /// The texture of each divisor.
    pub fn texture(&self, index: usize) -> Option<&StageTexture> {
        self.textures.get(index)
    }

    /// The texture of the stages at the screen's size over `div`.
    pub fn texture_of(&self, div: u32) -> Option<&StageTexture> {
        self.textures.get(texture_index(div))
    }

    /// Plans the stages for a new view, picture, size or interaction (`key`), keeping what
    /// is on screen (completed) until the new preview is done; a page draws that preview
    /// on the CPU (`on_cpu`).
    fn replan(&mut self, gpu: &Gpu, subject: &Subject<'_>, key: (ViewKey, u64, bool)) {
        let interacting = key.2;
        self.key = Some(key);
        let new_picture = self.generation != subject.generation;
        self.generation = subject.generation;
        self.plan(subject.scene, interacting);
        if let Some(formula) = subject.formula {
            let picture = (formula, subject.params, subject.hierarchy.as_ref());
            self.preview_on_cpu(gpu, subject.caster, picture, subject.scene, new_picture);
        }
    }

    fn plan(&mut self, scene: &Scene, interacting: bool) {
        self.plans += 1;
        self.take_throughput();
        self.verdict_read = None;
        self.verdicts = None;
        self.stages = stages::plan(self.size, scene.render.rays, self.rays_per_ms, interacting);
        self.preview_from_cpu = false;
        self.completed = None;
        self.stage = 0;
        self.next_tile = 0;
        self.stage_started = None;
        self.plan_tile();
    }

    /// Sets the throughput from the plain runs measured since it was last set. (Runs of a
    /// few milliseconds in all are mostly the wait for the GPU's word: they add up over the
    /// plans until they say more.)
    fn take_throughput(&mut self) {
        let [rays, ms] = self.measured;
        if ms >= MEASURED_MS {
            self.rays_per_ms = rays / ms;
            self.measured = [0.0; 2];
        }
    }

    /// Tile side for the current stage: about 20 ms of rays, at least 8 pixels.
    fn plan_tile(&mut self) {
        // Work goes in runs of UNIT×UNIT squares along a row; the run length adapts to the
        // measured time per square (a square of sky costs nothing, one on M a lot).
        self.tile = UNIT;
        self.unit_ms = None;
    }

    /// Draws as many tiles as fit in `budget_ms`; returns true while more work remains.
    /// `interacting` asks for a quick preview only.
    pub fn step(
        &mut self,
        gpu: &Gpu,
        renderer: &mut egui_wgpu::Renderer,
        subject: Subject<'_>,
        size: [u32; 2],
        interacting: bool,
        budget_ms: f64,
    ) -> bool {
        self.waiting = false;
        self.ensure_textures(gpu, subject.caster, renderer, size);
        self.read_verdicts(gpu);
        let full_key = (
            ViewKey::new(subject.scene, size),
            subject.generation,
            interacting,
        );
        if self.key.as_ref() != Some(&full_key) {
            self.replan(gpu, &subject, full_key);
        }
        let Subject {
            caster,
            hierarchy,
            certifying,
            certifier_pending,
            params,
            scene,
            ..
        } = subject;
        if self.held_after_cpu_preview() {
            return true;
        }
        let started = Instant::now();
        let mut runs = 0;
        let mut frame: Option<(usize, Camera, Uniforms)> = None;
        while self.stage < self.stages.len() {
            // Few runs at a time on the GPU: the next is sized by how long the last took.
            self.waiting = !self.land_runs();
            if self.waiting {
                return true;
            }
            let stage = self.stages[self.stage];
            let index = texture_index(stage.div);
            let (width, height) = (self.textures[index].width, self.textures[index].height);
            let cols = width.div_ceil(self.tile);
            // Previews and the frames while the user interacts are plain (fast); the full
            // picture once still is certified where the scene asks: its first pass proves
            // each pixel, the plain passes averaged into it after keep what it proved where
            // their rays find nothing.
            // (An interpreting caster cannot certify: its formula's own shader is coming,
            // or failed, and the picture stays plain.)
            let certifies = certifier_pending || !caster.interprets();
            let settled = scene.render.certified
                && certifying.is_some()
                && certifies
                && stage.div == 1
                && !interacting;
            let certified = settled && stage.frame == 0;
            if certified && certifier_pending {
                // Back at the next frame, which the window draws at once (not waiting for
                // the GPU): the session takes the pipeline as soon as it is built.
                return true;
            }
            if self.next_tile >= cols * height.div_ceil(self.tile) {
                self.complete_stage(gpu, stage, certified);
                continue;
            }
            // Stop when the budget is spent, or (after at least one run, so that the picture
            // always progresses) when what is left would not hold half a square more.
            let spent = started.elapsed().as_secs_f64() * 1e3;
            let half_square = 0.5 * self.unit_ms.unwrap_or(0.0);
            if spent >= budget_ms || (runs > 0 && budget_ms - spent < half_square) {
                return true;
            }
            if self.stage_started.is_none() {
                self.stage_started = Some(Instant::now());
            }
            // The stage's camera and settings are the same for all its squares: made once.
            if frame.as_ref().is_none_or(|(s, ..)| *s != self.stage) {
                let options = FrameOptions {
                    frame: stage.frame,
                    rays: Some(stage.rays),
                    keep_misses: settled && !certified,
                    ..FrameOptions::default()
                };
                let mut drawn = scene.clone();
                drawn.render.certified = certified;
                let (camera, uniforms) =
                    view::frame(&drawn, hierarchy, params, [width, height], options);
                frame = Some((self.stage, camera, uniforms));
            }
            let (_, camera, uniforms) = frame.as_ref().expect("made above");
            // The leaves of each screen tile, for this stage's resolution and view (brute
            // force reads none). Binned once per texture and plan, off the UI thread.
            let certifying = certifying.filter(|_| uniforms.certified());
            let hierarchies = (hierarchy, certifying);
            if !uniforms.brute_force()
                && !self
                    .binner
                    .ready(gpu, caster, hierarchies, camera, (index, self.plans))
            {
                return true;
            }
            // As many squares as fit in what is left of the budget (with a margin: squares
            // vary, and an overrun costs the window a frame); where the window cannot wait
            // for the GPU, the budget is the GPU time one run may take.
            let left = if platform::WAITS_FOR_GPU {
                (0.5 * (budget_ms - started.elapsed().as_secs_f64() * 1e3)).max(1.0)
            } else {
                budget_ms
            };
            self.draw_run(gpu, caster, uniforms, stage, left);
            runs += 1;
        }
        false
    }

    /// Takes a certified view's verdicts once they are back from the GPU.
    fn read_verdicts(&mut self, gpu: &Gpu) {
        if let Some(read) = &self.verdict_read
            && let Some(result) = read.poll(gpu)
        {
            self.verdicts = result
                .ok()
                .map(|mut rgba| VerdictCounts::of(&take_marks(&mut rgba).1));
            self.verdict_read = None;
        }
    }

    /// The stage in progress is complete: it is what is on screen now. (The first full
    /// picture of a certified view is read back for its verdicts: its alpha holds them, and
    /// later passes blend in the same.)
    fn complete_stage(&mut self, gpu: &Gpu, stage: Stage, certified: bool) {
        let index = texture_index(stage.div);
        let wall = self
            .stage_started
            .map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e3);
        if stage.div == 1 && stage.frame == 0 {
            self.full_ms = Some(wall);
            if certified {
                self.verdict_read = Some(start_texture_read(gpu, &self.textures[index].texture));
            }
        }
        if self.stage == 0 {
            self.preview_ms = Some(wall);
            if self.first_frame_of != Some(self.generation) {
                self.first_frame_of = Some(self.generation);
            }
        }
        self.completed = Some(self.stage);
        self.shown = Some(index);
        self.stage += 1;
        self.next_tile = 0;
        self.stage_started = None;
        self.plan_tile();
    }

    /// Draws the next run of squares of the stage in progress, as many as `left_ms` holds
    /// at the measured time per square: along the row, or whole rows from a row's start.
    fn draw_run(
        &mut self,
        gpu: &Gpu,
        caster: &mut RayCaster,
        uniforms: &Uniforms,
        stage: Stage,
        left_ms: f64,
    ) {
        let texture = &self.textures[texture_index(stage.div)];
        let (width, height) = (texture.width, texture.height);
        let cols = width.div_ceil(self.tile);
        let rows = height.div_ceil(self.tile);
        let (tx, ty) = (self.next_tile % cols, self.next_tile / cols);
        let run = match self.unit_ms {
            None => 1,
            Some(u) => ((left_ms / u.max(1e-3)) as u32).max(1),
        };
        let (region, squares) = if tx == 0 && run >= cols {
            let n = (run / cols).min(rows - ty);
            ([0, ty * self.tile, width, n * self.tile], n * cols)
        } else {
            let n = run.min(cols - tx);
            (
                [tx * self.tile, ty * self.tile, n * self.tile, self.tile],
                n,
            )
        };
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        caster.encode_pass(
            gpu,
            &mut encoder,
            &texture.view,
            uniforms,
            Pass {
                region: Some(region),
                weight: stage.weight,
            },
        );
        let submitted = Instant::now();
        gpu.queue.submit([encoder.finish()]);
        let done = Arc::new(OnceLock::new());
        let flag = Arc::clone(&done);
        let wake = self.wake.clone();
        gpu.queue.on_submitted_work_done(move || {
            let _ = flag.set(Instant::now());
            if let Some(ctx) = wake {
                ctx.request_repaint();
            }
        });
        if platform::WAITS_FOR_GPU {
            let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
        }
        let w = region[2].min(width - region[0]);
        let h = region[3].min(height - region[1]);
        self.in_flight.push_back(Run {
            squares,
            rays: f64::from(w) * f64::from(h) * f64::from(stage.rays),
            certified: uniforms.certified(),
            planned_ms: left_ms,
            submitted,
            done,
        });
        self.next_tile += squares;
    }

    /// Takes the measurements of the runs the GPU is done with; whether another may go.
    fn land_runs(&mut self) -> bool {
        while let Some(run) = self.in_flight.front() {
            let Some(&done) = run.done.get() else {
                break;
            };
            let run = self.in_flight.pop_front().expect("looked at above");
            self.land(&run, done);
        }
        self.in_flight.len() < RUNS_IN_FLIGHT
    }

    /// Takes the measurements of `run`, done at `done`.
    fn land(&mut self, run: &Run, done: Instant) {
        // (A run queued behind another starts when that one is done.)
        let start = self
            .last_done
            .map_or(run.submitted, |d| d.max(run.submitted));
        self.last_done = Some(done);
        let run_ms = done.duration_since(start).as_secs_f64() * 1e3;
        let per_unit = run_ms / f64::from(run.squares);
        self.unit_ms = Some(if platform::WAITS_FOR_GPU {
            // Slower squares count at once, faster ones slowly: never plan a run too long.
            match self.unit_ms {
                Some(u) if per_unit < u => 0.8 * u + 0.2 * per_unit,
                _ => per_unit,
            }
        } else {
            // Where the word that a run is done comes a frame or more later, a small run's
            // time is mostly that wait: one done within its plan is doubled, up to a
            // bound (a square on M may cost a thousand of sky, and a run is not taken
            // back once queued); one that overran shrinks in proportion.
            let next = if run_ms <= run.planned_ms {
                (2 * run.squares).min(PAGE_RUN_SQUARES)
            } else {
                ((f64::from(run.squares) * run.planned_ms / run_ms) as u32).max(1)
            };
            run.planned_ms / f64::from(next)
        });
        if !run.certified {
            self.measured[0] += run.rays;
            self.measured[1] += run_ms;
        }
    }

    /// The layers to paint, bottom first (see `paint::layers`).
    pub fn paint(&self) -> Paint {
        layers(Progress {
            stages: &self.stages,
            stage: self.stage,
            textures: &self.textures,
            shown: self.shown,
            next_tile: self.next_tile,
            tile: self.tile,
        })
    }
}

mod on_cpu;
#[cfg(test)]
mod tests;
