//! The picture API: one picture of a prepared scene, drawn offscreen at a size on a GPU or on
//! the CPU twin, read back with its certified pixels' verdicts and the pixels the driver cut
//! short. The command line, the viewer's exports (desktop and web), animations and the
//! gallery all draw through a [`Painter`]. Nothing here waits for the GPU: a picture comes
//! back through [`PendingPicture::poll`] (the `headless` module adds `wait`).

use web_time::Instant;

use crate::formula::CompiledFormula;
use crate::scene::{MAX_PICTURE_SIDE, Scene};
use crate::tree::{Hierarchy, TreeStats};

use super::gpu::{CacheUse, Gpu, GpuError, PendingRgba, RayCaster};
use super::prepare::Prepared;
use super::shader::{CodegenError, Shader};
use super::verdict::{Verdict, VerdictCounts, take_marks};
use super::view::{FrameOptions, frame};

/// Milliseconds per stage.
#[derive(Debug, Clone, Default)]
pub struct StageTimes {
    pub parse_ms: f64,
    pub tree_ms: f64,
    pub codegen_ms: f64,
    pub pipeline_ms: f64,
    /// What became of the compiled pipelines kept between runs (`Gpu::pipeline_cache`).
    pub pipeline_cache: CacheUse,
    pub frame_ms: f64,
    /// Of the frame, the GPU's pass alone (timestamps; None on the CPU reference or a GPU
    /// without timestamp queries).
    pub gpu_ms: Option<f64>,
}

/// A rendered picture and how it was made.
#[derive(Debug, Clone)]
pub struct Picture {
    pub width: u32,
    pub height: u32,
    /// RGBA8 rows, top to bottom.
    pub rgba: Vec<u8>,
    pub adapter: String,
    pub times: StageTimes,
    pub tree: TreeStats,
    /// What the ray caster marched, in words (`Hierarchy::march_summary`); None for brute
    /// force.
    pub marched: Option<String>,
    /// Pixels (row-major indices) whose work the GPU driver cut short (llvmpipe stops a
    /// shader invocation's loops after 65535 iterations): they may miss parts of M. The
    /// shader flags them in alpha (see `verdict::take_marks`); `rgba` has alpha 255
    /// everywhere.
    pub cut_pixels: Vec<usize>,
    /// With `[render] certified`: each pixel's verdict, row-major (docs/method.md §5.9).
    pub verdicts: Option<Vec<Verdict>>,
}

impl Picture {
    /// With `[render] certified`: how many pixels got each verdict.
    pub fn verdict_counts(&self) -> Option<VerdictCounts> {
        self.verdicts.as_deref().map(VerdictCounts::of)
    }

    /// The picture as a PNG file's bytes.
    pub fn to_png(&self) -> Result<Vec<u8>, String> {
        encode_png(&self.rgba, self.width, self.height)
    }
}

/// RGBA8 rows of `width`×`height` pixels as a PNG file's bytes.
pub fn encode_png(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>, String> {
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        rgba,
        width,
        height,
        image::ExtendedColorType::Rgba8,
    )
    .map_err(|e| format!("could not encode the PNG: {e}"))?;
    Ok(png)
}

/// What can stop a picture, with a message for the user.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("{0}")]
    Formula(String),
    #[error("{0}")]
    Tree(#[from] crate::tree::BuildError),
    #[error("{0}")]
    Codegen(#[from] CodegenError),
    #[error("{0}")]
    Gpu(#[from] GpuError),
    #[error(
        "the image size {0}x{1} is not allowed: both sides must be between 1 and {MAX_PICTURE_SIDE}"
    )]
    Size(u32, u32),
}

/// What a picture is drawn from besides its scene: the formula, its parameter values and the
/// tree's boxes ([`Prepared::source`] gives them for a prepared scene; a front end that keeps
/// them apart gives them as they are).
#[derive(Clone, Copy)]
pub struct Source<'a> {
    pub formula: &'a CompiledFormula,
    pub params: &'a [f64],
    pub hierarchy: &'a Hierarchy,
    /// The boxes certified pixels search (`Prepared::certifying`); None: they search the
    /// marched boxes.
    pub certifying: Option<&'a Hierarchy>,
    pub tree: &'a TreeStats,
    /// Milliseconds the tree and hierarchy took.
    pub build_ms: f64,
}

impl Prepared {
    /// What a picture is drawn from: this preparation of `formula`'s tree, with the boxes
    /// certified pixels search where `certified` (made now if not yet).
    pub fn source<'a>(&'a self, formula: &'a CompiledFormula, certified: bool) -> Source<'a> {
        Source {
            formula,
            params: &self.params,
            hierarchy: &self.hierarchy,
            certifying: certified.then(|| self.certifying(formula)),
            tree: &self.tree.stats,
            build_ms: self.build_ms,
        }
    }
}

/// Where to draw: a GPU, or the CPU reference renderer.
#[derive(Clone, Copy)]
pub enum Device<'a> {
    Gpu(&'a Gpu),
    Cpu,
}

/// Pixels a thread of the CPU twin draws of a slice in about the time a GPU takes to open
/// and make its pipeline (docs/benchmarks.md, "A one-off slice on the CPU").
pub const CPU_SLICE_PIXELS_PER_THREAD: u64 = 1 << 17;

/// Whether one picture of `scene` at `width` × `height`, with no GPU open yet, is sooner
/// drawn by the CPU twin: a slice (one ray a pixel, where a projection or a slab casts a
/// pencil of them) of at most [`CPU_SLICE_PIXELS_PER_THREAD`] pixels per thread of this
/// machine, for which opening a device and making its pipeline take longer than the twin's
/// whole picture.
pub fn sooner_on_cpu(scene: &Scene, width: u32, height: u32) -> bool {
    let pixels = u64::from(width) * u64::from(height);
    scene.view.slice.is_some() && scene.view.slab.is_none() && pixels <= cpu_slice_pixels()
}

/// The most pixels of a slice [`sooner_on_cpu`] gives the CPU twin on this machine.
pub fn cpu_slice_pixels() -> u64 {
    CPU_SLICE_PIXELS_PER_THREAD * rayon::current_num_threads().max(1) as u64
}

/// Draws offscreen pictures of one formula: on a GPU, with a ray caster whose pipelines are
/// kept from picture to picture (and from tree to tree); or on the CPU twin.
pub struct Painter {
    gpu: Option<(Gpu, RayCaster)>,
    /// Milliseconds it took to generate and validate the shader (0 on the CPU, which needs
    /// none, and where [`Self::new`] was given it), and to make the pipeline (0 on the CPU).
    pub codegen_ms: f64,
    pub pipeline_ms: f64,
    /// What became of the pipeline cache kept between runs.
    pub pipeline_cache: CacheUse,
}

impl Painter {
    /// A painter on `device` for `shader` (the formula's, already validated) over
    /// `hierarchy`, with the pipeline that pictures of `scene` draw with built now (not in
    /// the first picture), and no other.
    pub fn new(
        device: Device<'_>,
        shader: &Shader,
        hierarchy: &Hierarchy,
        scene: &Scene,
    ) -> Result<Self, RenderError> {
        let Device::Gpu(gpu) = device else {
            return Ok(Self::cpu());
        };
        let started = Instant::now();
        let target = super::gpu::Target::OFFSCREEN;
        let caster = RayCaster::for_scene(gpu, shader, hierarchy, target, scene)?;
        Ok(Self {
            codegen_ms: 0.0,
            pipeline_ms: ms(started),
            pipeline_cache: caster.pipeline_cache().clone(),
            gpu: Some((gpu.clone(), caster)),
        })
    }

    /// As [`Self::new`] for a formula whose shader is not made yet: it is generated and
    /// validated on a GPU (its time is the pictures' codegen time), and not at all for the
    /// CPU twin, which needs none.
    pub fn for_formula(
        device: Device<'_>,
        formula: &CompiledFormula,
        hierarchy: &Hierarchy,
        scene: &Scene,
    ) -> Result<Self, RenderError> {
        if let Device::Cpu = device {
            return Ok(Self::cpu());
        }
        let started = Instant::now();
        let shader = super::shader::generate(formula)?;
        let codegen_ms = ms(started);
        let painter = Self::new(device, &shader, hierarchy, scene)?;
        Ok(Self {
            codegen_ms,
            ..painter
        })
    }

    fn cpu() -> Self {
        Self {
            gpu: None,
            codegen_ms: 0.0,
            pipeline_ms: 0.0,
            pipeline_cache: CacheUse::Off,
        }
    }

    /// How many ray-caster pipelines this painter has built (0 on the CPU), and whether the
    /// one pictures of `scene` draw with is among them: what `fourfold render` builds.
    pub fn pipelines(&self, scene: &Scene, hierarchy: &Hierarchy) -> (usize, bool) {
        match &self.gpu {
            Some((_, caster)) => (
                caster.pipelines_built(),
                caster.has_pipeline_for(scene, hierarchy),
            ),
            None => (0, false),
        }
    }

    /// Draws over a new hierarchy of the same formula (new parameters, domain or levels).
    pub fn set_hierarchy(&mut self, hierarchy: &Hierarchy) -> Result<(), RenderError> {
        if let Some((gpu, caster)) = &mut self.gpu {
            caster.set_hierarchy(gpu, hierarchy)?;
        }
        Ok(())
    }

    /// What draws: the GPU adapter, or the CPU reference renderer.
    pub fn adapter(&self) -> String {
        match &self.gpu {
            Some((gpu, _)) => gpu.adapter.clone(),
            None => "CPU reference renderer".to_string(),
        }
    }

    /// Starts the picture of `scene` at `width`×`height` from `source` (made for `scene`): a
    /// GPU frame is binned and submitted here and comes back through
    /// [`PendingPicture::poll`]; a CPU frame is drawn here.
    pub fn start(
        &mut self,
        source: Source<'_>,
        scene: &Scene,
        [width, height]: [u32; 2],
        options: FrameOptions,
    ) -> Result<PendingPicture, RenderError> {
        check_size(width, height)?;
        let started = Instant::now();
        let hierarchy = source.hierarchy;
        let (camera, uniforms) = frame(scene, hierarchy, source.params, [width, height], options);
        let certifying = source.certifying.filter(|_| uniforms.certified());
        let mut picture = Picture {
            width,
            height,
            rgba: Vec::new(),
            adapter: self.adapter(),
            times: StageTimes {
                tree_ms: source.build_ms,
                codegen_ms: self.codegen_ms,
                pipeline_ms: self.pipeline_ms,
                pipeline_cache: self.pipeline_cache.clone(),
                ..StageTimes::default()
            },
            tree: source.tree.clone(),
            marched: (!uniforms.brute_force() && !hierarchy.is_empty())
                .then(|| hierarchy.march_summary()),
            cut_pixels: Vec::new(),
            verdicts: None,
        };
        let certified = scene.render.certified;
        let Some((gpu, caster)) = &mut self.gpu else {
            let (formula, params) = (source.formula, source.params);
            let rgba = super::twin::render_rgba(formula, params, hierarchy, certifying, &uniforms);
            picture.times.frame_ms = ms(started);
            return Ok(PendingPicture::ready(finish(picture, rgba, certified)));
        };
        caster.bin_view(gpu, hierarchy, certifying, &camera, &uniforms);
        let pending = caster.start_rgba(gpu, &uniforms, true)?;
        Ok(PendingPicture {
            state: Some(State::Gpu {
                gpu: gpu.clone(),
                pending,
                picture,
                started,
                certified,
            }),
        })
    }
}

/// A picture on its way back: [`PendingPicture::poll`] it until it is there.
pub struct PendingPicture {
    state: Option<State>,
}

enum State {
    Ready(Picture),
    Gpu {
        gpu: Gpu,
        pending: PendingRgba,
        picture: Picture,
        started: Instant,
        certified: bool,
    },
}

impl PendingPicture {
    fn ready(picture: Picture) -> Self {
        Self {
            state: Some(State::Ready(picture)),
        }
    }

    /// The GPU the picture is drawn on (None: the CPU, and it is ready).
    pub fn gpu(&self) -> Option<&Gpu> {
        match &self.state {
            Some(State::Gpu { gpu, .. }) => Some(gpu),
            _ => None,
        }
    }

    /// The picture once it is back (once: later calls give None), else None. A web page's
    /// event loop brings it back; natively the device must be polled (`headless` waits).
    pub fn poll(&mut self) -> Option<Result<Picture, RenderError>> {
        if let Some(State::Gpu { gpu, pending, .. }) = &self.state {
            match pending.poll_timed(gpu) {
                None => return None,
                Some(Err(e)) => {
                    self.state = None;
                    return Some(Err(e.into()));
                }
                Some(Ok((rgba, gpu_ms))) => {
                    let Some(State::Gpu {
                        mut picture,
                        started,
                        certified,
                        ..
                    }) = self.state.take()
                    else {
                        unreachable!("matched above");
                    };
                    picture.times.frame_ms = ms(started);
                    picture.times.gpu_ms = gpu_ms;
                    return Some(Ok(finish(picture, rgba, certified)));
                }
            }
        }
        match self.state.take() {
            Some(State::Ready(picture)) => Some(Ok(picture)),
            other => {
                self.state = other;
                None
            }
        }
    }
}

/// The picture with its pixels: the cut pixels and verdicts taken out of their alpha.
fn finish(mut picture: Picture, mut rgba: Vec<u8>, certified: bool) -> Picture {
    let (cut_pixels, verdicts) = take_marks(&mut rgba);
    picture.rgba = rgba;
    picture.cut_pixels = cut_pixels;
    picture.verdicts = certified.then_some(verdicts);
    picture
}

/// A picture side is 1 to MAX_PICTURE_SIDE pixels.
pub fn check_size(width: u32, height: u32) -> Result<(), RenderError> {
    let sides = 1..=MAX_PICTURE_SIDE;
    if sides.contains(&width) && sides.contains(&height) {
        Ok(())
    } else {
        Err(RenderError::Size(width, height))
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
