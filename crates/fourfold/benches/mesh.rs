//! Slice mesh benchmark: `cargo bench -p fourfold --bench mesh`. For every example scene, in its own
//! view, the slice at 0 (the middle of the domain along n2) meshed at levels 6 and 8: the
//! time (best of three), triangles, octree cells kept, the largest vertex distance
//! |F|/|∇F| against the tolerance, and the vertices beyond it. `FOURFOLD_BENCH_LEVELS=5,7`
//! picks the levels.

mod common;

use std::time::Instant;

use fourfold::CompiledFormula;
use fourfold::mesh::{MeshSettings, mesh_slice};
use fourfold::scene::EXAMPLES;
use fourfold::scene::Scene;

fn main() {
    let levels = common::bench_levels("6,8");
    println!(
        "{:<16} {:>5} {:>9} {:>10} {:>9} {:>11} {:>11} {:>7}",
        "scene", "level", "ms", "triangles", "cells", "max dist", "tolerance", "beyond"
    );
    for (name, _) in EXAMPLES {
        let scene = Scene::example(name).expect("an example");
        let formula = CompiledFormula::compile(&scene.formula).expect("examples compile");
        for &level in &levels {
            let settings = MeshSettings {
                max_level: level,
                ..MeshSettings::new(0.0)
            };
            let mut best = f64::INFINITY;
            let mut result = None;
            for _ in 0..3 {
                let t = Instant::now();
                result = Some(mesh_slice(&formula, &scene, &settings));
                best = best.min(t.elapsed().as_secs_f64() * 1e3);
            }
            match result.expect("ran") {
                Ok(m) => println!(
                    "{name:<16} {level:>5} {best:>9.1} {:>10} {:>9} {:>11.2e} {:>11.2e} {:>7}",
                    m.triangles.len(),
                    m.stats.leaves,
                    m.stats.max_residual,
                    m.stats.tolerance,
                    m.stats.over_tolerance
                ),
                Err(e) => println!("{name:<16} {level:>5} {best:>9.1} {e}"),
            }
        }
    }
}
