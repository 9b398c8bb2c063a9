//! `animate`: the manifold turning, a parameter sweeping or a slice moving, drawn frame by
//! frame into a GIF, an animated PNG or a folder, as `fourfold animate` draws it; progress
//! goes to a callback, and Ctrl-C stops after the frame being drawn with the file finished.

use std::path::PathBuf;

use pyo3::prelude::*;

use fourfold::critical::sweep::{place_frames, straddle_lines};
use fourfold::headless::{FrameDevice, Output, draw};
use fourfold::render::animation::{
    Animation, Sweep, Turn, fps_problem, frames_problem, parse_range,
};

use crate::errors::{render_error, value_error};
use crate::scene::Scene;
use crate::work::{OnInterrupt, gpu_or_error, run};

use crate::drawing::{compile, warn_all};

/// Draws the animation into `path`; `progress(done, total)` hears of each frame. What was
/// drawn, as JSON.
#[pyfunction]
#[pyo3(signature = (scene, path, turn = None, sweep = None, slice_sweep = None, frames = 60, fps = 24.0, fit = false, cpu = false, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn animate(
    py: Python<'_>,
    scene: &Scene,
    path: PathBuf,
    turn: Option<&str>,
    sweep: Option<&str>,
    slice_sweep: Option<&str>,
    frames: u32,
    fps: f64,
    fit: bool,
    cpu: bool,
    progress: Option<Bound<'_, PyAny>>,
) -> PyResult<String> {
    let sweep = sweep
        .map(Sweep::parse)
        .transpose()
        .map_err(|e| value_error(format!("sweep: {e}")))?;
    // The swept parameter has a value in every frame: no warning that it has none.
    let mut core = scene.scene.clone();
    if let Some(s) = &sweep {
        core.params.entry(s.name.clone()).or_insert(s.from);
    }
    let (formula, warnings) = compile(py, &core)?;
    let turn = turn
        .map(Turn::parse)
        .transpose()
        .map_err(|e| value_error(format!("turn: {e}")))?;
    if let Some(s) = &sweep {
        formula
            .check_param(&s.name)
            .map_err(|e| value_error(format!("sweep: {e}")))?;
    }
    let slice_sweep = slice_sweep
        .map(parse_range)
        .transpose()
        .map_err(|e| value_error(format!("slice_sweep: {e}")))?;
    if let Some(problem) = frames_problem(frames) {
        return Err(value_error(format!("frames={frames}: {problem}")));
    }
    if let Some(problem) = fps_problem(fps) {
        return Err(value_error(format!("fps={fps}: {problem}")));
    }
    if turn.is_none() && sweep.is_none() && slice_sweep.is_none() {
        return Err(value_error(
            "nothing moves: give turn='xw' (a plane, or θ1..θ6), sweep='R=1..2' or \
             slice_sweep=(-0.5, 0.5)",
        ));
    }
    let mut animation = Animation {
        turn,
        sweep,
        slice_sweep,
        slice_places: Vec::new(),
        frames,
        fps,
    };
    let output = Output::from_path(&path).map_err(value_error)?;
    let gpu = if cpu { None } else { Some(gpu_or_error()?) };
    warn_all(py, &warnings)?;
    let (width, height) = scene.size;
    let started = std::time::Instant::now();
    let summary = run(
        py,
        OnInterrupt::WindUp,
        move |job| {
            let report = place_frames(&mut animation, &formula, &core);
            let mut writer = output.open(width, height, animation.fps, animation.frames)?;
            let device = gpu.as_ref().map_or(FrameDevice::Cpu, FrameDevice::Gpu);
            let drawn = draw(
                &core,
                &formula,
                &animation,
                width,
                height,
                fit,
                device,
                job.stop,
                |k, rgba| {
                    writer.add(rgba)?;
                    job.progress(k + 1);
                    Ok(())
                },
            );
            // The frames drawn so far are written whatever stopped the drawing.
            let wrote = writer.finish()?;
            let drawn = drawn?;
            let straddles = report
                .map(|r| straddle_lines(&animation.slice_places, &r))
                .unwrap_or_default();
            Ok::<_, String>(serde_json::json!({
                "wrote": wrote,
                "frames": drawn.frames,
                "requested": animation.frames,
                "seconds": started.elapsed().as_secs_f64(),
                "adapter": gpu.as_ref().map_or("CPU reference renderer", |g| g.adapter.as_str()),
                "counts": drawn.verdicts.map(|c| serde_json::json!({
                    "hit": c.hit, "empty": c.empty, "undecided": c.undecided
                })),
                "cut_pixels": drawn.cut,
                "slice_places": animation.slice_places,
                "straddles": straddles,
            }))
        },
        |py, done| match &progress {
            Some(callback) => callback.call1((done, frames)).map(|_| ()),
            None => {
                let _ = py;
                Ok(())
            }
        },
    )?;
    summary.map(|s| s.to_string()).map_err(render_error)
}
