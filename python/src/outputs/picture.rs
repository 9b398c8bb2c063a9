//! `render` and `wgsl`: a picture of a scene drawn by the same code as `fourfold render`
//! (on the GPU, lavapipe where there is none; or the CPU reference renderer), handed back
//! as numpy arrays with what its making says.

use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use fourfold::render::picture::encode_png;
use fourfold::render::shader;

use crate::drawing::{Drawn, Want, compile, draw, warn_all};
use crate::errors::render_error;
use crate::scene::Scene;

type Arrays<'py> = (
    Bound<'py, PyArray3<u8>>,
    Option<Bound<'py, PyArray2<u8>>>,
    String,
    Scene,
);

/// The picture of `scene` (at its size) as (RGBA rows (h, w, 4), verdicts (h, w) or None,
/// what its making says as JSON, the scene drawn).
#[pyfunction]
#[pyo3(signature = (scene, fit = false, cpu = None))]
pub fn render<'py>(
    py: Python<'py>,
    scene: &Scene,
    fit: bool,
    cpu: Option<bool>,
) -> PyResult<Arrays<'py>> {
    let want = match cpu {
        Some(true) => Want::Cpu,
        Some(false) => Want::Gpu,
        None => Want::Sooner,
    };
    let Drawn {
        picture,
        scene: drawn_scene,
        hidden_range,
        warnings,
    } = draw(py, &scene.scene, scene.size, fit, want)?;
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
    let (formula, _) = compile(py, &scene.scene)?;
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
    let bytes = encode_png(&pixels, w as u32, h as u32).map_err(crate::errors::value_error)?;
    Ok(pyo3::types::PyBytes::new(py, &bytes))
}
