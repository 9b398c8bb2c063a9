//! Frame-time benchmark of the GPU ray caster: `cargo bench -p fourfold --bench frame`.
//!
//! In one run, on the first adapter wgpu finds (lavapipe on a machine without a GPU):
//! 1. the chapter's scene and the glome at SIZE² (default 512) with 8, 16 and 32 rays, drawn
//!    with the per-tile lists of the boxes to march (the default: the nodes one level above
//!    the finest leaves; the CPU binning of the boxes into the lists is included and shown),
//!    the same with the leaves themselves as the boxes (the previous design: march level =
//!    finest level), with the per-pixel walk of the sphere hierarchy (only with
//!    FOURFOLD_BENCH_WALK=1: slow on a software GPU), and by the brute-force variant (no
//!    hierarchy: every ray marched across the whole domain with the step count per unit
//!    length of the level's leaves, its own pipeline with the same march code), at
//!    tree levels 5, 6 and 7 (uniform trees, so the leaf size is the level's), as a ratio, with
//!    the share of pixels on which the two pictures agree;
//! 2. how the frame time grows with pixels, rays and tree level (glome);
//! 3. the frame time by march level (levels 0 to 6 above the finest, and the default cut,
//!    256², 16 rays, level 6).
//!
//! Environment: FOURFOLD_BENCH_LEAVES=0 skips the leaves column, FOURFOLD_BENCH_SIZE
//! (default 512), FOURFOLD_BENCH_LEVELS (default "5,6,7"),
//! FOURFOLD_BENCH_RAYS (default "8,16,32"), FOURFOLD_BENCH_SCENES (default
//! "fig-3-9-left,glome"; an example's name or a scene file's path ending in .toml),
//! FOURFOLD_BENCH_STEPS and FOURFOLD_BENCH_ITERS (steps per span and bisection iterations,
//! default the scene's), FOURFOLD_BENCH_QUICK=1 skips tables 2 and 3.
//! Frame times are the best of FOURFOLD_BENCH_RUNS (default 2) after warming up (a frame and
//! at least 200 ms of them), by the wall clock (the CPU binning, upload, pass and read-back
//! of the picture); in square brackets, where the device has timestamp queries, the best GPU
//! time of the pass alone.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

mod common;

use common::env_u32;
use fourfold::CompiledFormula;
use fourfold::render::shader;
use fourfold::render::{Camera, FrameOptions, Gpu, Prepared, RayCaster, TileLists, Uniforms};
use fourfold::scene::Scene;
use fourfold::tree::{BuildSettings, Hierarchy, Tree16};

fn env_list(name: &str, default: &str) -> Vec<u32> {
    std::env::var(name)
        .unwrap_or_else(|_| default.to_string())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect()
}

struct Case {
    scene: Scene,
    formula: CompiledFormula,
    params: Vec<f64>,
    /// The default hierarchy (down to the march level) and its caster.
    hierarchy: Hierarchy,
    caster: RayCaster,
    /// Every node down to the leaves and its caster (built when first needed; None inside
    /// if the device cannot hold it).
    full: Option<Option<(Hierarchy, RayCaster)>>,
    tree: Tree16,
    shader: shader::Shader,
    leaves: u64,
}

impl Case {
    /// Swaps the full hierarchy and its caster in or out; false if the device can't hold it.
    fn swap_full(&mut self, gpu: &Gpu) -> bool {
        let full = self.full.get_or_insert_with(|| {
            let mut h = Hierarchy::from_tree_at(&self.tree, u32::MAX);
            h.bound_slopes(&self.formula, &self.params);
            RayCaster::new(gpu, &self.shader, &h).ok().map(|c| (h, c))
        });
        match full {
            Some((h, c)) => {
                std::mem::swap(&mut self.hierarchy, h);
                std::mem::swap(&mut self.caster, c);
                true
            }
            None => false,
        }
    }
}

fn prepare(gpu: &Gpu, name: &str, level: u32) -> Case {
    // An example's name, or the path of a scene file.
    let scene = if name.ends_with(".toml") {
        Scene::load(std::path::Path::new(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
    } else {
        Scene::example(name).unwrap_or_else(|| panic!("no example scene named {name}"))
    };
    let formula = CompiledFormula::compile(&scene.formula).unwrap();
    let uniform = BuildSettings {
        max_level: level,
        min_level: level,
        node_budget: 50_000_000,
    };
    let Prepared {
        params,
        tree,
        hierarchy,
        ..
    } = Prepared::build(&formula, &scene, uniform, &AtomicBool::new(false), None).unwrap();
    // FOURFOLD_BENCH_MARCH_UP: march every box that many levels above the finest instead
    // of the default cut.
    let hierarchy = match std::env::var("FOURFOLD_BENCH_MARCH_UP") {
        Ok(up) => {
            let up: u32 = up
                .parse()
                .expect("FOURFOLD_BENCH_MARCH_UP: a number of levels");
            let level = tree.levels.len().saturating_sub(1 + up as usize) as u32;
            let mut h = Hierarchy::from_tree_at(&tree, level);
            h.bound_slopes(&formula, &params);
            h
        }
        Err(_) => hierarchy,
    };
    let shader = shader::generate(&formula).unwrap();
    let caster = RayCaster::new(gpu, &shader, &hierarchy).unwrap();
    Case {
        scene,
        formula,
        params,
        hierarchy,
        caster,
        full: None,
        leaves: tree.stats.leaves,
        tree,
        shader,
    }
}

/// How a frame finds its leaves.
#[derive(Clone, Copy, PartialEq)]
enum Method {
    /// Per-tile lists of the boxes to march, binned on the CPU (the default; binning time
    /// included).
    Tiles,
    /// The same without the slope and curvature bounds: every sample of the march taken.
    Unskipped,
    /// The same as Tiles, marching the finest leaves themselves.
    Leaves,
    /// Each pixel walks the sphere hierarchy.
    Walk,
    /// No hierarchy: every ray marched across the domain (steps of the level's leaves).
    Brute(u32),
}

/// A frame's best times in ms over the runs.
#[derive(Clone, Copy)]
struct Timing {
    /// Wall clock: CPU binning, upload, the pass and reading the picture back.
    total: f64,
    /// The CPU binning's share of `total` (in the run whose total was best).
    binning: f64,
    /// The GPU's pass alone, from timestamps (NaN where the device has none).
    pass: f64,
}

impl Timing {
    const NONE: Timing = Timing {
        total: f64::NAN,
        binning: 0.0,
        pass: f64::NAN,
    };
}

/// The best times of a frame and its picture.
fn frame(gpu: &Gpu, p: &mut Case, size: u32, rays: u32, method: Method) -> (Timing, Vec<u8>) {
    if method == Method::Unskipped {
        // No bounds in the caster's node buffers (binding 4, which the records point to).
        let slopes = std::mem::take(&mut p.hierarchy.slopes);
        let curvature = std::mem::take(&mut p.hierarchy.curvature);
        p.caster.set_hierarchy(gpu, &p.hierarchy).unwrap();
        let out = frame_at(gpu, p, size, rays, method);
        p.hierarchy.slopes = slopes;
        p.hierarchy.curvature = curvature;
        p.caster.set_hierarchy(gpu, &p.hierarchy).unwrap();
        return out;
    }
    if method != Method::Leaves {
        return frame_at(gpu, p, size, rays, method);
    }
    if !p.swap_full(gpu) {
        return (Timing::NONE, Vec::new());
    }
    let out = frame_at(gpu, p, size, rays, method);
    p.swap_full(gpu);
    out
}

fn frame_at(gpu: &Gpu, p: &mut Case, size: u32, rays: u32, method: Method) -> (Timing, Vec<u8>) {
    let brute = match method {
        Method::Brute(level) => Some(level),
        _ => None,
    };
    let tiled = matches!(method, Method::Tiles | Method::Unskipped | Method::Leaves);
    let mut render = p.scene.render;
    // The plain pencil: this bench is the hierarchy against brute force, not certification
    // (the default since 5f47b8f, which `cargo bench --bench certified` measures).
    render.certified = false;
    render.rays = rays;
    render.bisection_iters = env_u32("FOURFOLD_BENCH_ITERS", render.bisection_iters);
    render.steps = env_u32("FOURFOLD_BENCH_STEPS", render.steps);
    let camera = Camera::new(&p.scene.domain, &p.scene.view, size, size);
    let uniforms = Uniforms::new(
        &camera,
        &render,
        &p.scene.domain,
        &p.hierarchy,
        &p.params,
        FrameOptions {
            frame: 0,
            brute_force_level: brute,
            ..FrameOptions::default()
        },
    );
    let runs = env_u32("FOURFOLD_BENCH_RUNS", 2).max(1);
    // Warm-up in the same mode, one frame and at least 200 ms: llvmpipe compiles a pipeline
    // at its first draw, and a GPU left idle (during a tree build) runs at low clocks for a
    // while (on the H100, the first frames after the level-7 tree took 3x their time).
    let lists = tiled.then(|| TileLists::build(&p.hierarchy, &camera));
    p.caster.set_tiles(gpu, lists.as_ref());
    let warm = Instant::now();
    let mut rgba = p.caster.render_rgba(gpu, &uniforms).unwrap();
    while warm.elapsed().as_secs_f64() < 0.2 {
        rgba = p.caster.render_rgba(gpu, &uniforms).unwrap();
    }
    let mut best = Timing {
        total: f64::INFINITY,
        binning: 0.0,
        pass: f64::INFINITY,
    };
    for _ in 0..runs {
        let t = Instant::now();
        if tiled {
            let lists = TileLists::build(&p.hierarchy, &camera);
            p.caster.set_tiles(gpu, Some(&lists));
        }
        let binned = if tiled {
            t.elapsed().as_secs_f64() * 1e3
        } else {
            0.0
        };
        let pass;
        (rgba, pass) = p.caster.render_rgba_timed(gpu, &uniforms).unwrap();
        let total = t.elapsed().as_secs_f64() * 1e3;
        if total < best.total {
            (best.total, best.binning) = (total, binned);
        }
        best.pass = best.pass.min(pass.unwrap_or(f64::NAN));
    }
    (best, rgba)
}

/// A table cell of milliseconds: the frame, the binning in round brackets where there is
/// one, the GPU's pass in square ones where timed; a dash for a column left out (NaN).
/// Whole milliseconds from 100 on, tenths below.
fn ms(t: Timing) -> String {
    let num = |v: f64| {
        if v < 100.0 {
            format!("{v:.1}")
        } else {
            format!("{v:.0}")
        }
    };
    if t.total.is_nan() {
        return "–".to_string();
    }
    let mut cell = num(t.total);
    if t.binning > 0.0 {
        cell += &format!(" ({})", num(t.binning));
    }
    if !t.pass.is_nan() {
        cell += &format!(" [{}]", num(t.pass));
    }
    cell
}

/// A table cell of a ratio; a dash where a column was left out (NaN).
fn ratio(v: f64) -> String {
    if v.is_nan() {
        "–".to_string()
    } else {
        format!("{v:.1}x")
    }
}

/// Pixels the driver cut short (alpha 254, see templates/raycast.wgsl).
fn cut(rgba: &[u8]) -> usize {
    rgba.chunks(4).filter(|p| p[3] != 255).count()
}

/// Share of pixels whose colours agree within 16/255 per channel, and of pixels whose
/// coverage (differs from the background) agrees.
fn agreement(a: &[u8], b: &[u8], background: [u8; 3]) -> (f64, f64) {
    let n = a.len() / 4;
    let (mut colour, mut cover) = (0, 0);
    for (pa, pb) in a.chunks(4).zip(b.chunks(4)) {
        if pa.iter().zip(pb).take(3).all(|(x, y)| x.abs_diff(*y) <= 16) {
            colour += 1;
        }
        let bg = |p: &[u8]| p[..3] == background;
        if bg(pa) == bg(pb) {
            cover += 1;
        }
    }
    (colour as f64 / n as f64, cover as f64 / n as f64)
}

fn main() {
    let gpu = common::gpu_or_exit();
    let size = env_u32("FOURFOLD_BENCH_SIZE", 512);
    let levels = env_list("FOURFOLD_BENCH_LEVELS", "5,6,7");
    let ray_counts = env_list("FOURFOLD_BENCH_RAYS", "8,16,32");
    println!("adapter: {}", gpu.adapter);
    println!("\n## Hierarchy vs brute force, {size}x{size}\n");
    println!(
        "| scene | level | leaves | boxes marched | rays | tiles ms (CPU binning) [GPU pass] | no skip ms | leaves ms (CPU binning) | walk ms | brute force ms [GPU pass] | brute/tiles | brute/tiles, GPU passes | no skip/tiles | brute/leaves | leaves/tiles | brute/walk | same colour | same coverage | same as no skip | pixels cut (tiles/walk/brute) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    // The walk (the fallback when tile lists exceed the device's buffer limit) is slow on a
    // software GPU; FOURFOLD_BENCH_WALK=1 includes it.
    let with_walk = std::env::var("FOURFOLD_BENCH_WALK").is_ok_and(|v| v == "1");
    // Marching the leaves themselves bins millions of them per frame at level 7;
    // FOURFOLD_BENCH_LEAVES=0 leaves that column out.
    let with_leaves = std::env::var("FOURFOLD_BENCH_LEAVES").map_or(true, |v| v != "0");
    let scenes =
        std::env::var("FOURFOLD_BENCH_SCENES").unwrap_or_else(|_| "fig-3-9-left,glome".to_string());
    for name in scenes.split(',').map(str::trim) {
        for &level in &levels {
            let mut p = prepare(&gpu, name, level);
            let background = p.scene.render.background.0;
            for &rays in &ray_counts {
                let (tiles, a) = frame(&gpu, &mut p, size, rays, Method::Tiles);
                let (unskipped, u) = frame(&gpu, &mut p, size, rays, Method::Unskipped);
                let (leaves, _) = if with_leaves {
                    frame(&gpu, &mut p, size, rays, Method::Leaves)
                } else {
                    (Timing::NONE, Vec::new())
                };
                let (walk, w) = if with_walk {
                    frame(&gpu, &mut p, size, rays, Method::Walk)
                } else {
                    (Timing::NONE, Vec::new())
                };
                let (slow, b) = frame(&gpu, &mut p, size, rays, Method::Brute(level));
                let (colour, cover) = agreement(&a, &b, background);
                let same = a.chunks(4).zip(u.chunks(4)).filter(|(x, y)| x == y).count();
                println!(
                    "| {name} | {level} | {} | {} | {rays} | {} | {:.0} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1}% | {:.1}% | {:.2}% | {} / {} / {} |",
                    p.leaves,
                    p.hierarchy.march_boxes(),
                    ms(tiles),
                    unskipped.total,
                    ms(leaves),
                    ms(walk),
                    ms(slow),
                    ratio(slow.total / tiles.total),
                    ratio(slow.pass / tiles.pass),
                    ratio(unskipped.total / tiles.total),
                    ratio(slow.total / leaves.total),
                    ratio(leaves.total / tiles.total),
                    ratio(slow.total / walk.total),
                    100.0 * colour,
                    100.0 * cover,
                    100.0 * same as f64 / (a.len() / 4) as f64,
                    cut(&a),
                    cut(&w),
                    cut(&b)
                );
            }
        }
    }
    if std::env::var("FOURFOLD_BENCH_QUICK").is_ok() {
        return;
    }
    println!("\n## Growth of the hierarchy frame time (glome, uniform trees)\n");
    println!("| pixels | rays | level | ms (CPU binning) [GPU pass] | ms per megaray |");
    println!("|---|---|---|---|---|");
    let mut base = prepare(&gpu, "glome", 6);
    let row = |p: &mut Case, px: u32, rays: u32, level: u32| {
        let (t, _) = frame(&gpu, p, px, rays, Method::Tiles);
        let megarays = f64::from(px * px) * f64::from(rays) / 1e6;
        println!(
            "| {px}² | {rays} | {level} | {} | {:.1} |",
            ms(t),
            t.total / megarays
        );
    };
    for px in [128, 256, 512] {
        row(&mut base, px, 16, 6);
    }
    for rays in [4, 8, 16, 32] {
        row(&mut base, 256, rays, 6);
    }
    for level in [4, 5, 6, 7] {
        let mut p = prepare(&gpu, "glome", level);
        row(&mut p, 256, 16, level);
    }
    println!("\n## Frame time by march level (256², 16 rays, uniform level-6 trees)\n");
    println!(
        "| scene | levels above the finest | boxes marched | ms (CPU binning) [GPU pass] | brute force ms [GPU pass] |"
    );
    println!("|---|---|---|---|---|");
    for name in ["fig-3-9-left", "glome"] {
        let mut p = prepare(&gpu, name, 6);
        let brute = ms(frame(&gpu, &mut p, 256, 16, Method::Brute(6)).0);
        for up in 0..=6 {
            // Its own node buffers: the box records point into them for the bounds.
            p.hierarchy = Hierarchy::from_tree_at(&p.tree, 6 - up);
            p.hierarchy.bound_slopes(&p.formula, &p.params);
            let boxes = p.hierarchy.march_boxes();
            if let Err(e) = p.caster.set_hierarchy(&gpu, &p.hierarchy) {
                println!("| {name} | {up} | {boxes} | – ({e}) | {brute} |");
                continue;
            }
            let (t, _) = frame_at(&gpu, &mut p, 256, 16, Method::Tiles);
            println!("| {name} | {up} | {boxes} | {} | {brute} |", ms(t));
        }
        p.hierarchy = Hierarchy::for_formula(&p.tree, &p.formula, &p.params);
        p.caster.set_hierarchy(&gpu, &p.hierarchy).unwrap();
        let (t, _) = frame_at(&gpu, &mut p, 256, 16, Method::Tiles);
        println!(
            "| {name} | the default cut (coarser where the bounds allow) | {} | {} | {brute} |",
            p.hierarchy.march_boxes(),
            ms(t)
        );
    }
}
