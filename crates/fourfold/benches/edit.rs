//! Edit latency of the viewer, stage by stage: `cargo bench -p fourfold --bench edit`.
//!
//! For three presets, from the formula string to the first picture, the way the viewer does
//! it on an edit (src/viewer/session.rs, progressive.rs): parse, gradient (lowering and
//! symbolic differentiation), WGSL generation + naga validation, tree build + hierarchy,
//! pipeline creation, and the first frame, which in the viewer is the preview (1280x800
//! window picture divided by the preview divisor, 4 rays). Then the frame time while
//! rotating: previews at new angles, as the viewer draws while a slider or the mouse moves.
//! The GPU is the first adapter wgpu finds; each figure is the best of RUNS.

use std::time::Instant;

mod common;

use fourfold::CompiledFormula;
use fourfold::render::{FrameOptions, Prepared, RayCaster, TileLists, shader};
use fourfold::scene::Scene;
use fourfold::syntax;

const RUNS: usize = 3;

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn main() {
    let mut gpu = common::gpu_or_exit();
    // No pipelines kept between runs: an edit makes a shader no run compiled before.
    gpu.pipeline_cache = None;
    let (width, height) = (1280u32, 800u32);
    let div = common::env_u32("FOURFOLD_PREVIEW_DIV", 8);
    let (pw, ph) = (width.div_ceil(div), height.div_ceil(div));
    println!("adapter: {}", gpu.adapter);
    println!("window {width}x{height}, preview {pw}x{ph} (1/{div}) with 4 rays; best of {RUNS}\n");
    println!(
        "| preset | parse | gradient | WGSL + naga | tree | pipeline | first frame | total | rotating frame |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for name in ["glome", "fig-3-9-left", "tiger"] {
        let scene = Scene::example(name).unwrap();
        let mut best = [f64::INFINITY; 8];
        for run in 1..=RUNS {
            // A constant no run before used, as an edit makes (the driver may keep the
            // pipelines of a shader it compiled in this process).
            let text = format!("{} + 0.00{run}", scene.formula);
            let start = Instant::now();
            let t = Instant::now();
            syntax::parse(&text).unwrap();
            let parse = ms(t);
            let t = Instant::now();
            let f = CompiledFormula::compile(&text).unwrap();
            // compile() parses again; what is left is lowering and differentiation.
            let gradient = (ms(t) - parse).max(0.0);
            let t = Instant::now();
            let shader = shader::generate(&f).unwrap();
            let wgsl = ms(t);
            let t = Instant::now();
            let prepared = Prepared::new(&f, &scene).unwrap();
            let tree_ms = ms(t);
            let hierarchy = &prepared.hierarchy;
            let t = Instant::now();
            let mut caster = RayCaster::new(&gpu, &shader, hierarchy).unwrap();
            let pipeline = ms(t);
            let mut preview = scene.clone();
            preview.render.rays = 4;
            // The viewer's preview is plain (certified pixels wait for the settled picture).
            preview.render.certified = false;
            let mut frame = |angles: [f64; 6]| {
                preview.view.angles = angles;
                let (camera, u) = prepared.frame(&preview, pw, ph, FrameOptions::default());
                // As the viewer: bin the leaves into screen tiles, then draw.
                let t = Instant::now();
                caster.set_tiles(&gpu, Some(&TileLists::build(hierarchy, &camera)));
                caster.render_rgba(&gpu, &u).unwrap();
                ms(t)
            };
            let first = frame(scene.view.angles);
            let total = ms(start);
            let mut rotating = 0.0;
            for k in 1..=5 {
                let mut a = scene.view.angles;
                a[2] += 0.05 * k as f64;
                rotating += frame(a) / 5.0;
            }
            let run = [
                parse, gradient, wgsl, tree_ms, pipeline, first, total, rotating,
            ];
            for (b, r) in best.iter_mut().zip(run) {
                *b = b.min(r);
            }
        }
        let [
            parse,
            gradient,
            wgsl,
            tree,
            pipeline,
            first,
            total,
            rotating,
        ] = best;
        println!(
            "| {name} | {parse:.2} | {gradient:.2} | {wgsl:.1} | {tree:.0} | {pipeline:.0} | {first:.0} | {total:.0} | {rotating:.0} |"
        );
    }
}
