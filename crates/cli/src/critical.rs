//! `fourfold critical`: the sweep's proved critical values (where the slice along n2 can
//! change its topology), as a table or JSON.

use clap::Args;

use fourfold::critical::{CriticalError, CriticalReport, CriticalSettings, critical_values};
use fourfold::scene::limits::{CRITICAL_BOX_BUDGET, DEFAULT_CRITICAL_LEVEL};

use crate::failure::Failure;
use crate::input::{Input, Warn, checked, compile_warning, load_scene};
use crate::render::parse_angles;

#[derive(Debug, Clone, Args)]
pub struct CriticalArgs {
    #[command(flatten)]
    pub input: Input,
    /// The six rotation angles θ1..θ6 in radians: n2 is the fourth row of the rotation.
    #[arg(long, allow_hyphen_values = true)]
    pub angles: Option<String>,
    /// Levels of the search, 2 to 14: its finest boxes are the domain / 2^level.
    #[arg(long, default_value_t = DEFAULT_CRITICAL_LEVEL, allow_hyphen_values = true)]
    pub max_level: u32,
    /// The most boxes to look at; what is left then is reported undecided.
    #[arg(long, default_value_t = CRITICAL_BOX_BUDGET, allow_hyphen_values = true)]
    pub budget: usize,
    /// Leave out the critical points of M's cut by the domain's boundary (its faces, where
    /// they meet, its edges).
    #[arg(long)]
    pub no_boundary: bool,
    /// Print a JSON list of objects instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `fourfold critical`.
pub fn critical(args: &CriticalArgs, warn: Warn) -> Result<String, Failure> {
    if args.budget == 0 {
        return Err(Failure::usage(
            "--budget 0: the search needs at least one box",
        ));
    }
    let mut scene = load_scene(&args.input)?;
    if let Some(text) = &args.angles {
        scene.view.angles = parse_angles(text)?;
    }
    let scene = checked(scene)?;
    let formula = compile_warning(&scene, warn)?;
    let settings = CriticalSettings {
        max_level: args.max_level,
        box_budget: args.budget,
        boundary: !args.no_boundary,
    };
    let t = std::time::Instant::now();
    let report = critical_values(&formula, &scene, &settings).map_err(|e| match e {
        CriticalError::Level { level, lo, hi } => Failure::usage(format!(
            "--max-level {level}: the search takes {lo} to {hi} levels"
        )),
    })?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    if args.json {
        return Ok(report.to_json().to_string());
    }
    Ok(table(&report, &formula.f_text(), scene.view.angles, ms))
}

fn table(report: &CriticalReport, f: &str, angles: [f64; 6], ms: f64) -> String {
    let mut out = format!(
        "critical values of the slice sweep of F = {f}\nalong n2 of angles {angles:?}; \
         slices from -{reach:.6} to {reach:.6} meet the domain\n\n",
        reach = report.reach
    );
    if report.points.is_empty() {
        out.push_str("none: every slice has the same topology\n");
    } else {
        out.push_str(&format!(
            "{:>12} {:>9}  {:<6} {:<10} {:<12} {:<40} {}\n",
            "c", "±", "index", "status", "where", "point (x, y, z, w)", "as c rises"
        ));
    }
    for p in &report.points {
        let index = p.index.map_or("-".into(), |i| i.to_string());
        let point = p.point().map(|v| format!("{v:.5}")).join(", ");
        let boxes = if p.boxes > 1 {
            format!(" ({} boxes)", p.boxes)
        } else {
            String::new()
        };
        out.push_str(&format!(
            "{:>12.6} {:>9.1e}  {:<6} {:<10} {:<12} {:<40} {}{boxes}\n",
            p.value.midpoint(),
            0.5 * p.value.width(),
            index,
            p.status.name(),
            p.place.describe(),
            format!("({point})"),
            p.meaning(),
        ));
    }
    out.push_str(&format!(
        "\nsearched {} boxes in {ms:.0} ms; {} finest boxes left degenerate, {} undecided{}\n\
         Between consecutive values the slice's topology is constant (docs/critical.md).",
        report.visited,
        report.degenerate_boxes,
        report.undecided_boxes,
        if report.budget_spent {
            "; the budget ran out (--budget): what was left is undecided"
        } else {
            ""
        }
    ));
    out
}
