//! Certified pixels against the plain ray caster: `cargo bench -p fourfold --bench certified`.
//!
//! In one run, on the first adapter wgpu finds (lavapipe on a machine without a GPU):
//! 1. the certified frame against the plain one with the same rays (16), at SIZE² (default
//!    512), for the scenes of FOURFOLD_BENCH_SCENES (default the chapter's and the glome),
//!    each with its tree at level 6: by the wall clock (binning, upload, pass and read-back)
//!    and, in brackets, the GPU's pass alone, best of FOURFOLD_BENCH_RUNS (default 3) after a
//!    warm-up frame (which compiles the pipeline);
//! 2. for every example scene with its own settings, and the scenes of
//!    tests/data/unseen and unseen-hard, the verdicts of a certified frame at SIZE² and the default budget:
//!    the share of undecided pixels among those that may show M (hit or undecided); and the
//!    plain frame's time (after a warm-up frame) and recall: the share of the proved hits
//!    that a single plain frame (the scene's rays, 16 by default) draws as background.
//!    FOURFOLD_BENCH_QUICK=1 skips it;
//! 3. with FOURFOLD_BENCH_BUDGETS (a list of cell budgets, e.g. `1,4,16,64,2048`), the first
//!    table's certified frames again at each budget: where the certified pass's time goes
//!    (every pixel near M pays at least one cell per box its plane crosses).

use std::time::Instant;

mod common;
#[path = "../tests/support/unseen.rs"]
mod unseen;

use common::env_u32;
use fourfold::CompiledFormula;
use fourfold::render::shader;
use fourfold::render::verdict::{Verdict, VerdictCounts, take_marks};
use fourfold::render::{Gpu, Prepared, RayCaster};
use fourfold::scene::{EXAMPLES, Scene};

/// A frame's best wall-clock and GPU-pass milliseconds, its pixels and verdicts.
struct Timed {
    ms: f64,
    gpu_ms: Option<f64>,
    rgba: Vec<u8>,
    verdicts: Vec<Verdict>,
}

/// The best wall-clock and GPU-pass milliseconds of `runs` frames (after one to warm up),
/// and the last frame's pixels and verdicts.
fn time_frames(gpu: &Gpu, scene: &Scene, size: u32, runs: u32) -> Timed {
    let formula = CompiledFormula::compile(&scene.formula).expect("example formulas compile");
    let prepared = Prepared::new(&formula, scene).expect("the tree builds");
    let shader = shader::generate(&formula).expect("the shader validates");
    let mut caster = RayCaster::new(gpu, &shader, &prepared.hierarchy).expect("pipeline");
    let (camera, uniforms) = prepared.frame(scene, size, size, Default::default());
    let certifying = uniforms.certified().then(|| prepared.certifying(&formula));
    let (mut best, mut best_gpu) = (f64::INFINITY, None::<f64>);
    let (mut last, mut verdicts) = (Vec::new(), Vec::new());
    for run in 0..=runs {
        let t = Instant::now();
        caster.bin_view(gpu, &prepared.hierarchy, certifying, &camera, &uniforms);
        let (mut rgba, gpu_ms) = caster.render_rgba_timed(gpu, &uniforms).expect("frame");
        let ms = t.elapsed().as_secs_f64() * 1e3;
        verdicts = take_marks(&mut rgba).1;
        last = rgba;
        if run > 0 {
            best = best.min(ms);
            best_gpu = match (best_gpu, gpu_ms) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
        }
    }
    Timed {
        ms: best,
        gpu_ms: best_gpu,
        rgba: last,
        verdicts,
    }
}

fn example(name: &str) -> Scene {
    let text = EXAMPLES
        .iter()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("no example {name}"))
        .1;
    Scene::parse(text, name).expect("examples parse")
}

/// The example `name` as the first table draws it: 16 rays, its tree at level 6.
fn level_six(name: &str) -> Scene {
    let mut scene = example(name);
    scene.render.rays = 16;
    scene.tree.max_level = 6;
    scene.tree.min_level = scene.tree.min_level.min(6);
    scene
}

fn main() {
    let gpu = common::gpu_or_exit();
    let size = env_u32("FOURFOLD_BENCH_SIZE", 512);
    let runs = env_u32("FOURFOLD_BENCH_RUNS", 3);
    println!("adapter: {}", gpu.adapter);
    println!("\n## Certified frame against the plain one, {size}x{size}, 16 rays, level 6\n");
    println!(
        "| scene | plain ms [GPU pass] | certified ms [GPU pass] | certified/plain | certified/plain, GPU passes | undecided / covered |"
    );
    println!("|---|---|---|---|---|---|");
    let scenes =
        std::env::var("FOURFOLD_BENCH_SCENES").unwrap_or_else(|_| "fig-3-9-left,glome".into());
    for name in scenes.split(',').map(str::trim) {
        let mut scene = level_six(name);
        scene.render.certified = false;
        let plain = time_frames(&gpu, &scene, size, runs);
        scene.render.certified = true;
        let cert = time_frames(&gpu, &scene, size, runs);
        let counts = VerdictCounts::of(&cert.verdicts);
        let (plain_gpu, cert_gpu) = (plain.gpu_ms, cert.gpu_ms);
        let (plain, cert) = (plain.ms, cert.ms);
        let bracket = |g: Option<f64>| g.map_or(String::new(), |g| format!(" [{g:.1}]"));
        let gpu_ratio = plain_gpu
            .zip(cert_gpu)
            .map_or("-".into(), |(p, c)| format!("{:.1}x", c / p));
        println!(
            "| {name} | {plain:.1}{} | {cert:.1}{} | {:.1}x | {gpu_ratio} | {} / {} ({:.2}%) |",
            bracket(plain_gpu),
            bracket(cert_gpu),
            cert / plain,
            counts.undecided,
            counts.hit + counts.undecided,
            counts.undecided_share()
        );
    }
    if let Ok(budgets) = std::env::var("FOURFOLD_BENCH_BUDGETS") {
        by_budget(&gpu, &scenes, &budgets, size, runs);
    }
    if std::env::var("FOURFOLD_BENCH_QUICK").is_ok_and(|v| v == "1") {
        return;
    }
    println!(
        "\n## Verdicts per scene, {size}x{size}, its own settings, default budget; the plain \
         frame's misses\n"
    );
    println!(
        "| scene | hit | empty | undecided | undecided / covered | certified ms [GPU pass] | plain ms [GPU pass] | proved hits a plain frame misses |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let examples = EXAMPLES
        .iter()
        .map(|(name, _)| (name.to_string(), example(name)));
    let pass = |g: Option<f64>| g.map_or(String::new(), |g| format!(" [{g:.0}]"));
    let unseen = unseen::unseen_scenes()
        .into_iter()
        .chain(unseen::hard_scenes());
    for (name, mut scene) in examples.chain(unseen) {
        scene.render.certified = true;
        let cert = time_frames(&gpu, &scene, size, 1);
        scene.render.certified = false;
        let plain = time_frames(&gpu, &scene, size, 1);
        let c = VerdictCounts::of(&cert.verdicts);
        let background = scene.render.background.0;
        let missed = cert
            .verdicts
            .iter()
            .zip(plain.rgba.chunks(4))
            .filter(|(v, p)| **v == Verdict::Hit && p[..3] == background)
            .count();
        println!(
            "| {name} | {} | {} | {} | {:.2}% | {:.0}{} | {:.0}{} | {missed} ({:.2}%) |",
            c.hit,
            c.empty,
            c.undecided,
            c.undecided_share(),
            cert.ms,
            pass(cert.gpu_ms),
            plain.ms,
            pass(plain.gpu_ms),
            100.0 * missed as f64 / c.hit.max(1) as f64
        );
    }
}

/// The first table's certified frames at each of `budgets` (comma-separated cell counts).
fn by_budget(gpu: &Gpu, scenes: &str, budgets: &str, size: u32, runs: u32) {
    let budgets: Vec<u32> = budgets
        .split(',')
        .map(|b| {
            b.trim()
                .parse()
                .expect("FOURFOLD_BENCH_BUDGETS: cell counts")
        })
        .collect();
    println!("\n## Certified frames by cell budget, {size}x{size}, 16 rays, level 6\n");
    println!("ms by the wall clock [GPU pass], undecided pixels, at each budget\n");
    let heads: Vec<String> = budgets.iter().map(u32::to_string).collect();
    println!("| scene | {} |", heads.join(" | "));
    println!("|---|{}", "---|".repeat(budgets.len()));
    for name in scenes.split(',').map(str::trim) {
        let mut scene = level_six(name);
        scene.render.certified = true;
        let cells: Vec<String> = budgets
            .iter()
            .map(|&budget| {
                scene.render.cert_budget = budget;
                let t = time_frames(gpu, &scene, size, runs);
                let pass = t.gpu_ms.map_or(String::new(), |g| format!(" [{g:.1}]"));
                let undecided = VerdictCounts::of(&t.verdicts).undecided;
                format!("{:.1}{pass}, {undecided}", t.ms)
            })
            .collect();
        println!("| {name} | {} |", cells.join(" | "));
    }
}
