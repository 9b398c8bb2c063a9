//! fourfold against the best CPU renderer of implicit surfaces on the same cores:
//! `cargo bench -p fourfold-cli --bench peer`.
//!
//! A slice of M is a 3D implicit surface, so it is the same work as fidget's
//! `raster::voxel::render` of a SIZE³ grid (JIT, interval subdivision and tape simplification,
//! all cores). For four surfaces (a sphere, the chapter's torus graph at w = 5, a sextic, a
//! trigonometric lattice), seen along z with the slice at w = C, in one run:
//! 1. in process: fidget's render (its JIT compiled beforehand) against fourfold's plain frame
//!    (binning, pass, read-back) and the GPU's pass alone (timestamps), best of RUNS after a
//!    warm-up; and whether the two pictures cover the same pixels;
//! 2. whole processes, as a user runs them: `fourfold render SCENE --slice C` (certified,
//!    on the device `render` chooses: the CPU twin for a slice this size on most machines)
//!    against this bench re-run as a program that JIT-compiles, renders with fidget and
//!    writes a PNG, the two taken in turn, the median of RUNS of each; the same on the GPU
//!    (`--gpu`), its first run with an empty pipeline cache (cold), then the median of RUNS
//!    (warm); and the median of RUNS with `--uncertified` (fidget proves nothing either) on
//!    the GPU and on the CPU twin.
//!
//! fidget sees F(p) over the picture's box, p the point of the slice that the pixel and the
//! depth stand for, intersected with the scene's domain (fourfold marches only within it).
//! Environment: `FOURFOLD_BENCH_SIZE` (default 512), `FOURFOLD_BENCH_RUNS` (default 5),
//! `FOURFOLD_BIN` (the `fourfold` program to time, where cargo's build is not at hand).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use fidget::context::{Context, Node as FNode};
use fidget::jit::JitShape;
use fidget::raster::voxel::{self, RenderConfig};
use fidget::render::VoxelSize;
use fourfold::CompiledFormula;
use fourfold::render::view::Camera;
use fourfold::render::{Gpu, Prepared, RayCaster, Target, shader};
use fourfold::scene::Scene;

// The benchmarks' shared helpers, kept once beside the core's benchmarks.
#[path = "../../fourfold/benches/common/mod.rs"]
mod common;
#[path = "../../fourfold/benches/common/fidget_graph.rs"]
mod fidget_graph;

use common::{env_u32, gpu_or_exit};

/// A surface: its name, the scene (formula, parameters, domain) and the slice's offset
/// along n2 (w here: the view's angles are zero). Each formula is negative inside, as
/// fidget's solids are.
struct Surface {
    name: &'static str,
    scene: &'static str,
    slice: f64,
}

const SURFACES: [Surface; 4] = [
    Surface {
        name: "sphere",
        scene: "formula = \"x^2 + y^2 + z^2 + w^2 - 1\"\n[domain]\nx = [-1.5, 1.5]\ny = [-1.5, 1.5]\nz = [-1.5, 1.5]\nw = [-1.5, 1.5]\n",
        slice: 0.3,
    },
    Surface {
        name: "torus graph",
        scene: "formula = \"(x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4R^2(x^2 + y^2) - w\"\n[params]\nR = 2.0\nr = 1.0\n[domain]\nx = [-3.5, 3.5]\ny = [-3.5, 3.5]\nz = [-3.5, 3.5]\nw = [-6.0, 6.0]\n",
        slice: 5.0,
    },
    Surface {
        name: "sextic",
        scene: "formula = \"x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1\"\n[domain]\nx = [-1.3, 1.3]\ny = [-1.3, 1.3]\nz = [-1.3, 1.3]\nw = [-1.3, 1.3]\n",
        slice: 0.5,
    },
    Surface {
        name: "trig lattice",
        scene: "formula = \"cos(3x) + cos(3y) + cos(3z) + cos(3w)\"\n[domain]\nx = [-2.0, 2.0]\ny = [-2.0, 2.0]\nz = [-2.0, 2.0]\nw = [-2.0, 2.0]\n",
        slice: 0.2,
    },
];

/// The environment variable that makes this program render one surface with fidget and
/// write a PNG (the peer's whole process), and the file it writes.
const PEER_RUN: &str = "FOURFOLD_PEER_RUN";
const PEER_OUT: &str = "FOURFOLD_PEER_OUT";

fn scene_of(surface: &Surface) -> Scene {
    let mut scene = Scene::parse(surface.scene, surface.name).expect("the bench's scenes parse");
    scene.view.angles = [0.0; 6];
    scene.view.slice = Some(surface.slice);
    scene
}

/// fidget's shape for the slice of `scene` as a `size`² picture sees it: its x, y, z are
/// the picture's [-1, 1]² (pixel centres as fourfold's) and the depth along n1.
fn fidget_shape(scene: &Scene, size: u32) -> Result<JitShape, String> {
    let formula = CompiledFormula::compile(&scene.formula).map_err(|e| e.to_string())?;
    let camera = Camera::new(&scene.domain, &scene.view, size, size);
    let offset = scene.view.slice.unwrap_or(0.0);
    // fidget's pixel i is at x = (i − size/2)·2/size, fourfold's at (i + ½ − size/2)·s.
    let half = camera.pixel_size * f64::from(size) / 2.0;
    let shift = 1.0 / f64::from(size);
    let mut ctx = Context::new();
    let (x, y, z) = (ctx.x(), ctx.y(), ctx.z());
    let mut axes = Vec::new();
    for k in 0..4 {
        let mut sum = ctx.constant((camera.center[k] + offset * camera.n2[k]) as f32);
        let terms = [
            (x, camera.v1[k], shift),
            (y, camera.v2[k], shift),
            (z, camera.n1[k], 0.0),
        ];
        for (var, along, by) in terms {
            if along != 0.0 {
                let moved = ctx.add(var, by as f32).map_err(|e| e.to_string())?;
                let scaled = ctx
                    .mul(moved, (half * along) as f32)
                    .map_err(|e| e.to_string())?;
                sum = ctx.add(sum, scaled).map_err(|e| e.to_string())?;
            }
        }
        axes.push(sum);
    }
    let axes: [FNode; 4] = axes.try_into().expect("four axes");
    let params = scene.param_values(&formula.param_names());
    let f = fidget_graph::translate(&mut ctx, &formula, &params, &[formula.f], axes)?[0];
    // Intersected with the domain: max(F, max_k |p_k − c_k| − h_k).
    let mut clipped = f;
    for (k, range) in scene.domain.axes().iter().enumerate() {
        let (c, h) = ((range.lo + range.hi) / 2.0, (range.hi - range.lo) / 2.0);
        let d = ctx.sub(axes[k], c as f32).map_err(|e| e.to_string())?;
        let a = ctx.abs(d).map_err(|e| e.to_string())?;
        let wall = ctx.sub(a, h as f32).map_err(|e| e.to_string())?;
        clipped = ctx.max(clipped, wall).map_err(|e| e.to_string())?;
    }
    JitShape::new(&ctx, clipped).map_err(|e| e.to_string())
}

fn fidget_render(shape: &JitShape, size: u32) -> voxel::Image {
    let config = RenderConfig::from_size(VoxelSize::new(size, size, size));
    let bound = shape.clone().try_into().expect("no free variables");
    voxel::render(bound, &config, &Default::default()).expect("not cancelled")
}

fn fidget_coverage(image: &voxel::Image) -> Vec<bool> {
    image.iter().map(|p| p.depth > 0).collect()
}

/// The peer's whole process: JIT-compile, render, write a PNG of the normals.
fn peer_process(index: usize, size: u32, out: &Path) {
    let scene = scene_of(&SURFACES[index]);
    let shape = fidget_shape(&scene, size).expect("the bench's formulas translate");
    let image = fidget_render(&shape, size);
    let rgb: Vec<u8> = image
        .iter()
        .flat_map(|p| if p.depth > 0 { p.to_color() } else { [0; 3] })
        .collect();
    let file = std::fs::File::create(out).expect("the peer's PNG");
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), size, size);
    encoder.set_color(png::ColorType::Rgb);
    encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(&rgb))
        .expect("the peer's PNG");
}

/// fourfold's frame by the wall clock and its GPU pass (best of `runs` after a warm-up),
/// and the pixels it covers.
fn fourfold_frame(gpu: &Gpu, scene: &Scene, size: u32, runs: u32) -> (f64, f64, Vec<bool>) {
    let mut scene = scene.clone();
    scene.render.background = fourfold::scene::Color([255, 0, 255]);
    // The plain pencil, as fidget proves nothing (the frame is binned without the
    // certifying lists a certified one searches).
    scene.render.certified = false;
    let formula = CompiledFormula::compile(&scene.formula).expect("the bench's formulas compile");
    let prepared = Prepared::new(&formula, &scene).expect("the tree builds");
    let shader = shader::generate(&formula).expect("the shader validates");
    let mut caster =
        RayCaster::for_scene(gpu, &shader, &prepared.hierarchy, Target::OFFSCREEN, &scene)
            .expect("pipeline");
    let (camera, uniforms) = prepared.frame(&scene, size, size, Default::default());
    let (mut best, mut best_pass, mut covered) = (f64::INFINITY, f64::INFINITY, Vec::new());
    for run in 0..=runs {
        let t = Instant::now();
        caster.bin_view(gpu, &prepared.hierarchy, None, &camera, &uniforms);
        let (rgba, pass) = caster.render_rgba_timed(gpu, &uniforms).expect("frame");
        let ms = t.elapsed().as_secs_f64() * 1e3;
        if run > 0 {
            best = best.min(ms);
            best_pass = best_pass.min(pass.unwrap_or(f64::NAN));
        }
        covered = rgba
            .chunks_exact(4)
            .map(|p| p[..3] != [255, 0, 255])
            .collect();
    }
    (best, best_pass, covered)
}

/// The `fourfold` program: cargo's build of it, or FOURFOLD_BIN (the bench run elsewhere).
fn fourfold_binary() -> PathBuf {
    std::env::var_os("FOURFOLD_BIN")
        .map_or_else(|| env!("CARGO_BIN_EXE_fourfold").into(), PathBuf::from)
}

fn best_ms(runs: u32, mut work: impl FnMut()) -> f64 {
    work();
    (0..runs)
        .map(|_| {
            let t = Instant::now();
            work();
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A whole process: its wall time, and what it printed of the adapter that drew and of
/// its stages (empty where it printed none).
#[derive(Default, Clone)]
struct Process {
    ms: f64,
    adapter: String,
    stages: String,
}

fn process_ms(command: &mut Command) -> Process {
    let t = Instant::now();
    let output = command.output().expect("the process starts");
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let text = String::from_utf8_lossy(&output.stderr).to_string()
        + &String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{command:?} failed:\n{text}");
    let line = |start: &str| {
        text.lines()
            .rfind(|l| l.starts_with(start))
            .map(|l| l.trim_start_matches(start).to_string())
            .unwrap_or_default()
    };
    Process {
        ms,
        adapter: line("adapter: "),
        stages: line("times (ms): "),
    }
}

struct Row {
    name: &'static str,
    peer: f64,
    frame: f64,
    pass: f64,
    coverage: (usize, usize, usize),
    peer_process: f64,
    /// `render`'s own choice of device, and the adapter it names.
    default: f64,
    default_adapter: String,
    cold: f64,
    warm: f64,
    warm_stages: String,
    plain: f64,
    cpu: f64,
}

fn measure(gpu: &Gpu, index: usize, size: u32, runs: u32, work: &Path) -> Row {
    let surface = &SURFACES[index];
    let scene = scene_of(surface);
    let shape = fidget_shape(&scene, size).expect("the bench's formulas translate");
    let mut image = None;
    let peer = best_ms(runs, || image = Some(fidget_render(&shape, size)));
    let theirs = fidget_coverage(&image.expect("rendered"));
    let (frame, pass, ours) = fourfold_frame(gpu, &scene, size, runs);
    let differ = ours.iter().zip(&theirs).filter(|(a, b)| a != b).count();
    let count = |v: &[bool]| v.iter().filter(|&&c| c).count();

    let scene_file = work.join(format!("surface-{index}.toml"));
    std::fs::write(&scene_file, surface.scene).expect("the scene file");
    let cache = work.join(format!("cache-{index}"));
    let _ = std::fs::remove_dir_all(&cache);
    let fourfold = |extra: &[&str]| {
        let mut c = Command::new(fourfold_binary());
        c.arg("render")
            .arg(&scene_file)
            .args([
                "--angles",
                "0,0,0,0,0,0",
                "--slice",
                &surface.slice.to_string(),
            ])
            .args(["--size", &format!("{size}x{size}")])
            .args(extra)
            .arg("-o")
            .arg(work.join("fourfold.png"))
            .env("FOURFOLD_CACHE_DIR", &cache);
        c
    };
    // The median of RUNS processes' times, and the last one.
    let median_of = |extra: &[&str]| {
        let runs: Vec<Process> = (0..runs)
            .map(|_| process_ms(&mut fourfold(extra)))
            .collect();
        let last = runs.last().cloned().unwrap_or_default();
        (median(runs.into_iter().map(|r| r.ms).collect()), last)
    };
    // (The GPU's first run before any other: its pipeline cache is still empty.)
    let cold = process_ms(&mut fourfold(&["--gpu"])).ms;
    // fourfold's default render and fidget's process taken in turn, so that both meet the
    // same moments of a noisy machine.
    let this = std::env::current_exe().expect("the bench's own path");
    let fidget = || {
        let mut c = Command::new(&this);
        c.env(PEER_RUN, index.to_string())
            .env(PEER_OUT, work.join("fidget.png"));
        c
    };
    let (mut mine, mut peers, mut chosen) = (Vec::new(), Vec::new(), Process::default());
    for _ in 0..runs {
        chosen = process_ms(&mut fourfold(&[]));
        mine.push(chosen.ms);
        peers.push(process_ms(&mut fidget()).ms);
    }
    let (default, peer_process) = (median(mine), median(peers));
    let (warm, on_gpu) = median_of(&["--gpu"]);
    let (plain, _) = median_of(&["--uncertified", "--gpu"]);
    let (cpu, _) = median_of(&["--uncertified", "--cpu"]);
    Row {
        name: surface.name,
        peer,
        frame,
        pass,
        coverage: (count(&ours), count(&theirs), differ),
        peer_process,
        default,
        default_adapter: chosen.adapter,
        cold,
        warm,
        warm_stages: on_gpu.stages,
        plain,
        cpu,
    }
}

fn main() {
    let size = env_u32("FOURFOLD_BENCH_SIZE", 512);
    if let Ok(index) = std::env::var(PEER_RUN) {
        let out = PathBuf::from(std::env::var(PEER_OUT).expect("FOURFOLD_PEER_OUT"));
        peer_process(index.parse().expect("a surface's index"), size, &out);
        return;
    }
    // `cargo bench` passes --bench; a filter (any other argument) picks surfaces by name.
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let runs = env_u32("FOURFOLD_BENCH_RUNS", 5).max(1);
    let gpu = gpu_or_exit();
    let work = std::env::temp_dir().join(format!("fourfold-peer-{}", std::process::id()));
    std::fs::create_dir_all(&work).expect("a work folder");
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "fidget {}³ voxels (JIT, {threads} threads) against fourfold render --slice at {size}², on {}; best of {runs} in process, median of {runs} processes",
        size, gpu.adapter
    );
    println!(
        "\n| surface | fidget ms | fourfold frame ms [GPU pass] | pass/fidget | frame/fidget | covered: fourfold / fidget (differ) |"
    );
    println!("|---|---|---|---|---|---|");
    let mut rows = Vec::new();
    for index in 0..SURFACES.len() {
        if !filter.is_empty()
            && !filter
                .iter()
                .any(|f| SURFACES[index].name.contains(f.as_str()))
        {
            continue;
        }
        let r = measure(&gpu, index, size, runs, &work);
        println!(
            "| {} | {:.1} | {:.1} [{:.1}] | {:.2}x | {:.2}x | {} / {} ({}) |",
            r.name,
            r.peer,
            r.frame,
            r.pass,
            r.pass / r.peer,
            r.frame / r.peer,
            r.coverage.0,
            r.coverage.1,
            r.coverage.2
        );
        rows.push(r);
    }
    println!(
        "\n| surface | fidget process ms | fourfold process ms (certified; drawn by) | fourfold/fidget | on the GPU (--gpu), cold / warm | warm/fidget | plain (--uncertified) on the GPU, on the CPU twin, ms | plain/fidget, GPU and CPU | fourfold's stages (--gpu, warm) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!(
            "| {} | {:.0} | {:.0} ({}) | {:.2}x | {:.0} / {:.0} | {:.2}x | {:.0}, {:.0} | {:.2}x, {:.2}x | {} |",
            r.name,
            r.peer_process,
            r.default,
            r.default_adapter,
            r.default / r.peer_process,
            r.cold,
            r.warm,
            r.warm / r.peer_process,
            r.plain,
            r.cpu,
            r.plain / r.peer_process,
            r.cpu / r.peer_process,
            r.warm_stages
        );
    }
    let _ = std::fs::remove_dir_all(&work);
}
