//! How settled the viewer's picture is when it stops refining: `cargo bench -p fourfold-viewer --bench quality`.
//!
//! For each example scene at SIZE² (default 512) with its own view and settings, the passes
//! the viewer accumulates once the picture is complete (`ACCUMULATED_PASSES` full-size
//! passes with new ray offsets, each blended into an RGBA8 running mean with weight
//! 1/(k+1), rounded as the viewer's target rounds it), drawn on the first adapter wgpu
//! finds. Reported: the covered pixels (not background after the last pass), and how many
//! pixels the last pass still changed, by at least 1, 8 and 32 levels of 255 in some
//! channel (what could still be seen to flicker if refinement went on); and the speckle
//! left in the final picture: the pixels where two final pictures made with different
//! seeds (other ray offsets) differ by at least 8 and 32 levels.
//! Environment: FOURFOLD_BENCH_SIZE, FOURFOLD_BENCH_SCENES (comma-separated example names).

// The benchmarks' shared helpers, kept once beside the core's benchmarks.
#[path = "../../fourfold/benches/common/mod.rs"]
mod common;

use fourfold::CompiledFormula;
use fourfold::render::{FrameOptions, Gpu, Prepared, RayCaster, TileLists, shader};
use fourfold::scene::{EXAMPLES, Scene};
use fourfold_viewer::progressive::ACCUMULATED_PASSES;

fn main() {
    let gpu = common::gpu_or_exit();
    let size = common::env_u32("FOURFOLD_BENCH_SIZE", 512);
    let names: Vec<String> = match std::env::var("FOURFOLD_BENCH_SCENES") {
        Ok(list) => list.split(',').map(|s| s.trim().to_string()).collect(),
        Err(_) => EXAMPLES.iter().map(|(n, _)| n.to_string()).collect(),
    };
    println!("adapter: {}", gpu.adapter);
    println!(
        "{size}x{size}, {ACCUMULATED_PASSES} accumulated passes; pixels the last pass changed\n"
    );
    println!(
        "| scene | rays | covered | last pass changed ≥ 1 | ≥ 8 | ≥ 32 | another seed differs ≥ 8 | ≥ 32 |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for name in names {
        let mut scene = Scene::example(&name).unwrap_or_else(|| panic!("no example {name}"));
        // The plain pencil's passes: how far averaging alone settles a picture (the viewer's
        // certified first pass, which the passes after it keep where they find nothing, is
        // `cargo bench --bench certified`'s).
        scene.render.certified = false;
        let (last, [any, visible, strong]) = accumulate(&gpu, &scene, size);
        let mut reseeded = scene.clone();
        reseeded.render.seed = scene.render.seed.wrapping_add(1);
        let (other, _) = accumulate(&gpu, &reseeded, size);
        let background = scene.render.background.0;
        let covered = last.chunks(4).filter(|p| p[..3] != background).count();
        let [speckle, strong_speckle] = [8, 32].map(|level| differing(&last, &other, level));
        let share = |n: usize| format!("{n} ({:.2}%)", 100.0 * n as f64 / covered.max(1) as f64);
        println!(
            "| {name} | {} | {covered} | {} | {} | {} | {} | {} |",
            scene.render.rays,
            share(any),
            share(visible),
            share(strong),
            share(speckle),
            share(strong_speckle)
        );
    }
}

/// Pixels of two RGBA8 pictures whose colours differ by at least `level` in some channel.
fn differing(a: &[u8], b: &[u8], level: u8) -> usize {
    a.chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| (0..3).any(|i| p[i].abs_diff(q[i]) >= level))
        .count()
}

/// The final accumulated picture, and the pixels its last pass changed by ≥ 1, ≥ 8 and
/// ≥ 32 levels.
fn accumulate(gpu: &Gpu, scene: &Scene, size: u32) -> (Vec<u8>, [usize; 3]) {
    let formula = CompiledFormula::compile(&scene.formula).unwrap();
    let prepared = Prepared::new(&formula, scene).unwrap();
    let shader = shader::generate(&formula).unwrap();
    let mut caster = RayCaster::new(gpu, &shader, &prepared.hierarchy).unwrap();
    let (camera, _) = prepared.frame(scene, size, size, FrameOptions::default());
    caster.set_tiles(gpu, Some(&TileLists::build(&prepared.hierarchy, &camera)));
    let mut mean: Vec<u8> = Vec::new();
    let mut changed = [0; 3];
    for k in 0..ACCUMULATED_PASSES {
        let options = FrameOptions {
            frame: k,
            brute_force_level: None,
            ..FrameOptions::default()
        };
        let (_, uniforms) = prepared.frame(scene, size, size, options);
        let pass = caster.render_rgba(gpu, &uniforms).unwrap();
        if mean.is_empty() {
            mean = pass;
            continue;
        }
        // target = c·new + (1 − c)·old, in unorm8 as the viewer's target blends.
        let c = 1.0 / f64::from(k + 1);
        let next: Vec<u8> = mean
            .iter()
            .zip(&pass)
            .map(|(&old, &new)| (c * f64::from(new) + (1.0 - c) * f64::from(old)).round() as u8)
            .collect();
        if k + 1 == ACCUMULATED_PASSES {
            changed = [1, 8, 32].map(|level| differing(&mean, &next, level));
        }
        mean = next;
    }
    (mean, changed)
}
