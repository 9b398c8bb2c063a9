//! Progressive drawing: the viewer never asks the GPU for more than about one UI frame's
//! worth of rays at a time, so the window stays responsive even on a software GPU.
//!
//! A picture is drawn in stages: a coarse preview (every `div`-th pixel, few rays, sized from
//! the measured ray throughput so that it fits in one frame), a half-resolution pass, the
//! full picture with the scene's rays, and then further full passes with new ray offsets that
//! are averaged into it (the picture converges; nothing flickers). Each stage is drawn in
//! square tiles, as many per UI frame as fit in the time budget. Any change (view, settings,
//! new tree) starts again from the preview, while the last picture stays on screen.

use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError};
use web_time::Instant;

use eframe::{egui, egui_wgpu};

use fourfold::render::gpu::{PendingRgba, start_texture_read};
use fourfold::render::verdict::{VerdictCounts, take_marks};
use fourfold::render::view;
use fourfold::render::{Camera, FrameOptions, Gpu, Pass, RayCaster, TileLists, Uniforms};
use fourfold::scene::{Domain, RenderSettings, Scene, View};
use fourfold::tree::Hierarchy;

/// Full-resolution passes averaged into the picture once it is complete.
pub const ACCUMULATED_PASSES: u32 = 16;

/// What a progressive picture draws: a ray caster with its hierarchy and parameter values,
/// seen as `scene` says, for the session's picture `generation` (a new one starts again).
pub struct Subject<'a> {
    pub caster: &'a mut RayCaster,
    pub hierarchy: &'a Arc<Hierarchy>,
    /// The boxes certified pixels search (`Hierarchy::for_certifying`), where the scene
    /// certifies.
    pub certifying: Option<&'a Arc<Hierarchy>>,
    pub params: &'a [f64],
    pub scene: &'a Scene,
    pub generation: u64,
}

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
struct Stage {
    /// Pixels are `div`× larger than the screen's.
    div: u32,
    rays: u32,
    /// Frame index (ray offsets) and blend weight of the pass.
    frame: u32,
    weight: f64,
}

/// A texture the ray caster draws into and egui shows.
pub struct StageTexture {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    pub id: egui::TextureId,
    /// For the app's own blit (see blit.rs), where egui's renderer has it.
    pub blit: Option<wgpu::BindGroup>,
    pub width: u32,
    pub height: u32,
}

/// A stretch of a stage texture that is drawn: the rectangle in texture pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Done {
    pub texture: usize,
    pub rect: [u32; 4],
}

/// What the app paints: the textures (by index) and, for the stage in progress, the tiles
/// done so far.
#[derive(Debug, Clone, Default)]
pub struct Paint {
    pub layers: Vec<Done>,
}

/// Which stage texture and plan (view, settings, picture) a set of tile lists is for.
type BinKey = (usize, u64);

/// Leaf lists being binned on a worker thread (the binning of a full-size view takes longer
/// than a UI frame).
struct Binning {
    key: BinKey,
    /// The ray caster's lists, and the certifying ones where asked for.
    lists: Receiver<(TileLists, Option<TileLists>)>,
    started: Instant,
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
    /// Measured throughput (rays per millisecond), for sizing previews and tiles.
    rays_per_ms: f64,
    stage_started: Option<Instant>,
    /// Wall time of the last complete full-resolution stage, and of the last preview.
    pub full_ms: Option<f64>,
    pub preview_ms: Option<f64>,
    /// Set when the first stage of a new picture generation completed.
    pub first_frame_of: Option<u64>,
    generation: u64,
    /// The tile lists the ray caster holds, and the binning in flight.
    binned: Option<BinKey>,
    binning: Option<Binning>,
    /// Wall time of the last binning, milliseconds, and how many were started.
    pub binning_ms: Option<f64>,
    pub binnings: u64,
    /// A certified view's verdicts: read back from its first full-resolution stage, and
    /// the counts once they are in (None: not certified, or not yet).
    verdict_read: Option<PendingRgba>,
    pub verdicts: Option<VerdictCounts>,
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
            stage_started: None,
            full_ms: None,
            preview_ms: None,
            first_frame_of: None,
            generation: 0,
            binned: None,
            binning: None,
            binning_ms: None,
            binnings: 0,
            verdict_read: None,
            verdicts: None,
        }
    }
}

/// Side of the squares a stage is drawn in, pixels.
const UNIT: u32 = 8;

/// The divisors of the stage textures: preview sizes and the full picture.
const DIVS: [u32; 6] = [32, 16, 8, 4, 2, 1];

impl Progressive {
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
        // (A view wider or taller than the device's largest texture is drawn at that side
        // and stretched.)
        let max_side = gpu.device.limits().max_texture_dimension_2d;
        for div in DIVS {
            let width = size[0].div_ceil(div).clamp(1, max_side);
            let height = size[1].div_ceil(div).clamp(1, max_side);
            let texture = caster.target_texture(
                gpu,
                width,
                height,
                wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
            );
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let id = renderer.register_native_texture(&gpu.device, &view, wgpu::FilterMode::Linear);
            let blit = renderer
                .callback_resources
                .get::<super::blit::Blit>()
                .map(|b| b.bind(&gpu.device, &view));
            self.textures.push(StageTexture {
                texture,
                view,
                id,
                blit,
                width,
                height,
            });
        }
        self.key = None;
        self.completed = None;
        self.shown = None;
    }

    /// The texture of each divisor.
    pub fn texture(&self, index: usize) -> Option<&StageTexture> {
        self.textures.get(index)
    }

    fn plan(&mut self, scene: &Scene, interacting: bool) {
        self.plans += 1;
        self.verdict_read = None;
        self.verdicts = None;
        let rays = scene.render.rays.max(1);
        let pixels = |div: u32| {
            f64::from(self.size[0].div_ceil(div)) * f64::from(self.size[1].div_ceil(div))
        };
        // The preview: the finest divisor whose pass fits in ~one frame at the measured speed.
        let preview_rays = rays.min(4);
        let budget = if interacting { 30.0 } else { 60.0 } * self.rays_per_ms;
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
        self.stages = stages;
        self.completed = None;
        self.stage = 0;
        self.next_tile = 0;
        self.stage_started = None;
        self.plan_tile();
    }

    /// Tile side for the current stage: about 20 ms of rays, at least 8 pixels.
    fn plan_tile(&mut self) {
        // Work goes in runs of UNIT×UNIT squares along a row; the run length adapts to the
        // measured time per square (a square of sky costs nothing, one on M a lot).
        self.tile = UNIT;
        self.unit_ms = None;
    }

    fn texture_index(div: u32) -> usize {
        DIVS.iter()
            .position(|&d| d == div)
            .unwrap_or(DIVS.len() - 1)
    }

    /// Draws as many tiles as fit in `budget_ms`; returns true while more work remains.
    /// `key` names everything the picture depends on besides the session's generation;
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
        let Subject {
            caster,
            hierarchy,
            certifying,
            params,
            scene,
            generation,
        } = subject;
        self.ensure_textures(gpu, caster, renderer, size);
        if let Some(read) = &self.verdict_read
            && let Some(result) = read.poll(gpu)
        {
            self.verdicts = result
                .ok()
                .map(|mut rgba| VerdictCounts::of(&take_marks(&mut rgba).1));
            self.verdict_read = None;
        }
        let full_key = (ViewKey::new(scene, size), generation, interacting);
        if self.key.as_ref() != Some(&full_key) {
            // Keep what is on screen (completed) until the new preview is done.
            self.key = Some(full_key);
            self.generation = generation;
            self.plan(scene, interacting);
        }
        let started = Instant::now();
        let mut runs = 0;
        let mut frame: Option<(usize, Camera, Uniforms)> = None;
        while self.stage < self.stages.len() {
            let stage = self.stages[self.stage];
            let index = Self::texture_index(stage.div);
            let (width, height) = (self.textures[index].width, self.textures[index].height);
            let cols = width.div_ceil(self.tile);
            let rows = height.div_ceil(self.tile);
            if self.next_tile >= cols * rows {
                // Stage complete.
                let wall = self
                    .stage_started
                    .map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e3);
                if stage.div == 1 && stage.frame == 0 {
                    self.full_ms = Some(wall);
                    // Its alpha holds each pixel's verdict (later passes blend in the same).
                    if scene.render.certified && certifying.is_some() {
                        self.verdict_read =
                            Some(start_texture_read(gpu, &self.textures[index].texture));
                    }
                }
                if self.stage == 0 {
                    self.preview_ms = Some(wall);
                    if self.first_frame_of != Some(self.generation) {
                        self.first_frame_of = Some(self.generation);
                    }
                }
                self.completed = Some(self.stage);
                self.shown = Some(Self::texture_index(stage.div));
                self.stage += 1;
                self.next_tile = 0;
                self.stage_started = None;
                self.plan_tile();
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
                    ..FrameOptions::default()
                };
                let (camera, uniforms) =
                    view::frame(scene, hierarchy, params, [width, height], options);
                frame = Some((self.stage, camera, uniforms));
            }
            let (_, camera, uniforms) = frame.as_ref().expect("made above");
            // The leaves of each screen tile, for this stage's resolution and view (brute
            // force reads none). Binned once per texture and plan, off the UI thread.
            let certifying = certifying.filter(|_| uniforms.certified());
            let hierarchies = (hierarchy, certifying);
            if !uniforms.brute_force()
                && !self.lists_ready(gpu, caster, hierarchies, camera, (index, self.plans))
            {
                return true;
            }
            let (tx, ty) = (self.next_tile % cols, self.next_tile / cols);
            // As many squares of this row as fit in what is left of the budget (with a
            // margin: squares vary, and an overrun costs the window a frame).
            let left = (0.5 * (budget_ms - started.elapsed().as_secs_f64() * 1e3)).max(1.0);
            let run = match self.unit_ms {
                None => 1,
                Some(u) => ((left / u.max(1e-3)) as u32).clamp(1, cols - tx),
            };
            let region = [tx * self.tile, ty * self.tile, run * self.tile, self.tile];
            let t = Instant::now();
            let mut encoder = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            caster.encode_pass(
                gpu,
                &mut encoder,
                &self.textures[index].view,
                uniforms,
                Pass {
                    region: Some(region),
                    weight: stage.weight,
                },
            );
            gpu.queue.submit([encoder.finish()]);
            let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
            let run_ms = t.elapsed().as_secs_f64() * 1e3;
            let per_unit = run_ms / f64::from(run);
            // Slower squares count at once, faster ones slowly: never plan a run too long.
            self.unit_ms = Some(match self.unit_ms {
                Some(u) if per_unit < u => 0.8 * u + 0.2 * per_unit,
                _ => per_unit,
            });
            let w = (run * self.tile).min(width - region[0]);
            let h = self.tile.min(height - region[1]);
            let rays = f64::from(w * h * stage.rays);
            if run_ms > 0.05 {
                let measured = rays / run_ms;
                self.rays_per_ms = if measured < self.rays_per_ms {
                    measured
                } else {
                    0.9 * self.rays_per_ms + 0.1 * measured
                };
            }
            self.next_tile += run;
            runs += 1;
        }
        false
    }

    /// Whether the caster holds the tile lists for `key` (and, for a certified view, the
    /// certifying lists); if not, starts or polls their binning on a worker thread and
    /// uploads them once done.
    fn lists_ready(
        &mut self,
        gpu: &Gpu,
        caster: &mut RayCaster,
        (hierarchy, certifying): (&Arc<Hierarchy>, Option<&Arc<Hierarchy>>),
        camera: &Camera,
        key: BinKey,
    ) -> bool {
        if self.binned.as_ref() == Some(&key) {
            return true;
        }
        if let Some(job) = &self.binning
            && job.key == key
        {
            let (lists, cert) = match job.lists.try_recv() {
                Ok((lists, cert)) => (Some(lists), cert),
                Err(TryRecvError::Empty) => return false,
                // The worker died (it cannot, short of running out of memory): draw by the
                // stackless walk, which needs no lists.
                Err(TryRecvError::Disconnected) => (None, None),
            };
            self.binning_ms = Some(job.started.elapsed().as_secs_f64() * 1e3);
            caster.set_tiles(gpu, lists.as_ref());
            caster.set_cert_tiles(gpu, cert.as_ref());
            self.binning = None;
            self.binned = Some(key);
            return true;
        }
        // A new view: bin it (a stale job finishes on its own; its result is dropped).
        let (send, lists) = std::sync::mpsc::channel();
        let (shared, view, budget) = (hierarchy.clone(), *camera, gpu.tile_entry_budget());
        let shared_cert = certifying.cloned();
        let worker = std::thread::Builder::new()
            .name("fourfold binning".into())
            .spawn(move || {
                let cert = shared_cert.map(|c| TileLists::build_within(&c, &view, budget));
                let _ = send.send((TileLists::build_within(&shared, &view, budget), cert));
            });
        self.binnings += 1;
        if worker.is_ok() {
            self.binning = Some(Binning {
                key,
                lists,
                started: Instant::now(),
            });
            return false;
        }
        // No thread to be had: bin here.
        let lists = TileLists::build_within(hierarchy, camera, budget);
        caster.set_tiles(gpu, Some(&lists));
        let cert = certifying.map(|c| TileLists::build_within(c, camera, budget));
        caster.set_cert_tiles(gpu, cert.as_ref());
        self.binned = Some(key);
        true
    }

    /// The layers to paint, bottom first: the last completed stage's texture below the rows
    /// the stage in progress has done (each window pixel is blitted about once: on a software
    /// GPU every layer costs its area), then those rows, if that stage draws into a different
    /// texture.
    pub fn paint(&self) -> Paint {
        let mut layers = Vec::new();
        // The part of the picture's height done by the stage in progress, 0..1.
        let mut covered = 0.0;
        if let Some(stage) = self.stages.get(self.stage) {
            let i = Self::texture_index(stage.div);
            if self.shown != Some(i) && self.next_tile > 0 {
                let t = &self.textures[i];
                let cols = t.width.div_ceil(self.tile);
                let full_rows = self.next_tile / cols;
                let partial = self.next_tile % cols;
                let rows_h = (full_rows * self.tile).min(t.height);
                // The blit filters bilinearly, so a layer stops one texel short of texels not
                // drawn yet (else a dark seam shows along the edge).
                let short =
                    |end: u32, limit: u32| if end > 0 && end < limit { end - 1 } else { end };
                let shown_h = short(rows_h, t.height);
                if shown_h > 0 {
                    layers.push(Done {
                        texture: i,
                        rect: [0, 0, t.width, shown_h],
                    });
                    covered = f64::from(shown_h) / f64::from(t.height);
                }
                let partial_w = (partial * self.tile).min(t.width);
                let partial_h = self.tile.min(t.height - rows_h);
                if partial > 0 && rows_h < t.height && partial_w > 1 && partial_h > 1 {
                    layers.push(Done {
                        texture: i,
                        rect: [
                            0,
                            shown_h,
                            short(partial_w, t.width),
                            short(rows_h + partial_h, t.height) - shown_h,
                        ],
                    });
                }
            }
        }
        if let Some(i) = self.shown {
            let t = &self.textures[i];
            let top = ((covered * f64::from(t.height)).floor() as u32).min(t.height);
            if top < t.height {
                layers.insert(
                    0,
                    Done {
                        texture: i,
                        rect: [0, top, t.width, t.height - top],
                    },
                );
            }
        }
        Paint { layers }
    }
}
