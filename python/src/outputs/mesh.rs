//! `mesh`: the slice at a place along n2 as a closed, outward-wound triangle mesh (the
//! mesher of `fourfold mesh`), its vertices and faces as numpy arrays, savable as STL, OBJ,
//! PLY or GLB.

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;

use fourfold::mesh::{MeshError, MeshFormat, MeshSettings, SliceMesh, describe_slice, mesh_slice};

use crate::errors::value_error;
use crate::scene::Scene;
use crate::work::run_quiet;

use crate::drawing::{compile, warn_all};

/// A slice's mesh, in the slice's frame (v1, v2, n1) and R⁴'s units.
#[pyclass(module = "fourfold", frozen)]
pub struct Mesh {
    mesh: SliceMesh,
    /// What the file's comment says it is.
    about: String,
    /// Milliseconds the mesher took.
    #[pyo3(get)]
    build_ms: f64,
}

#[pymethods]
impl Mesh {
    /// The vertices, (n, 3) floats.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat: Vec<f64> = self.mesh.vertices.iter().flatten().copied().collect();
        PyArray1::from_vec(py, flat).reshape([self.mesh.vertices.len(), 3])
    }

    /// The triangles, (m, 3) vertex indices, wound outward.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let flat: Vec<u32> = self.mesh.triangles.iter().flatten().copied().collect();
        PyArray1::from_vec(py, flat).reshape([self.mesh.triangles.len(), 3])
    }

    /// The enclosed volume (of a closed mesh).
    #[getter]
    fn volume(&self) -> f64 {
        self.mesh.volume()
    }

    /// The corners (low, high) of the mesh's bounding box.
    #[getter]
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        self.mesh.bounds()
    }

    /// What the mesher found: cells, the largest vertex distance |F|/|∇F| and the tolerance.
    #[getter]
    fn stats(&self) -> std::collections::BTreeMap<&'static str, f64> {
        let s = &self.mesh.stats;
        [
            ("visited", s.visited as f64),
            ("leaves", s.leaves as f64),
            ("tolerance", s.tolerance),
            ("max_residual", s.max_residual),
            ("over_tolerance", s.over_tolerance as f64),
            ("cell_side", self.mesh.grid.side),
        ]
        .into_iter()
        .collect()
    }

    /// Writes the mesh: .stl (binary), .obj, .ply (binary) or .glb (binary glTF), by the
    /// path's extension, multiplied by `scale`.
    #[pyo3(signature = (path, scale = 1.0))]
    fn save(&self, path: PathBuf, scale: f64) -> PyResult<()> {
        let format = MeshFormat::from_path(&path).map_err(|e| value_error(format!("path: {e}")))?;
        if !(scale.is_finite() && scale > 0.0) {
            return Err(value_error(format!("scale={scale}: a number above 0")));
        }
        let mut bytes = Vec::new();
        self.mesh
            .write(format, scale, &self.about, &mut bytes)
            .and_then(|()| std::fs::write(&path, &bytes))
            .map_err(|e| PyOSError::new_err(format!("cannot write {}: {e}", path.display())))
    }

    fn __len__(&self) -> usize {
        self.mesh.triangles.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "<Mesh: {} triangles, {} vertices, volume {:.6}>",
            self.mesh.triangles.len(),
            self.mesh.vertices.len(),
            self.mesh.volume()
        )
    }
}

/// The mesh of the scene's slice at `slice` (the scene's own slice if None).
#[pyfunction]
#[pyo3(signature = (scene, slice = None, max_level = fourfold::scene::limits::DEFAULT_MESH_LEVEL, tolerance = None, open = false))]
pub fn mesh(
    py: Python<'_>,
    scene: &Scene,
    slice: Option<f64>,
    max_level: u32,
    tolerance: Option<f64>,
    open: bool,
) -> PyResult<Mesh> {
    let offset = slice.or(scene.scene.view.slice).ok_or_else(|| {
        value_error(
            "a mesh is of a slice: give slice=C (where the hyperplane cuts along n2, from the \
             domain's centre), or a scene with a slice",
        )
    })?;
    if !offset.is_finite() {
        return Err(value_error(format!("slice={offset}: a finite number")));
    }
    let (formula, warnings) = compile(py, &scene.scene)?;
    warn_all(py, &warnings)?;
    let settings = MeshSettings {
        offset,
        max_level,
        tolerance,
        caps: !open,
    };
    let core = scene.scene.clone();
    let about = describe_slice(&formula, &core, offset);
    let (mesh, build_ms) = run_quiet(py, move |_| {
        let t = std::time::Instant::now();
        mesh_slice(&formula, &core, &settings).map(|m| (m, t.elapsed().as_secs_f64() * 1e3))
    })?
    .map_err(|e| {
        value_error(match e {
            MeshError::Level { level, lo, hi } => {
                format!("max_level={level}: the mesh's octree takes {lo} to {hi} levels")
            }
            MeshError::Tolerance(t) => {
                format!("tolerance={t}: a distance above 0, in the slice's units")
            }
            e => e.to_string().replace("(--max-level)", "(max_level)"),
        })
    })?;
    Ok(Mesh {
        mesh,
        about,
        build_ms,
    })
}
