//! `tree`: the 16-tree's leaves as arrays (box corners, levels, the topological flag) and
//! the statistics `fourfold tree --json` prints.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;

use fourfold::render::Prepared;
use fourfold::tree::BuildError;

use crate::errors::render_error;
use crate::scene::Scene;
use crate::work::run_quiet;

use crate::drawing::{compile, warn_all};

type Leaves<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<u32>>,
    Bound<'py, PyArray1<bool>>,
    String,
);

/// The tree's leaves: lows (n, 4), highs (n, 4), levels (n,), and whether 0 is in every
/// partial derivative's enclosure there (n,); and the statistics as JSON.
#[pyfunction]
pub fn tree<'py>(py: Python<'py>, scene: &Scene) -> PyResult<Leaves<'py>> {
    let (formula, warnings) = compile(py, &scene.scene)?;
    warn_all(py, &warnings)?;
    let core = scene.scene.clone();
    let built = run_quiet(py, move |job| {
        let settings = core.tree.into();
        let prepared = Prepared::build(&formula, &core, settings, job.stop, None)?;
        let report = prepared.tree_report(settings).to_string();
        let tree = &prepared.tree;
        let mut lows = Vec::new();
        let mut highs = Vec::new();
        let mut levels = Vec::new();
        let mut critical = Vec::new();
        for (level, b) in tree.leaves() {
            let bx = tree.box_of(level, b);
            lows.extend(bx.iter().map(|i| i.lo()));
            highs.extend(bx.iter().map(|i| i.hi()));
            levels.push(level);
            critical.push(b.critical);
        }
        Ok::<_, BuildError>((lows, highs, levels, critical, report))
    })?;
    let (lows, highs, levels, critical, report) = built.map_err(|e| match e {
        BuildError::Cancelled => render_error("the tree build was stopped"),
        e => render_error(e),
    })?;
    let n = levels.len();
    Ok((
        PyArray1::from_vec(py, lows).reshape([n, 4])?,
        PyArray1::from_vec(py, highs).reshape([n, 4])?,
        PyArray1::from_vec(py, levels),
        PyArray1::from_vec(py, critical),
        report,
    ))
}
