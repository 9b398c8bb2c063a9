//! Waiting for the GPU: a picture or a frame polled until it is back, with the device
//! polled meanwhile (which a web page cannot do), and the whole pipeline of one picture,
//! from a scene to its pixels.

use std::sync::atomic::AtomicBool;

use web_time::Instant;

use crate::formula::CompiledFormula;
use crate::render::Prepared;
use crate::render::gpu::{Gpu, GpuError, RayCaster};
use crate::render::picture::{Device, Painter, PendingPicture, Picture, RenderError, check_size};
use crate::render::view::{FrameOptions, TileLists, Uniforms, frame};
use crate::scene::Scene;
use crate::tree::Hierarchy;

impl PendingPicture {
    /// Waits for the picture.
    pub fn wait(mut self) -> Result<Picture, RenderError> {
        loop {
            if let Some(gpu) = self.gpu() {
                gpu.device
                    .poll(wgpu::PollType::wait_indefinitely())
                    .map_err(|e| GpuError::Readback(e.to_string()))?;
            }
            if let Some(picture) = self.poll() {
                return picture;
            }
        }
    }
}

impl RayCaster {
    /// Draws a 4×4-pixel picture of the view with the pipeline frames of `scene` will draw
    /// with (brute force, or tile lists of `hierarchy`: an empty one binds empty lists, and
    /// the pixels are drawn as background), so that a driver that readies a shader at its
    /// first draw does it now, on the caller's thread, rather than in a window's frame.
    /// llvmpipe does so at the first draw that runs the pixels' code: after a warm-up over
    /// empty lists the first frame still took 0.3 s more (docs/benchmarks.md). The caster's
    /// buffers must hold `hierarchy` or an empty one.
    pub fn warm_up(
        &mut self,
        gpu: &Gpu,
        hierarchy: &Hierarchy,
        scene: &Scene,
    ) -> Result<(), GpuError> {
        let (camera, uniforms) = frame(scene, hierarchy, &[], [4, 4], FrameOptions::default());
        self.set_tiles(gpu, Some(&TileLists::build(hierarchy, &camera)));
        self.render_rgba(gpu, &uniforms).map(|_| ())
    }

    /// Renders one frame offscreen and reads it back as tightly packed rows, 4 bytes a
    /// pixel (the RGBA8 formats, which both targets use).
    pub fn render_rgba(&self, gpu: &Gpu, uniforms: &Uniforms) -> Result<Vec<u8>, GpuError> {
        self.render_rgba_timed(gpu, uniforms).map(|(rgba, _)| rgba)
    }

    /// As [`RayCaster::render_rgba`], with the milliseconds the GPU took for the frame's
    /// pass, from timestamps written at its start and end (None where the device has no
    /// timestamp queries, `Gpu::has_timestamps`). That excludes the upload, the read-back
    /// and the CPU's work around them.
    pub fn render_rgba_timed(
        &self,
        gpu: &Gpu,
        uniforms: &Uniforms,
    ) -> Result<(Vec<u8>, Option<f64>), GpuError> {
        let pending = self.start_rgba(gpu, uniforms, true)?;
        loop {
            gpu.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            if let Some(frame) = pending.poll_timed(gpu) {
                return frame;
            }
        }
    }
}

/// `read` of the contents of a mappable buffer, once the GPU has finished writing it.
pub fn read_back<T>(
    gpu: &Gpu,
    buffer: wgpu::Buffer,
    read: impl FnOnce(&[u8]) -> T,
) -> Result<T, GpuError> {
    let mapping = crate::render::gpu::Mapping::start(buffer);
    while !mapping.ready() {
        gpu.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Readback(e.to_string()))?;
    }
    mapping.read(read)
}

/// Renders `scene` at `width`×`height`: the whole pipeline, from the formula's text.
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
    let prepared = Prepared::for_picture(formula, scene, false, &AtomicBool::new(false))?;
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
    let mut painter = Painter::for_formula(device, formula, &prepared.hierarchy, scene)?;
    let source = prepared.source(formula, scene.render.certified);
    painter
        .start(source, scene, [width, height], options)?
        .wait()
}

/// As [`render_prepared`], first zooming and centring `scene` on the manifold (the tree's
/// boxes in this view) where `fit` asks, as the viewer frames a scene it opens; the scene as
/// drawn comes back with its picture.
pub fn render_fitted(
    mut scene: Scene,
    formula: &CompiledFormula,
    prepared: &Prepared,
    width: u32,
    height: u32,
    device: Device<'_>,
    fit: bool,
) -> Result<(Picture, Scene), RenderError> {
    if fit {
        crate::render::view::framing::fit_scene(&mut scene, &prepared.hierarchy, width, height);
    }
    let picture = render_prepared(
        &scene,
        formula,
        prepared,
        width,
        height,
        device,
        FrameOptions::default(),
    )?;
    Ok((picture, scene))
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
