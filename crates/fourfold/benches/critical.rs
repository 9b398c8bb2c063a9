//! Critical-value search benchmark: `cargo bench -p fourfold --bench critical`. For every example
//! scene, in its own view, the search at its default level and budget: the time (best of
//! three), boxes looked at, and what it found (proved points, degenerate and undecided
//! clusters, and the finest boxes left in them). `FOURFOLD_BENCH_LEVELS=6,8` picks levels.

mod common;

use std::time::Instant;

use fourfold::CompiledFormula;
use fourfold::critical::{CriticalSettings, Status, critical_values};
use fourfold::scene::EXAMPLES;
use fourfold::scene::Scene;
use fourfold::scene::limits::DEFAULT_CRITICAL_LEVEL;

fn main() {
    let levels = common::bench_levels(&DEFAULT_CRITICAL_LEVEL.to_string());
    println!(
        "{:<16} {:>5} {:>9} {:>9} {:>7} {:>11} {:>10} {:>10} {:>10} {:>6}",
        "scene",
        "level",
        "ms",
        "boxes",
        "proved",
        "degenerate",
        "undecided",
        "deg boxes",
        "und boxes",
        "spent"
    );
    for (name, _) in EXAMPLES {
        let scene = Scene::example(name).expect("an example");
        let formula = CompiledFormula::compile(&scene.formula).expect("examples compile");
        for &level in &levels {
            let settings = CriticalSettings {
                max_level: level,
                ..CriticalSettings::default()
            };
            let mut best = f64::INFINITY;
            let mut report = None;
            for _ in 0..3 {
                let t = Instant::now();
                report = Some(critical_values(&formula, &scene, &settings).expect("a level"));
                best = best.min(t.elapsed().as_secs_f64() * 1e3);
            }
            let r = report.expect("ran");
            let count = |s: Status| r.points.iter().filter(|p| p.status == s).count();
            println!(
                "{name:<16} {level:>5} {best:>9.1} {:>9} {:>7} {:>11} {:>10} {:>10} {:>10} {:>6}",
                r.visited,
                count(Status::Proved),
                count(Status::Degenerate),
                count(Status::Undecided),
                r.degenerate_boxes,
                r.undecided_boxes,
                if r.budget_spent { "yes" } else { "no" }
            );
        }
    }
}
