//! An edit through the viewer's session, as typing makes it: `cargo bench -p fourfold-viewer
//! --bench edit_session`.
//!
//! For each preset of FOURFOLD_BENCH_SCENES (default the glome, the chapter's scene and the
//! tiger), certified (the default) and plain, three edits that each add a term of a new
//! shape to the formula (`+ 0.001 x^k`, a new k each time, so each makes a new shader and
//! ray caster), on the first adapter wgpu finds, with the first frames drawn by the
//! interpreting shader (built once, before the edits) and by the formula's own; and three
//! edits that change only that term's number (the same shader: the caster on screen draws
//! it, "numbers only"): from the changed text to the new tree and caster being ready for the
//! first preview (`EditTimes::ready_ms`, of which the caster's pipeline and its warm-up),
//! one preview-sized frame drawn with that caster, and the time until the formula's own
//! pipelines are there too (built beside the window after the caster: the settled picture's
//! certified one, and where the caster interprets its plain one), and for a certified scene
//! one certified frame of that size then (what the settled picture's first pass costs, a
//! driver's code generation included where the warm-up left it). Each edit waits for the one
//! before to finish entirely, so that no compile of one slows the next.

// The benchmarks' shared helpers, kept once beside the core's benchmarks.
#[path = "../../fourfold/benches/common/mod.rs"]
mod common;

use std::time::{Duration, Instant};

use fourfold::render::{Camera, FrameOptions, Gpu, Uniforms};
use fourfold::scene::{EXAMPLES, Scene};
use fourfold_viewer::Session;

/// The preview-sized frame: a quarter of a 960×720 picture's side.
const PREVIEW: [u32; 2] = [240, 180];

fn main() {
    let mut gpu = common::gpu_or_exit();
    // No pipelines kept between runs: an edit makes a shader no run compiled before.
    gpu.pipeline_cache = None;
    println!("adapter: {}", gpu.adapter);
    let names = std::env::var("FOURFOLD_BENCH_SCENES")
        .unwrap_or_else(|_| "glome,fig-3-9-left,tiger".into());
    println!(
        "\n| preset | certified | first frames by | edit → ready for the preview, ms (of which pipeline, of that its warm-up draw) | a {w}×{h} frame with that caster, ms | edit → own pipelines ready, ms | then a certified {w}×{h} frame, ms |",
        w = PREVIEW[0],
        h = PREVIEW[1]
    );
    println!("|---|---|---|---|---|---|---|");
    let mut constant = 0;
    for name in names.split(',').map(str::trim) {
        let Some((_, text)) = EXAMPLES.iter().find(|(n, _)| *n == name) else {
            eprintln!("no example {name}");
            std::process::exit(1);
        };
        for certified in [true, false] {
            for (interpreted, numbers_only) in [(true, false), (false, false), (false, true)] {
                let mut scene = Scene::parse(text, name).expect("examples parse");
                scene.render.certified = certified;
                let formula = scene.formula.clone();
                let mut session = Session::new(scene);
                session.interpret_new_formulas(interpreted);
                // (With numbers only, the term is there before the edits change its number.)
                let first = if numbers_only {
                    constant += 1;
                    format!("{formula} + 0.009 x^{}", constant + 1)
                } else {
                    formula.clone()
                };
                session.set_text(&first, Some(&gpu));
                settle(&mut session, &gpu);
                session.wait_for_interpreter(Some(&gpu));
                let pipelines = session.counters.pipelines;
                let (mut ready, mut frames, mut settled) = (Vec::new(), Vec::new(), Vec::new());
                let mut proved = Vec::new();
                for edit in 1..=3 {
                    // A shape no edit before had (the driver may keep the pipelines of a
                    // shader it compiled in this process), or the same with a new number.
                    if !numbers_only {
                        constant += 1;
                    }
                    let text = format!("{formula} + 0.00{edit} x^{}", constant + 1);
                    let started = Instant::now();
                    session.set_text(&text, Some(&gpu));
                    session.wait(Some(&gpu));
                    let t = session.times;
                    assert_eq!(session.interpreting(), interpreted, "{name}");
                    let made = session.counters.pipelines - pipelines;
                    assert_eq!(made, if numbers_only { 0 } else { edit }, "{name}");
                    ready.push(format!(
                        "{:.0} ({:.0}, {:.0})",
                        t.ready_ms, t.pipeline_ms, t.warm_up_ms
                    ));
                    frames.push(format!("{:.0}", frame_ms(&mut session, &gpu, false)));
                    settle(&mut session, &gpu);
                    settled.push(format!("{:.0}", started.elapsed().as_secs_f64() * 1e3));
                    if certified {
                        proved.push(format!("{:.0}", frame_ms(&mut session, &gpu, true)));
                    }
                }
                let by = match (interpreted, numbers_only) {
                    (true, _) => "interpreter",
                    (false, false) => "own shader",
                    (false, true) => "numbers only (the same shader)",
                };
                // (A plain scene drawn by its own shader builds nothing beside the window.)
                let settled = cell(&settled, (certified && !numbers_only) || interpreted);
                println!(
                    "| {name} | {certified} | {by} | {} | {} | {settled} | {} |",
                    ready.join(", "),
                    frames.join(", "),
                    cell(&proved, certified)
                );
            }
        }
    }
}

/// A table cell: the times, where they were taken, else "-".
fn cell(times: &[String], taken: bool) -> String {
    if taken { times.join(", ") } else { "-".into() }
}

/// Draws one preview-sized frame of the session's scene with its caster as it is, plain or
/// certified, and waits for it: its milliseconds.
fn frame_ms(session: &mut Session, gpu: &Gpu, certified: bool) -> f64 {
    let scene = &session.scene;
    let hierarchy = session.hierarchy.clone().expect("a tree");
    let camera = Camera::new(&scene.domain, &scene.view, PREVIEW[0], PREVIEW[1]);
    let mut render = scene.render;
    render.certified = certified;
    let (domain, params) = (&scene.domain, &session.tree_params);
    let options = FrameOptions::default();
    let uniforms = Uniforms::new(&camera, &render, domain, &hierarchy, params, options);
    let caster = session.caster.as_mut().expect("a caster");
    let started = Instant::now();
    let certifying = session.certifying.clone();
    caster.bin_view(gpu, &hierarchy, certifying.as_deref(), &camera, &uniforms);
    caster.render_rgba(gpu, &uniforms).expect("a frame");
    started.elapsed().as_secs_f64() * 1e3
}

/// Polls the session until its build and the own pipelines that follow it are done.
fn settle(session: &mut Session, gpu: &Gpu) {
    let deadline = Instant::now() + Duration::from_secs(120);
    session.wait(Some(gpu));
    while session.certified_pipeline_pending() {
        session.poll(Some(gpu));
        assert!(Instant::now() < deadline, "no own pipelines in 120 s");
        std::thread::sleep(Duration::from_millis(1));
    }
    if let Some(error) = &session.error {
        eprintln!("{error}");
        std::process::exit(1);
    }
}
