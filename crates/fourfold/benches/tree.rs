//! Tree build benchmark: `cargo bench -p fourfold --bench tree`. Prints, in one run, build time and
//! leaves for the glome, the chapter's scene, the tiger and a trigonometric formula: at each
//! scene's own settings, then refined to levels 4..7 under both criteria settings, on one
//! thread (as in the browser) and on all threads, and interval evaluations per second. Each
//! figure is the best of several runs (these machines are noisy).
//!
//! `FOURFOLD_BENCH_LEVELS=4,5,6` picks the levels; `FOURFOLD_BENCH_SCENES=glome,trig` the
//! scenes.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use fourfold::CompiledFormula;
use fourfold::scene::Scene;
use fourfold::tree::{BuildSettings, Tree16};

/// The trigonometric formula of `cargo bench -p fourfold --bench interval`, on the default domain.
const TRIG: &str = "sin(3x)cos(3y) + sin(3z)cos(3w) - 0.2";

fn best_ms(runs: usize, mut f: impl FnMut() -> Tree16) -> (f64, Tree16) {
    let mut best = f64::INFINITY;
    let mut tree = f();
    for _ in 0..runs {
        let t = Instant::now();
        tree = f();
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
    }
    (best, tree)
}

fn scene(name: &str) -> Scene {
    match name {
        "trig" => Scene::from_formula(TRIG),
        name => Scene::example(name).unwrap_or_else(|| panic!("no example scene {name}")),
    }
}

fn list(var: &str, default: &str) -> Vec<String> {
    std::env::var(var)
        .unwrap_or_else(|_| default.into())
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect()
}

fn main() {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let threads = rayon::current_num_threads();
    let levels: Vec<u32> = list("FOURFOLD_BENCH_LEVELS", "4,5,6,7")
        .iter()
        .map(|l| l.parse().expect("FOURFOLD_BENCH_LEVELS: levels like 4,5,6"))
        .collect();
    println!(
        "scene        criteria      level   leaves      1 thread   {threads} threads   speed-up   Mevals/s ({threads} thr)"
    );
    for name in list("FOURFOLD_BENCH_SCENES", "glome,fig-3-9-left,tiger,trig") {
        let scene = scene(&name);
        let f = CompiledFormula::compile(&scene.formula).unwrap();
        let params = scene.param_values(&f.param_names());
        let domain = scene.domain.to_box();
        let mut rows = vec![("scene", BuildSettings::from(scene.tree))];
        for uniform in [true, false] {
            for &level in &levels {
                let criteria = if uniform { "uniform" } else { "chapter" };
                let min_level = if uniform { level } else { 0 };
                let settings = BuildSettings {
                    max_level: level,
                    min_level,
                    node_budget: 20_000_000,
                };
                rows.push((criteria, settings));
            }
        }
        for (criteria, settings) in rows {
            let build = || {
                Tree16::build(
                    &f,
                    &params,
                    &domain,
                    settings,
                    &AtomicBool::new(false),
                    None,
                )
                .unwrap()
            };
            let runs = if settings.max_level >= 7 { 1 } else { 5 };
            let (single, _) = one.install(|| best_ms(runs, build));
            let (multi, tree) = best_ms(runs, build);
            println!(
                "{name:<12} {criteria:<12} {:>6} {:>8} {single:>11.1} ms {multi:>9.1} ms {:>9.2}x {:>10.2}",
                settings.max_level,
                tree.stats.leaves,
                single / multi,
                tree.stats.interval_evaluations as f64 / multi / 1e3,
            );
        }
    }
}
