//! `render` and `wgsl`: a picture of a scene drawn by the same code as `fourfold render`
//! (on the GPU, lavapipe where there is none; or the CPU reference renderer), handed back
//! as numpy arrays with what its making says.

use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use fourfold::headless::render_prepared;
use fourfold::render::picture::{Device, Picture, RenderError};
use fourfold::render::view::{Camera, framing::fit_scene, hidden_range};
use fourfold::render::{Prepared, shader};
use fourfold::scene::{ColorBy, Scene as CoreScene};
use fourfold::tree::BuildError;

use crate::errors::render_error;
use crate::scene::Scene;
use crate::work::{gpu, gpu_or_error, run_quiet};

use super::{compile, warn_all};

/// Where a picture is drawn.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Want {
    Gpu,
    Cpu,
    /// The GPU if one opens, else the CPU (pictures shown inline in a notebook).
    Any,
}

/// A picture and the scene it was drawn from (zoomed and centred with `fit`).
pub struct Drawn {
    pub picture: Picture,
    pub scene: CoreScene,
    pub hidden_range: Option<[f64; 2]>,
    pub warnings: Vec<String>,
}

/// Draws `scene` at its size: the command line's `render` with the GIL released and
/// Ctrl-C heard.
pub fn draw(py: Python<'_>, scene: &Scene, fit: bool, want: Option<Want>) -> PyResult<Drawn> {
    let (formula, mut warnings) = compile(py, scene)?;
    let want = want.unwrap_or(Want::Any);
    let gpu = match want {
        Want::Cpu => None,
        Want::Gpu => Some(gpu_or_error()?),
        Want::Any => gpu().ok(),
    };
    let mut core = scene.scene.clone();
    let (width, height) = scene.size;
    let drawn = run_quiet(py, move |job| {
        let prepared = Prepared::build(&formula, &core, core.tree.into(), job.stop, None).map_err(
            |e| match e {
                BuildError::Cancelled => None,
                e => Some(e.to_string()),
            },
        )?;
        if fit {
            fit_scene(&mut core, &prepared.hierarchy, width, height);
        }
        let device = gpu.as_ref().map_or(Device::Cpu, Device::Gpu);
        let picture = render_prepared(
            &core,
            &formula,
            &prepared,
            width,
            height,
            device,
            Default::default(),
        )
        .map_err(|e: RenderError| Some(e.to_string()))?;
        let hidden = (core.render.color_by == ColorBy::Hidden).then(|| {
            let camera = Camera::new(&core.domain, &core.view, width, height);
            hidden_range(&prepared.hierarchy, &core.domain, &camera)
        });
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
    Ok(Drawn {
        picture,
        scene: core,
        hidden_range,
        warnings,
    })
}

type Arrays<'py> = (
    Bound<'py, PyArray3<u8>>,
    Option<Bound<'py, PyArray2<u8>>>,
    String,
    Scene,
);

/// The picture of `scene` (at its size) as (RGBA rows (h, w, 4), verdicts (h, w) or None,
/// what its making says as JSON, the scene drawn).
#[pyfunction]
#[pyo3(signature = (scene, fit = false, cpu = false))]
pub fn render<'py>(py: Python<'py>, scene: &Scene, fit: bool, cpu: bool) -> PyResult<Arrays<'py>> {
    let want = if cpu { Want::Cpu } else { Want::Gpu };
    let Drawn {
        picture,
        scene: drawn_scene,
        hidden_range,
        warnings,
    } = draw(py, scene, fit, Some(want))?;
    warn_all(py, &warnings)?;
    let (w, h) = (picture.width as usize, picture.height as usize);
    let counts = picture.verdict_counts();
    let t = &picture.times;
    let info = serde_json::json!({
        "adapter": picture.adapter,
        "times_ms": {
            "tree": t.tree_ms,
            "codegen": t.codegen_ms,
            "pipeline": t.pipeline_ms,
            "frame": t.frame_ms,
            "gpu": t.gpu_ms,
        },
        "tree": picture.tree,
        "marched": picture.marched,
        "cut_pixels": picture.cut_pixels.len(),
        "counts": counts.map(|c| serde_json::json!({
            "hit": c.hit, "empty": c.empty, "undecided": c.undecided
        })),
        "hidden_range": hidden_range,
    });
    let verdicts = picture.verdicts.as_ref().map(|v| {
        let codes: Vec<u8> = v.iter().map(|&v| v as u8).collect();
        PyArray1::from_vec(py, codes).reshape([h, w])
    });
    let rgba = PyArray1::from_vec(py, picture.rgba).reshape([h, w, 4])?;
    Ok((
        rgba,
        verdicts.transpose()?,
        info.to_string(),
        Scene {
            scene: drawn_scene,
            size: scene.size,
        },
    ))
}

/// The complete, validated WGSL shader of the scene's formula, as `fourfold wgsl` prints it.
#[pyfunction]
pub fn wgsl(py: Python<'_>, scene: &Scene) -> PyResult<String> {
    let (formula, _) = compile(py, scene)?;
    shader::listing(&formula).map_err(render_error)
}

/// An (h, w, 4) RGBA8 array as a PNG file's bytes (a picture shown inline, or saved).
#[pyfunction]
pub fn png<'py>(
    py: Python<'py>,
    rgba: PyReadonlyArray3<'_, u8>,
) -> PyResult<Bound<'py, pyo3::types::PyBytes>> {
    let shape = rgba.shape();
    if shape[2] != 4 {
        return Err(crate::errors::value_error(format!(
            "expected an RGBA picture of shape (h, w, 4), got {shape:?}"
        )));
    }
    let (h, w) = (shape[0], shape[1]);
    let pixels: Vec<u8> = rgba.as_array().iter().copied().collect();
    let picture = Picture {
        width: w as u32,
        height: h as u32,
        rgba: pixels,
        adapter: String::new(),
        times: Default::default(),
        tree: Default::default(),
        marched: None,
        cut_pixels: Vec::new(),
        verdicts: None,
    };
    let bytes = picture.to_png().map_err(crate::errors::value_error)?;
    Ok(pyo3::types::PyBytes::new(py, &bytes))
}
