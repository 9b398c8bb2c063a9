//! An edit through the viewer's session, as typing makes it: `cargo bench -p fourfold-viewer
//! --bench edit_session`.
//!
//! For each preset of FOURFOLD_BENCH_SCENES (default the glome, the chapter's scene and the
//! tiger), certified (the default) and plain, three edits that each change a constant of the
//! formula (so each makes a new shader and ray caster), on the first adapter wgpu finds:
//! from the changed text to the new tree and caster being ready for the first preview
//! (`EditTimes::ready_ms`, of which the caster's pipeline and its warm-up), and, for a
//! certified scene, to the settled picture's certified pipeline being there too (built
//! beside the window after the caster). Each edit waits for the one before to finish
//! entirely, so that no compile of one slows the next.

// The benchmarks' shared helpers, kept once beside the core's benchmarks.
#[path = "../../fourfold/benches/common/mod.rs"]
mod common;

use std::time::{Duration, Instant};

use fourfold::scene::{EXAMPLES, Scene};
use fourfold_viewer::Session;

fn main() {
    let mut gpu = common::gpu_or_exit();
    // No pipelines kept between runs: an edit makes a shader no run compiled before.
    gpu.pipeline_cache = None;
    println!("adapter: {}", gpu.adapter);
    let names = std::env::var("FOURFOLD_BENCH_SCENES")
        .unwrap_or_else(|_| "glome,fig-3-9-left,tiger".into());
    println!(
        "\n| preset | certified | edit → ready for the preview, ms (of which pipeline, of that its warm-up draw) | edit → certified pipeline ready, ms |"
    );
    println!("|---|---|---|---|");
    for name in names.split(',').map(str::trim) {
        let Some((_, text)) = EXAMPLES.iter().find(|(n, _)| *n == name) else {
            eprintln!("no example {name}");
            std::process::exit(1);
        };
        for certified in [true, false] {
            let mut scene = Scene::parse(text, name).expect("examples parse");
            scene.render.certified = certified;
            let formula = scene.formula.clone();
            let mut session = Session::new(scene);
            session.set_text(&formula, Some(&gpu));
            settle(&mut session, &gpu);
            let (mut ready, mut settled) = (Vec::new(), Vec::new());
            for k in 1..=3 {
                let started = Instant::now();
                // A constant no edit before used (the driver may keep the pipelines of a
                // shader it compiled in this process).
                let k = if certified { k } else { k + 3 };
                session.set_text(&format!("{formula} + 0.00{k}"), Some(&gpu));
                session.wait(Some(&gpu));
                let t = session.times;
                ready.push(format!(
                    "{:.0} ({:.0}, {:.0})",
                    t.ready_ms, t.pipeline_ms, t.warm_up_ms
                ));
                settle(&mut session, &gpu);
                settled.push(format!("{:.0}", started.elapsed().as_secs_f64() * 1e3));
            }
            let settled = if certified {
                settled.join(", ")
            } else {
                "-".into()
            };
            println!(
                "| {name} | {certified} | {} | {settled} |",
                ready.join(", ")
            );
        }
    }
}

/// Polls the session until its build and the certified pipeline that follows it are done.
fn settle(session: &mut Session, gpu: &fourfold::render::Gpu) {
    let deadline = Instant::now() + Duration::from_secs(120);
    session.wait(Some(gpu));
    while session.certified_pipeline_pending() {
        session.poll(Some(gpu));
        assert!(Instant::now() < deadline, "no certified pipeline in 120 s");
        std::thread::sleep(Duration::from_millis(1));
    }
    if let Some(error) = &session.error {
        eprintln!("{error}");
        std::process::exit(1);
    }
}
