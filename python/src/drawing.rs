//! Drawing a scene, shared by `render` and a scene shown inline in Jupyter: its formula
//! compiled (with the command line's warnings about parameters), then the command line's
//! path, `Prepared` → `render_prepared`, with the GIL released and Ctrl-C heard.

use std::sync::Arc;

use pyo3::prelude::*;

use fourfold::formula::CompiledFormula;
use fourfold::headless::render_fitted;
use fourfold::render::Prepared;
use fourfold::render::picture::{Device, Picture, RenderError, sooner_on_cpu};
use fourfold::render::view::scene_hidden_range;
use fourfold::scene::{ColorBy, Scene as CoreScene};
use fourfold::tree::BuildError;

use crate::errors::render_error;
use crate::formula::Formula;
use crate::work::{gpu, gpu_or_error, run_quiet};

/// The scene's formula compiled (a `FormulaError` if it does not parse), and the warnings
/// for parameters it uses that the scene leaves at 1.0, or that the scene sets and it does
/// not use.
pub fn compile(py: Python<'_>, scene: &CoreScene) -> PyResult<(Arc<CompiledFormula>, Vec<String>)> {
    let formula = Formula::compile(py, &scene.formula)?;
    let (missing, unused) = formula.param_mismatch(&scene.params);
    let mut warnings: Vec<String> = missing
        .iter()
        .map(|name| {
            format!("parameter {name} has no value; using 1.0 (give params={{'{name}': VALUE}})")
        })
        .collect();
    warnings.extend(
        unused
            .iter()
            .map(|name| format!("parameter {name} is set but the formula does not use it")),
    );
    Ok((formula, warnings))
}

/// Issues each of `warnings` as a Python `UserWarning`.
pub fn warn_all(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    for w in warnings {
        let message = std::ffi::CString::new(w.replace('\0', " ")).unwrap_or_default();
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &message,
            2,
        )?;
    }
    Ok(())
}

/// Where a picture is drawn.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Want {
    Gpu,
    Cpu,
    /// The CPU for a slice it draws sooner than a GPU could be opened for it (as `fourfold
    /// render`), else the GPU.
    Sooner,
    /// As `Sooner`, but the CPU where no GPU opens (pictures shown inline in a notebook).
    Any,
}

/// A picture and the scene it was drawn from (zoomed and centred with `fit`).
pub struct Drawn {
    pub picture: Picture,
    pub scene: CoreScene,
    pub hidden_range: Option<[f64; 2]>,
    pub warnings: Vec<String>,
}

/// Draws `scene` at `width`×`height`: the command line's `render` with the GIL released
/// and Ctrl-C heard.
pub fn draw(
    py: Python<'_>,
    scene: &CoreScene,
    (width, height): (u32, u32),
    fit: bool,
    want: Want,
) -> PyResult<Drawn> {
    let (formula, mut warnings) = compile(py, scene)?;
    let on_cpu = want == Want::Cpu
        || (matches!(want, Want::Sooner | Want::Any) && sooner_on_cpu(scene, width, height));
    let gpu = match want {
        _ if on_cpu => None,
        Want::Any => gpu().ok(),
        _ => Some(gpu_or_error()?),
    };
    let core = scene.clone();
    let drawn = run_quiet(py, move |job| {
        let prepared =
            Prepared::for_picture(&formula, &core, fit, job.stop).map_err(|e| match e {
                BuildError::Cancelled => None,
                e => Some(e.to_string()),
            })?;
        let device = gpu.as_ref().map_or(Device::Cpu, Device::Gpu);
        let (picture, core) = render_fitted(core, &formula, &prepared, width, height, device, fit)
            .map_err(|e: RenderError| Some(e.to_string()))?;
        let hidden = (core.render.color_by == ColorBy::Hidden)
            .then(|| scene_hidden_range(&prepared.hierarchy, &core));
        Ok::<_, Option<String>>((picture, core, hidden))
    })?;
    let (picture, core, hidden_range) = match drawn {
        Ok(d) => d,
        Err(Some(message)) => return Err(render_error(message)),
        Err(None) => return Err(render_error("the picture was stopped")),
    };
    if !picture.cut_pixels.is_empty() {
        warnings.push(format!(
            "the GPU driver cut the work of {} pixels short (llvmpipe stops a shader's loops \
             after 65535 iterations), so they may miss parts of the manifold: lower rays, \
             steps or max_level, or render with cpu=True",
            picture.cut_pixels.len()
        ));
    }
    warnings.extend(fourfold::render::verdict::touching_note(&picture.tree));
    Ok(Drawn {
        picture,
        scene: core,
        hidden_range,
        warnings,
    })
}
