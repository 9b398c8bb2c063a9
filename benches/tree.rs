//! Tree build benchmark: `cargo bench --bench tree`. Prints, in one run, build time and
//! leaves for the glome and the chapter's scene at levels 4..7 under both criteria settings,
//! on one thread and on all threads, and interval evaluations per second. Each figure is the
//! best of several runs (these machines are noisy).

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use fourfold::CompiledFormula;
use fourfold::scene::Scene;
use fourfold::tree::{BuildSettings, Tree16};

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

fn main() {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let threads = rayon::current_num_threads();
    println!(
        "scene        criteria      level   leaves      1 thread   {threads} threads   speed-up   Mevals/s ({threads} thr)"
    );
    for name in ["glome", "fig-3-9-left"] {
        let scene = Scene::example(name).unwrap();
        let f = CompiledFormula::compile(&scene.formula).unwrap();
        let params = scene.param_values(&f.param_names());
        let domain = scene.domain.to_box();
        for uniform in [true, false] {
            for level in 4..=7 {
                let settings = BuildSettings {
                    max_level: level,
                    min_level: if uniform { level } else { 0 },
                    node_budget: 20_000_000,
                };
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
                let runs = if level >= 7 { 1 } else { 5 };
                let (single, _) = one.install(|| best_ms(runs, build));
                let (multi, tree) = best_ms(runs, build);
                println!(
                    "{name:<12} {:<12} {level:>6} {:>8} {single:>11.1} ms {multi:>9.1} ms {:>9.2}x {:>10.2}",
                    if uniform { "uniform" } else { "chapter" },
                    tree.stats.leaves,
                    single / multi,
                    tree.stats.interval_evaluations as f64 / multi / 1e3,
                );
            }
        }
    }
}
