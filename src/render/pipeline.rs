//! The whole pipeline for one picture: formula → tree → hierarchy → shader → frame, with the
//! time of each stage. The CLI's `render` and the benchmarks call this.

use web_time::Instant;

use crate::formula::CompiledFormula;
use crate::scene::Scene;
use crate::tree::{Hierarchy, TreeStats};

use super::camera::Camera;
use super::certify::{Verdict, VerdictCounts, take_marks};
use super::codegen;
use super::gpu::{Gpu, RayCaster};
use super::prepare::Prepared;
use super::tiles::TileLists;
use super::uniforms::{FrameOptions, Uniforms};

/// The largest picture side `render` takes (within the device's own limit, which
/// `gpu::check_image_size` reports).
pub const MAX_PICTURE_SIDE: u32 = 8192;

/// Milliseconds per stage.
#[derive(Debug, Clone, Default)]
pub struct StageTimes {
    pub parse_ms: f64,
    pub tree_ms: f64,
    pub codegen_ms: f64,
    pub pipeline_ms: f64,
    pub frame_ms: f64,
    /// Of the frame, the GPU's pass alone (timestamps; None on the CPU reference or a GPU
    /// without timestamp queries).
    pub gpu_ms: Option<f64>,
}

/// A rendered picture and how it was made.
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
    /// shader flags them in alpha (see `certify::take_marks`); `rgba` has alpha 255
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
}

/// The pixels the shader flagged as cut short, with alpha made opaque.
pub fn take_cut_pixels(rgba: &mut [u8]) -> Vec<usize> {
    take_marks(rgba).0
}

/// What can stop a picture, with a message for the user.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("{0}")]
    Formula(String),
    #[error("{0}")]
    Tree(#[from] crate::tree::BuildError),
    #[error("{0}")]
    Codegen(#[from] codegen::CodegenError),
    #[error("{0}")]
    Gpu(#[from] super::gpu::GpuError),
    #[error(
        "the image size {0}x{1} is not allowed: both sides must be between 1 and {MAX_PICTURE_SIDE}"
    )]
    Size(u32, u32),
}

/// Where to draw: an existing GPU, a new one, or the CPU reference.
pub enum Device<'a> {
    Gpu(&'a Gpu),
    NewGpu,
    Cpu,
}

/// Renders `scene` at `width`×`height`.
pub fn render_scene(
    scene: &Scene,
    width: u32,
    height: u32,
    device: Device<'_>,
    options: FrameOptions,
) -> Result<Picture, RenderError> {
    let t = Instant::now();
    let formula = CompiledFormula::compile(&scene.formula)
        .map_err(|e| RenderError::Formula(e.render("formula", &scene.formula)))?;
    let parse_ms = ms(t);
    let mut picture = render_compiled(scene, &formula, width, height, device, options)?;
    picture.times.parse_ms = parse_ms;
    Ok(picture)
}

/// As [`render_scene`], for a formula the caller has already compiled from `scene.formula`
/// (the parse time is then left at 0).
pub fn render_compiled(
    scene: &Scene,
    formula: &CompiledFormula,
    width: u32,
    height: u32,
    device: Device<'_>,
    options: FrameOptions,
) -> Result<Picture, RenderError> {
    check_size(width, height)?;
    let prepared = Prepared::new(formula, scene)?;
    render_prepared(scene, formula, &prepared, width, height, device, options)
}

/// As [`render_compiled`], for a tree the caller has already prepared from `scene` and
/// `formula` (its build time is the picture's tree time).
pub fn render_prepared(
    scene: &Scene,
    formula: &CompiledFormula,
    prepared: &Prepared,
    width: u32,
    height: u32,
    device: Device<'_>,
    options: FrameOptions,
) -> Result<Picture, RenderError> {
    check_size(width, height)?;
    let mut times = StageTimes {
        tree_ms: prepared.build_ms,
        ..StageTimes::default()
    };
    let (camera, uniforms) = prepared.frame(scene, width, height, options);
    let Prepared {
        params,
        tree,
        hierarchy,
        ..
    } = prepared;
    let certifying = uniforms.certified().then(|| prepared.certifying());
    let t = Instant::now();
    let shader = codegen::generate(formula)?;
    times.codegen_ms = ms(t);

    let (mut rgba, adapter) = match device {
        Device::Cpu => {
            let t = Instant::now();
            let rgba = super::cpu::render_rgba(formula, params, hierarchy, certifying, &uniforms);
            times.frame_ms = ms(t);
            (rgba, "CPU reference renderer".to_string())
        }
        Device::Gpu(gpu) => gpu_frame(
            gpu, &shader, hierarchy, certifying, &camera, &uniforms, &mut times,
        )?,
        Device::NewGpu => {
            let gpu = Gpu::new()?;
            gpu_frame(
                &gpu, &shader, hierarchy, certifying, &camera, &uniforms, &mut times,
            )?
        }
    };
    let (cut_pixels, verdicts) = take_marks(&mut rgba);
    let verdicts = scene.render.certified.then_some(verdicts);
    let marched =
        (!uniforms.brute_force() && !hierarchy.is_empty()).then(|| hierarchy.march_summary());
    Ok(Picture {
        width,
        height,
        rgba,
        cut_pixels,
        verdicts,
        adapter,
        times,
        tree: tree.stats.clone(),
        marched,
    })
}

/// A picture side is 1 to MAX_PICTURE_SIDE pixels.
fn check_size(width: u32, height: u32) -> Result<(), RenderError> {
    let sides = 1..=MAX_PICTURE_SIDE;
    if sides.contains(&width) && sides.contains(&height) {
        Ok(())
    } else {
        Err(RenderError::Size(width, height))
    }
}

fn gpu_frame(
    gpu: &Gpu,
    shader: &codegen::Shader,
    hierarchy: &Hierarchy,
    certifying: Option<&Hierarchy>,
    camera: &Camera,
    uniforms: &Uniforms,
    times: &mut StageTimes,
) -> Result<(Vec<u8>, String), RenderError> {
    let t = Instant::now();
    let mut caster = RayCaster::new(gpu, shader, hierarchy)?;
    times.pipeline_ms = ms(t);
    let t = Instant::now();
    bin_view(gpu, &mut caster, hierarchy, certifying, camera, uniforms);
    let (rgba, gpu_ms) = caster.render_rgba_timed(gpu, uniforms)?;
    times.frame_ms = ms(t);
    times.gpu_ms = gpu_ms;
    Ok((rgba, gpu.adapter.clone()))
}

/// Gives `caster` the tile lists of `camera`'s whole view, for one offscreen frame drawn
/// with `uniforms` (brute force reads none), and for a certified frame the lists of
/// `certifying` (`Prepared::certifying`; without it, certified pixels search the marched
/// boxes).
pub fn bin_view(
    gpu: &Gpu,
    caster: &mut RayCaster,
    hierarchy: &Hierarchy,
    certifying: Option<&Hierarchy>,
    camera: &Camera,
    uniforms: &Uniforms,
) {
    if !uniforms.brute_force() {
        let budget = gpu.tile_entry_budget();
        let lists = TileLists::build_within(hierarchy, camera, budget);
        caster.set_tiles(gpu, Some(&lists));
        let certifying = certifying.filter(|_| uniforms.certified());
        let lists = certifying.map(|c| TileLists::build_within(c, camera, budget));
        caster.set_cert_tiles(gpu, lists.as_ref());
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
