//! `critical`: the sweep's proved critical values (where the slice along n2 can change its
//! topology), as `fourfold critical --json` gives them, searched in steps so that Ctrl-C
//! stops the search.

use std::time::Duration;

use pyo3::prelude::*;

use fourfold::critical::{CriticalError, CriticalSettings, CriticalSteps};
use fourfold::scene::limits::{CRITICAL_BOX_BUDGET, DEFAULT_CRITICAL_LEVEL};

use crate::errors::{render_error, value_error};
use crate::scene::Scene;
use crate::work::run_quiet;

use crate::drawing::{compile, warn_all};

/// How long the search works between two looks at the stop flag.
const STEP: Duration = Duration::from_millis(50);

/// The report as JSON: `points` (as the command's `--json`), `reach`, `visited`,
/// `degenerate_boxes`, `undecided_boxes`, `budget_spent`.
#[pyfunction]
#[pyo3(signature = (scene, max_level = DEFAULT_CRITICAL_LEVEL, budget = CRITICAL_BOX_BUDGET, boundary = true))]
pub fn critical(
    py: Python<'_>,
    scene: &Scene,
    max_level: u32,
    budget: usize,
    boundary: bool,
) -> PyResult<String> {
    if budget == 0 {
        return Err(value_error("budget=0: the search needs at least one box"));
    }
    let (formula, warnings) = compile(py, &scene.scene)?;
    warn_all(py, &warnings)?;
    let settings = CriticalSettings {
        max_level,
        box_budget: budget,
        boundary,
    };
    let mut steps = CriticalSteps::new(formula, &scene.scene, &settings).map_err(|e| match e {
        CriticalError::Level { level, lo, hi } => value_error(format!(
            "max_level={level}: the search takes {lo} to {hi} levels"
        )),
    })?;
    let report = run_quiet(py, move |job| {
        loop {
            if job.stopped() {
                return None;
            }
            if let Some(report) = steps.step(STEP) {
                return Some(report);
            }
        }
    })?
    .ok_or_else(|| render_error("the search was stopped"))?;
    Ok(serde_json::json!({
        "points": report.to_json(),
        "reach": report.reach,
        "visited": report.visited,
        "degenerate_boxes": report.degenerate_boxes,
        "undecided_boxes": report.undecided_boxes,
        "budget_spent": report.budget_spent,
    })
    .to_string())
}
