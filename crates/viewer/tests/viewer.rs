//! The viewer driven as a person drives it (egui_kittest on the real app and the real GPU
//! path, lavapipe in CI): typing a formula, a mistyped formula, a parameter slider, presets.

use std::time::{Duration, Instant};

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use fourfold::scene::{EXAMPLES, Scene};
use fourfold_viewer::FourfoldApp;

#[path = "../../fourfold/tests/support/undefined_constants.rs"]
mod support;
use support::{carets, undefined_constants};

/// A small, quick scene: the glome at a coarse level with few rays.
fn small_scene() -> Scene {
    let mut scene = Scene::from_formula("x^2 + y^2 + z^2 + w^2 = 1");
    scene.tree.max_level = 4;
    scene.tree.min_level = 0;
    scene.render.rays = 2;
    scene
}

fn harness(scene: Scene) -> Harness<'static, FourfoldApp> {
    Harness::builder()
        .wgpu()
        .with_size([900.0, 640.0])
        .build_eframe(move |cc| FourfoldApp::new(cc, Some(scene)))
}

/// Steps the UI until the build in flight is done and a picture is on screen.
fn settle(h: &mut Harness<'static, FourfoldApp>) {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        h.step();
        let app = h.state();
        let shown = !app.progressive.paint().layers.is_empty();
        if !app.session.building() && shown {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "the viewer did not settle in 120 s"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    h.step();
}

/// Settles the picture and checks that no error is shown (`what`: the case, for the message).
fn settle_without_error(h: &mut Harness<'static, FourfoldApp>, what: &str) {
    settle(h);
    let error = &h.state().session.error;
    assert!(error.is_none(), "{what}: {error:?}");
}

/// Steps the UI until the tree is built (within 60 s), and once more.
fn built(h: &mut Harness<'static, FourfoldApp>) {
    let deadline = Instant::now() + Duration::from_secs(60);
    while h.state().session.building() {
        h.step();
        assert!(Instant::now() < deadline, "the tree took over 60 s");
    }
    h.step();
}

/// Steps the UI until the picture has taken all its passes.
fn converge(h: &mut Harness<'static, FourfoldApp>) {
    let deadline = Instant::now() + Duration::from_secs(120);
    while !h.state().progressive.converged() {
        h.step();
        assert!(
            Instant::now() < deadline,
            "the picture did not converge in 120 s"
        );
    }
}

fn replace_formula(h: &mut Harness<'static, FourfoldApp>, text: &str) {
    let editor = h.get_by_label_contains("Formula");
    editor.focus();
    h.step();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.step();
    h.get_by_label_contains("Formula").type_text(text);
    h.step();
}

#[test]
fn typing_a_valid_formula_updates_the_picture() {
    let mut h = harness(small_scene());
    settle(&mut h);
    let before = h.state().session.picture_generation;
    let pipelines = h.state().session.counters.pipelines;
    assert!(h.state().session.error.is_none());

    replace_formula(&mut h, "x^2 + y^2 + z^2 + w^4 = 0.25");
    assert_eq!(h.state().session.text, "x^2 + y^2 + z^2 + w^4 = 0.25");
    assert!(
        h.state().session.error.is_none(),
        "{:?}",
        h.state().session.error
    );
    settle(&mut h);
    let app = h.state();
    assert!(app.session.picture_generation > before, "no new picture");
    assert_eq!(
        app.session.counters.pipelines,
        pipelines + 1,
        "a new formula needs a new shader"
    );
    assert_eq!(app.session.scene.formula, "x^2 + y^2 + z^2 + w^4 = 0.25");
    assert!(app.session.stats.as_ref().unwrap().leaves > 0);
    assert!(
        app.edit_latency_ms.is_some(),
        "the edit latency was not measured"
    );
}

/// A formula whose numbers alone change keeps its shader (its constants are data): the
/// picture on screen's caster draws it with no new pipeline, and on the page's path its
/// preview on the CPU holds the GPU back for no compile; its settled picture proves what
/// a caster made for it proves.
#[test]
fn a_formula_whose_numbers_alone_change_draws_without_a_new_shader() {
    let mut h = harness(small_scene());
    settle_without_error(&mut h, "the first picture");
    converge(&mut h);
    h.state_mut().session.previews_on_cpu = true;
    let counters = h.state().session.counters;
    let (generation, drawn) = (
        h.state().session.picture_generation,
        h.state().progressive.cpu_previews.drawn,
    );
    let edited = "x^2 + y^2 + z^2 + w^2 = 0.45";
    replace_formula(&mut h, edited);
    let deadline = Instant::now() + Duration::from_secs(120);
    while h.state().session.building()
        || h.state().progressive.first_frame_of != Some(h.state().session.picture_generation)
    {
        h.step();
        assert!(Instant::now() < deadline, "no first frame in 120 s");
    }
    let previews = &h.state().progressive.cpu_previews;
    assert_eq!(previews.drawn, drawn + 1, "no preview on the CPU");
    assert!(
        previews.gpu_held().is_none(),
        "the GPU waits for no compile"
    );
    settle_without_error(&mut h, edited);
    converge(&mut h);
    let app = h.state();
    assert!(
        app.session.picture_generation > generation,
        "no new picture"
    );
    assert_eq!(app.session.counters.compiles, counters.compiles + 1);
    assert_eq!(
        app.session.counters.pipelines, counters.pipelines,
        "a new shader for new numbers"
    );
    let reused = app.progressive.verdicts.expect("certified");
    // The same formula again after another shape's: a caster made for it, in this view.
    replace_formula(&mut h, "x^2 + y^2 + z^2 + w^4 = 0.45");
    settle_without_error(&mut h, "another shape");
    replace_formula(&mut h, edited);
    settle_without_error(&mut h, edited);
    converge(&mut h);
    let app = h.state();
    assert_eq!(app.session.counters.pipelines, counters.pipelines + 2);
    let fresh = app.progressive.verdicts.expect("certified");
    assert!(reused.hit > 0 && reused.empty > 0, "{reused:?}");
    assert_eq!(
        (reused.hit, reused.empty, reused.undecided),
        (fresh.hit, fresh.empty, fresh.undecided),
        "the kept caster proves otherwise"
    );
}

#[test]
fn a_mistyped_formula_shows_the_error_and_keeps_the_picture() {
    let mut h = harness(small_scene());
    settle(&mut h);
    let before = h.state().session.picture_generation;
    let formula_before = h.state().session.scene.formula.clone();

    replace_formula(&mut h, "x^2 + sn(y) - 1");
    for _ in 0..5 {
        h.step();
    }
    let app = h.state();
    let error = app.session.error.as_deref().expect("an error is shown");
    assert!(error.contains("sn"), "{error}");
    assert!(error.contains("did you mean sin"), "{error}");
    assert!(error.contains('^'), "the message has a caret: {error}");
    assert_eq!(
        app.session.picture_generation, before,
        "the picture was replaced"
    );
    assert_eq!(app.session.scene.formula, formula_before);
    assert!(
        !app.progressive.paint().layers.is_empty(),
        "the last picture is gone"
    );
    // The message is on screen, under the editor.
    h.get_by_label_contains("did you mean sin");
}

#[test]
fn an_undefined_constant_says_so_and_keeps_the_picture() {
    // asin(2) has no value, so F has none anywhere: the editor says so and underlines it,
    // as the command line does; no shader is made for it and the last picture stays. The
    // issue's other formulas: the same with their culprit, or a new picture.
    let mut h = harness(small_scene());
    settle(&mut h);
    let cases = undefined_constants();
    assert_eq!(cases.len(), 12, "the issue's twelve formulas");
    for (formula, culprit) in cases {
        let before = h.state().session.picture_generation;
        let pipelines = h.state().session.counters.pipelines;
        let place = h.state().picture_rect;
        replace_formula(&mut h, formula);
        for _ in 0..5 {
            h.step();
        }
        let Some(culprit) = culprit else {
            settle_without_error(&mut h, formula);
            assert!(
                h.state().session.picture_generation > before,
                "{formula}: no new picture"
            );
            continue;
        };
        let app = h.state();
        let error = app.session.error.as_deref().expect("an error is shown");
        assert!(
            error.contains("F is undefined everywhere in the domain"),
            "{formula}: {error}"
        );
        assert_eq!(carets(error), culprit.chars().count(), "{formula}: {error}");
        if culprit == "asin(2)" {
            assert!(
                error.contains("asin is undefined outside [−1, 1]"),
                "{error}"
            );
        }
        assert_eq!(
            app.session.picture_generation, before,
            "{formula}: the picture was replaced"
        );
        assert_eq!(
            app.session.counters.pipelines, pipelines,
            "{formula}: a pipeline was made"
        );
        assert!(
            !app.progressive.paint().layers.is_empty(),
            "{formula}: the last picture is gone"
        );
        // A long message wraps in the panel: the picture keeps its place and size.
        assert_eq!(app.picture_rect, place, "{formula}: the picture moved");
        h.get_by_label_contains("F is undefined everywhere");
    }
}

#[test]
fn moving_a_parameter_slider_rebuilds_the_tree_not_the_shader() {
    let mut scene = Scene::from_formula("x^2 + y^2 + z^2 + w^2 = a");
    scene.params.insert("a".into(), 1.0);
    scene.tree.max_level = 4;
    scene.tree.min_level = 0;
    scene.render.rays = 2;
    let mut h = harness(scene);
    settle(&mut h);
    let counters = h.state().session.counters;

    h.get_by_role_and_label(egui::accesskit::Role::Slider, "a")
        .set_value_accesskit(0.5);
    h.step();
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.session.scene.params["a"], 0.5);
    assert_eq!(app.session.tree_params, vec![0.5]);
    assert_eq!(
        app.session.counters.pipelines, counters.pipelines,
        "the shader was rebuilt"
    );
    assert_eq!(
        app.session.counters.compiles, counters.compiles,
        "the formula was re-parsed"
    );
    assert_eq!(
        app.session.counters.trees,
        counters.trees + 1,
        "the tree was not rebuilt"
    );
}

#[test]
fn every_preset_loads() {
    let mut h = harness(small_scene());
    settle(&mut h);
    // One through the combo box, as a person would.
    h.get_by_label("Preset").click();
    h.run_steps(3);
    h.get_by_role_and_label(egui::accesskit::Role::Button, "glome")
        .click();
    h.step();
    settle(&mut h);
    assert_eq!(h.state().preset, Some("glome"));
    for (name, _) in EXAMPLES {
        let pipelines = h.state().session.counters.pipelines;
        h.state_mut().load_preset(name);
        // Keep the previews cheap on the software GPU.
        h.state_mut().session.scene.render.rays = 2;
        settle_without_error(&mut h, name);
        let app = h.state();
        assert_eq!(app.session.counters.pipelines, pipelines + 1, "{name}");
        assert!(
            app.session.stats.as_ref().unwrap().leaves > 0,
            "{name}: no surface"
        );
        assert!(
            !app.session.scene.description.is_empty(),
            "{name}: no explanation"
        );
    }
}

#[test]
fn a_formula_that_only_touches_zero_says_so() {
    let mut h = harness(small_scene());
    settle(&mut h);
    replace_formula(&mut h, "(x^2 + y^2 + z^2 + w^2 - 1)^2");
    built(&mut h);
    let summary = h.state().session.tree_summary();
    assert!(summary.contains("F does not change sign"), "{summary}");
    h.get_by_label_contains("F does not change sign");
    // x·y² changes sign across x = 0 and touches 0 along y = 0.
    replace_formula(&mut h, "x*y^2");
    built(&mut h);
    let summary = h.state().session.tree_summary();
    assert!(
        summary.contains("F does not change sign across part of M"),
        "{summary}"
    );
    h.get_by_label_contains("F does not change sign across part of M");
    // The glome changes sign: no note.
    replace_formula(&mut h, "x^2 + y^2 + z^2 + w^2 - 1");
    built(&mut h);
    let summary = h.state().session.tree_summary();
    assert!(!summary.contains("F does not change sign"), "{summary}");
}

#[test]
fn a_formula_with_no_zero_set_says_so_and_nothing_freezes() {
    let mut h = harness(small_scene());
    settle(&mut h);
    replace_formula(&mut h, "x^2 + y^2 + z^2 + w^2 + 1");
    built(&mut h);
    let app = h.state();
    assert!(app.session.error.is_none());
    assert_eq!(app.session.stats.as_ref().unwrap().leaves, 0);
    assert!(
        app.session
            .tree_summary()
            .contains("no surface in this domain")
    );
    h.get_by_label_contains("no surface in this domain");

    // A huge max level is bounded by the node budget; the window keeps answering meanwhile.
    h.state_mut().session.scene.tree.max_level = 12;
    h.state_mut().session.scene.tree.node_budget = 200_000;
    h.state_mut().load_preset("glome");
    h.state_mut().session.scene.tree.max_level = 12;
    h.state_mut().session.scene.tree.min_level = 12;
    h.state_mut().session.scene.tree.node_budget = 200_000;
    h.state_mut().session.scene.render.rays = 2;
    let gpu = h.state().gpu().cloned();
    h.state_mut().session.rebuild_tree(gpu.as_ref());
    let started = Instant::now();
    let mut frames = 0;
    while h.state().session.building() {
        let t = Instant::now();
        h.step();
        frames += 1;
        // Generous: CI runs these tests in parallel on a software GPU.
        assert!(
            t.elapsed() < Duration::from_secs(15),
            "a UI frame took {:?}",
            t.elapsed()
        );
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "the build did not end"
        );
    }
    settle(&mut h);
    let stats = h.state().session.stats.clone().unwrap();
    assert!(stats.budget_hit, "the budget should stop a level-12 glome");
    assert!(stats.nodes <= 200_000 + 16, "{} nodes", stats.nodes);
    assert!(frames > 0);
    assert!(h.state().session.tree_summary().contains("node budget hit"));
}

#[test]
fn the_brute_force_checkbox_switches_once_its_pipeline_is_warm() {
    let mut h = harness(small_scene());
    settle(&mut h);
    let pipelines = h.state().session.counters.pipelines;
    // The rendering settings start folded.
    assert!(h.query_by_label_contains("brute force").is_none());
    h.get_by_label_contains("Rendering").click();
    h.step();
    h.get_by_label_contains("brute force").click_accesskit();
    h.step();
    {
        // The picture keeps its mode until the new pipeline is warmed up in the background.
        let app = h.state();
        assert!(
            app.session.scene.render.brute_force || app.session.pending_brute_force == Some(true),
            "the checkbox did nothing"
        );
    }
    settle(&mut h);
    let app = h.state();
    assert!(app.session.scene.render.brute_force);
    assert_eq!(app.session.pending_brute_force, None);
    assert_eq!(app.session.counters.pipelines, pipelines + 1);
    assert!(!app.progressive.paint().layers.is_empty());
}

/// The settled picture is certified by default, its counts under it; the switch turns the
/// proof off (the plain pencil, no counts).
#[test]
fn the_settled_picture_is_certified_by_default_and_the_switch_turns_it_off() {
    let mut h = harness(small_scene());
    assert!(
        h.state().session.scene.render.certified,
        "a scene is not certified by default"
    );
    settle(&mut h);
    let deadline = Instant::now() + Duration::from_secs(120);
    while h.state().progressive.verdicts.is_none() {
        h.step();
        assert!(Instant::now() < deadline, "no verdicts in 120 s");
        std::thread::sleep(Duration::from_millis(5));
    }
    h.step();
    let c = h.state().progressive.verdicts.unwrap();
    assert!(c.hit > 0 && c.empty > 0, "{c:?}");
    let said = format!("certified: {} hit · {} empty", c.hit, c.empty);
    assert!(h.query_by_label_contains(&said).is_some(), "no {said:?}");
    h.get_by_label_contains("Rendering").click();
    h.step();
    h.get_by_label_contains("certified pixels")
        .click_accesskit();
    h.step();
    assert!(
        !h.state().session.scene.render.certified,
        "the switch did nothing"
    );
    settle(&mut h);
    assert!(
        h.query_by_label_contains("certified:").is_none(),
        "a plain picture still shows certified counts"
    );
}

/// A build makes the settled picture's certified pipeline off the window's frames (its
/// compile, hundreds of milliseconds on llvmpipe, would stall the first still frame), and
/// only for a certified scene; after the caster, so that the first preview does not wait
/// for it: the caster comes with its first frames' pipeline alone, and a sibling with the
/// certified one follows.
#[test]
fn a_build_makes_the_certified_pipeline_beside_the_window_after_the_caster() {
    use fourfold::render::{Gpu, Program};
    use fourfold_viewer::job::JobInputs;
    use fourfold_viewer::platform::BuildWork;
    let gpu = Gpu::new().unwrap();
    for certified in [true, false] {
        let mut scene = small_scene();
        scene.render.certified = certified;
        let inputs = JobInputs {
            generation: 1,
            program: Program::new(&scene.formula).unwrap(),
            scene: scene.clone(),
            gpu: Some(gpu.clone()),
            make_pipeline: true,
            pipeline_at_first_draw: false,
            brute_force: false,
            interpreter: None,
        };
        let mut work = BuildWork::start(inputs).unwrap();
        let deadline = Instant::now() + Duration::from_secs(120);
        let result = loop {
            if let Some(result) = work.poll(Duration::ZERO) {
                break result.unwrap();
            }
            assert!(Instant::now() < deadline, "no build in 120 s");
            std::thread::sleep(Duration::from_millis(5));
        };
        let mut caster = result.caster.unwrap().unwrap();
        let hierarchy = result.tree.unwrap().0;
        assert_eq!(caster.pipelines_built(), 1, "certified: {certified}");
        let Some(settling) = result.settling else {
            assert!(!certified, "no certified pipeline follows the caster");
            continue;
        };
        assert!(certified, "a plain scene builds a certified pipeline");
        let sibling = settling
            .receiver
            .recv_timeout(Duration::from_secs(120))
            .expect("the certified pipeline is built")
            .unwrap();
        assert_eq!(sibling.pipelines_built(), 1);
        assert!(caster.adopt(sibling), "the sibling is the caster's");
        assert_eq!(caster.pipelines_built(), 2);
        assert!(caster.has_pipeline_for(&scene, &hierarchy));
    }
}

/// Once the interpreting shader is built (after the first picture, where it is on), a new
/// formula's first frames draw with it, at once; its own shader compiles beside the window and takes over
/// the picture, which then settles certified. A parameter's new tree keeps to the caster
/// on screen, whichever shader it has.
#[test]
fn a_new_formula_draws_with_the_interpreter_until_its_own_shader_takes_over() {
    let mut h = harness(small_scene());
    settle_without_error(&mut h, "the first picture");
    // On a CPU's adapter, as in CI, it is off by default: switched on in the Rendering panel.
    let gpu = h.state().gpu().unwrap().clone();
    assert!(!h.state().session.interprets_new_formulas(&gpu));
    h.get_by_label_contains("Rendering").click();
    h.step();
    h.get_by_label_contains("interpreted first frames")
        .click_accesskit();
    h.step();
    assert!(h.state().session.interprets_new_formulas(&gpu));
    assert_eq!(h.state().ui.interpret, Some(true), "not remembered");
    assert!(
        !h.state().session.interpreting(),
        "the first picture interprets"
    );
    let deadline = Instant::now() + Duration::from_secs(120);
    while !h.state().session.interpreter_ready() {
        h.step();
        assert!(Instant::now() < deadline, "no interpreter in 120 s");
        std::thread::sleep(Duration::from_millis(5));
    }
    let pipelines = h.state().session.counters.pipelines;
    replace_formula(&mut h, "x^2 + y^2 + z^2 + w^2 = a");
    let deadline = Instant::now() + Duration::from_secs(120);
    while h.state().session.building() {
        h.step();
        assert!(Instant::now() < deadline, "no build in 120 s");
    }
    let session = &h.state().session;
    assert!(session.error.is_none(), "{:?}", session.error);
    assert_eq!(session.scene.formula, "x^2 + y^2 + z^2 + w^2 = a");
    assert!(
        session.interpreting(),
        "the new formula's first frames do not interpret"
    );
    assert_eq!(session.counters.pipelines, pipelines + 1);
    assert!(
        session.times.pipeline_ms < session.times.ready_ms,
        "{:?}",
        session.times
    );
    // The new picture's verdicts (the old picture's stay until its first frame is drawn).
    let generation = session.picture_generation;
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let p = &h.state().progressive;
        if p.first_frame_of == Some(generation) && p.verdicts.is_some() {
            break;
        }
        h.step();
        assert!(Instant::now() < deadline, "no verdicts in 120 s");
        std::thread::sleep(Duration::from_millis(5));
    }
    let app = h.state();
    assert!(
        !app.session.interpreting(),
        "the settled picture interprets"
    );
    let c = app.progressive.verdicts.unwrap();
    assert!(c.hit > 0 && c.empty > 0, "{c:?}");
}

/// A new formula in a mode the interpreting shader has no pipeline for (a slice) draws with
/// its own shader, and the build's thread then gives the interpreter that mode's pipeline:
/// the next new formula in it is interpreted.
#[test]
fn the_interpreter_gains_the_pipeline_of_a_mode_it_lacked() {
    use fourfold::render::{Gpu, Program};
    use fourfold::tree::Hierarchy;
    use fourfold_viewer::job::{JobInputs, build_interpreter, first_frames};
    use fourfold_viewer::platform::{BuildWork, warm_up};
    use std::sync::Arc;
    let gpu = Gpu::new().unwrap();
    let scene = small_scene();
    let formula = Program::new(&scene.formula).unwrap().formula;
    let empty = Hierarchy::default();
    let interpreter = build_interpreter(&gpu, &scene, &formula, &empty, warm_up).unwrap();
    let interpreter = Arc::new(interpreter);
    let mut sliced = scene.clone();
    sliced.view.slice = Some(0.3);
    let first = first_frames(&sliced, false);
    assert!(!interpreter.has_pipeline_for(&first, &empty));
    let interprets = |text: &str| {
        let inputs = JobInputs {
            generation: 1,
            program: Program::new(text).unwrap(),
            scene: sliced.clone(),
            gpu: Some(gpu.clone()),
            make_pipeline: true,
            pipeline_at_first_draw: false,
            brute_force: false,
            interpreter: Some(interpreter.clone()),
        };
        let mut work = BuildWork::start(inputs).unwrap();
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            if let Some(result) = work.poll(Duration::ZERO) {
                break result.unwrap().caster.unwrap().unwrap().interprets();
            }
            assert!(Instant::now() < deadline, "no build in 120 s");
            std::thread::sleep(Duration::from_millis(5));
        }
    };
    assert!(
        !interprets("x^2 + y^2 + z^2 + w^2 = 0.9"),
        "no slice pipeline yet"
    );
    let deadline = Instant::now() + Duration::from_secs(120);
    while !interpreter.has_pipeline_for(&first, &empty) {
        assert!(Instant::now() < deadline, "no slice pipeline in 120 s");
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(
        interprets("x^2 + y^2 + z^2 + w^2 = 0.8"),
        "the slice pipeline was built"
    );
}

/// Switching the view to a slice needs the slice's pipelines (plain and certified): they are
/// built beside the window, not in the frame that first draws the slice, and the picture
/// waits for them.
#[test]
fn a_slice_s_pipelines_are_built_beside_the_window() {
    use fourfold_viewer::job::{first_frames, settled_frames};
    let mut h = harness(small_scene());
    h.state_mut().ui.side_by_side = false;
    settle_without_error(&mut h, "the projection");
    converge(&mut h);
    h.state_mut().session.scene.view.slice = Some(0.3);
    let sliced = first_frames(&h.state().session.scene, false);
    let settled = settled_frames(&sliced);
    let has = |h: &Harness<'static, FourfoldApp>, scene: &Scene| {
        let s = &h.state().session;
        let hierarchy = s.hierarchy.as_ref().unwrap();
        s.caster
            .as_ref()
            .unwrap()
            .has_pipeline_for(scene, hierarchy)
    };
    assert!(!has(&h, &sliced) && !has(&h, &settled));
    h.step();
    assert!(
        h.state().session.certified_pipeline_pending(),
        "the slice's pipelines are not being built beside the window"
    );
    assert!(!has(&h, &sliced), "the frame built the slice's pipeline");
    let deadline = Instant::now() + Duration::from_secs(120);
    while !(has(&h, &sliced) && has(&h, &settled)) {
        h.step();
        assert!(Instant::now() < deadline, "no slice pipelines in 120 s");
        std::thread::sleep(Duration::from_millis(5));
    }
    converge(&mut h);
    assert!(
        h.state().progressive.verdicts.is_some(),
        "the slice is not certified"
    );
}

#[test]
fn a_picture_converges_with_one_binning_per_resolution() {
    let mut h = harness(small_scene());
    settle(&mut h);
    converge(&mut h);
    let app = h.state();
    // A preview, maybe a half-size pass, then the full size: the accumulated full-size passes
    // (same view, new ray offsets) reuse one set of leaf lists.
    assert!(
        (2..=3).contains(&app.progressive.binner.binnings),
        "{} binnings for one picture",
        app.progressive.binner.binnings
    );
    assert!(app.progressive.full_quality());
}

#[test]
fn the_frame_rate_shown_leaves_out_the_wait_of_an_idle_window() {
    // Once the picture has converged the window stops drawing until the next event; the
    // status line's "UI N fps" must not count that wait as a frame (it read 1 fps at the
    // first drag after a pause).
    let mut h = harness(small_scene());
    settle(&mut h);
    converge(&mut h);
    h.step();
    let drawing = h.state().pacing.ui_frame_ms;
    std::thread::sleep(Duration::from_secs(3));
    h.step();
    let after = h.state().pacing.ui_frame_ms;
    assert!(
        after < drawing + 100.0,
        "{after:.0} ms per UI frame after a 3 s pause, {drawing:.0} ms before"
    );
}

#[test]
fn the_picture_keeps_its_size_as_the_lines_below_it_change_in_a_small_window() {
    // The status line's text grows as the picture refines and after an edit, and notices
    // come and go: in a small window a line that wrapped shrank the picture, which started
    // again (on a software GPU, seconds of certified frame: the page at 800x500 showed a
    // blank picture after a mistyped formula). At 900 px, with lavapipe's name in the line,
    // the edit's "edit to picture" made it wrap.
    let mut h = Harness::builder()
        .wgpu()
        .with_size([900.0, 480.0])
        .build_eframe(move |cc| FourfoldApp::new(cc, Some(small_scene())));
    settle(&mut h);
    converge(&mut h);
    let rect = |h: &Harness<'static, FourfoldApp>| h.state().picture_rect.expect("a picture");
    let first = rect(&h);
    h.get_by_label("Copy formula").click();
    h.step();
    h.step();
    assert!(h.state().message.is_some(), "no notice after Copy formula");
    assert_eq!(rect(&h), first, "a notice moved the picture");
    replace_formula(&mut h, "x^2 + y^2 + z^2 + w^2 - 0.8 + 0.0000001 x y z w");
    settle(&mut h);
    converge(&mut h);
    assert!(h.state().edit_latency_ms.is_some(), "no edit latency shown");
    assert_eq!(rect(&h), first, "the edit's status line moved the picture");
    replace_formula(&mut h, "x^2 + (y");
    for _ in 0..5 {
        h.step();
    }
    assert!(h.state().session.error.is_some(), "no error shown");
    assert_eq!(rect(&h), first, "the error moved the picture");
}

/// The bounding box [x0, y0, x1, y1] of the pixels of `rgba` (w×h) that are not `background`.
fn covered_box(rgba: &[u8], w: u32, background: [u8; 3]) -> Option<[u32; 4]> {
    let mut bbox: Option<[u32; 4]> = None;
    for (i, p) in rgba.chunks(4).enumerate() {
        if p[..3] != background {
            let (x, y) = (i as u32 % w, i as u32 / w);
            bbox = Some(match bbox {
                None => [x, y, x, y],
                Some([x0, y0, x1, y1]) => [x0.min(x), y0.min(y), x1.max(x), y1.max(y)],
            });
        }
    }
    bbox
}

#[test]
fn opening_a_preset_frames_the_manifold() {
    use fourfold::headless::render_scene;
    use fourfold::render::{Device, Gpu};
    let gpu = Gpu::new().expect("GPU tests need an adapter");
    let mut h = harness(small_scene());
    settle(&mut h);
    for name in ["fig-3-9-left", "glome", "tiger", "duocylinder"] {
        h.state_mut().load_preset(name);
        h.state_mut().session.scene.render.rays = 4;
        settle(&mut h);
        let app = h.state();
        assert!(!app.fit_pending, "{name}: not framed");
        // The picture as it is on screen (the same view, a quarter of the size: the framing
        // scales with it), drawn independently of the viewer's textures.
        let [w, ht] = app.picture_size.map(|s| s / 4);
        let scene = app.session.scene.clone();
        let picture = render_scene(&scene, w, ht, Device::Gpu(&gpu), Default::default()).unwrap();
        let background = scene.render.background.0;
        let [x0, y0, x1, y1] = covered_box(&picture.rgba, w, background)
            .unwrap_or_else(|| panic!("{name}: nothing drawn"));
        assert!(
            x0 > 0 && y0 > 0 && x1 < w - 1 && y1 < ht - 1,
            "{name}: the manifold runs off the picture: {x0},{y0}..{x1},{y1} of {w}x{ht}"
        );
        let (cw, ch) = (x1 - x0 + 1, y1 - y0 + 1);
        assert!(
            2 * cw >= w || 2 * ch >= ht,
            "{name}: the manifold fills {cw}x{ch} of {w}x{ht}"
        );
    }
}

#[test]
fn a_late_error_in_a_long_formula_keeps_its_caret_in_the_panel() {
    let mut h = harness(small_scene());
    settle(&mut h);
    // 200 characters, the error at the very end, no '^' but the caret's.
    let mut text = "sin(3x)cos(3y) + sin(3z)cos(3w) - 0.2 + ".repeat(5);
    text.truncate(194);
    text.push_str(" + sn(x");
    assert!(text.len() >= 200 && !text.contains('^'));
    replace_formula(&mut h, &text);
    h.run_steps(3);
    let panel = h.state().controls_rect.expect("the controls panel");
    assert!(h.state().session.error_at.is_some(), "no error shown");
    let carets: Vec<_> = h.query_all_by_label_contains("^").collect();
    assert!(!carets.is_empty(), "no caret line on screen");
    for caret in carets {
        let rect = caret.rect();
        assert!(
            rect.left() >= panel.left() - 1.0 && rect.right() <= panel.right() + 1.0,
            "the caret line {rect:?} leaves the panel {panel:?}"
        );
    }
    // The label says where, in view too.
    let label = h.get_by_label_contains("opened here").rect();
    assert!(label.right() <= panel.right() + 1.0, "{label:?} {panel:?}");
}

#[test]
fn undo_after_a_formula_edit_restores_the_formula_and_its_picture() {
    let mut h = harness(small_scene());
    settle(&mut h);
    let before = h.state().session.scene.formula.clone();
    let leaves = h.state().session.stats.as_ref().unwrap().leaves;
    // Let the opening state settle into the history, then edit.
    std::thread::sleep(Duration::from_millis(500));
    h.run_steps(2);
    replace_formula(&mut h, "x + y + z + w = 0.5");
    settle(&mut h);
    std::thread::sleep(Duration::from_millis(500));
    h.run_steps(2);
    assert_ne!(h.state().session.stats.as_ref().unwrap().leaves, leaves);
    // Ctrl+Z acts on the window once the editor has let go of the keyboard.
    h.key_press(egui::Key::Escape);
    h.run_steps(2);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.step();
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.session.text, before);
    assert_eq!(app.session.scene.formula, before);
    assert_eq!(app.session.stats.as_ref().unwrap().leaves, leaves);
    assert!(app.history.can_redo());
    // And redo brings the edit back.
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    h.step();
    settle(&mut h);
    assert_eq!(h.state().session.text, "x + y + z + w = 0.5");
}

#[test]
fn the_gallery_lists_every_example_scene() {
    let mut h = harness(small_scene());
    settle(&mut h);
    h.get_by_label("Gallery").click();
    h.run_steps(3);
    for (name, _) in EXAMPLES {
        h.get_by_label(name);
    }
    // Picking one opens and frames it.
    h.get_by_label("tiger").click();
    h.step();
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.preset, Some("tiger"));
    assert!(!app.gallery.open);
    assert!(!app.fit_pending);
}

#[test]
fn an_animation_exports_in_the_background_with_its_progress() {
    let mut h = harness(small_scene());
    settle(&mut h);
    let path = std::env::temp_dir().join(format!("fourfold-viewer-{}.gif", std::process::id()));
    {
        let app = h.state_mut();
        app.ui.export_size = [40, 30];
        app.ui.animation.path = path.display().to_string();
        app.ui.animation.plane = "xw".into();
        app.ui.animation.frames = 3;
    }
    h.get_by_label_contains("Export animation").click();
    h.step();
    h.get_by_role_and_label(egui::accesskit::Role::Button, "Export animation")
        .click_accesskit();
    h.step();
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        h.step();
        let message = h.state().message.clone();
        if let Some(m) = message.filter(|m| m.text.starts_with("wrote")) {
            assert!(!m.is_error, "{}", m.text);
            break;
        }
        assert!(Instant::now() < deadline, "the export did not end");
        std::thread::sleep(Duration::from_millis(10));
    }
    use image::AnimationDecoder;
    let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
    let frames = image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .count();
    assert_eq!(frames, 3);
    std::fs::remove_file(&path).ok();
}

#[test]
fn a_slice_is_shown_beside_the_projection() {
    let mut h = harness(small_scene());
    settle(&mut h);
    h.state_mut().session.scene.view.slice = Some(0.3);
    let deadline = Instant::now() + Duration::from_secs(120);
    // (The slice's picture starts again at its new size; the projection starts anew.)
    let drawn = |h: &Harness<'static, FourfoldApp>| {
        let app = h.state();
        !app.inset.paint().layers.is_empty() && !app.progressive.paint().layers.is_empty()
    };
    while !drawn(&h) {
        h.step();
        assert!(
            Instant::now() < deadline,
            "the slice and the projection beside it never both drew"
        );
    }
    assert!(h.state().side_by_side());
    // Back to the projection alone.
    h.state_mut().session.scene.view.slice = None;
    h.step();
    assert!(!h.state().side_by_side());
}

#[test]
fn export_mesh_writes_the_slice_shown() {
    let mut h = harness(small_scene());
    settle(&mut h);
    let path = std::env::temp_dir().join(format!("fourfold-viewer-{}.stl", std::process::id()));
    std::fs::remove_file(&path).ok();
    h.state_mut().ui.mesh_path = path.display().to_string();
    // With no slice shown, the button does nothing.
    h.get_by_role_and_label(egui::accesskit::Role::Button, "Export mesh")
        .click();
    h.step();
    h.step();
    assert!(!path.exists() && h.state().message.is_none());
    h.state_mut().session.scene.view.slice = Some(0.3);
    h.step();
    h.get_by_role_and_label(egui::accesskit::Role::Button, "Export mesh")
        .click();
    h.step();
    let deadline = Instant::now() + Duration::from_secs(120);
    let said = loop {
        h.step();
        let message = h.state().message.clone();
        if let Some(m) = message.filter(|m| m.text.starts_with("saved")) {
            assert!(!m.is_error, "{}", m.text);
            break m.text;
        }
        assert!(Instant::now() < deadline, "the mesh export did not end");
        std::thread::sleep(Duration::from_millis(10));
    };
    // The unit glome's slice at 0.3: a binary STL of a sphere, its triangles counted.
    let bytes = std::fs::read(&path).unwrap();
    let triangles = u32::from_le_bytes(bytes[80..84].try_into().unwrap());
    assert_eq!(bytes.len(), 84 + 50 * triangles as usize);
    assert!(said.contains(&format!("{triangles} triangles")), "{said}");
    std::fs::remove_file(&path).ok();
}

#[test]
fn the_slice_slider_jumps_between_proved_critical_values() {
    // The unit glome turned: its slices are born at c = -1 and vanish at c = 1.
    let mut scene = small_scene();
    scene.view.angles = [0.3, 0.5, 0.7, 0.2, 0.9, 1.1];
    scene.view.slice = Some(-1.5);
    let mut h = harness(scene);
    settle(&mut h);
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        h.step();
        let app = h.state();
        let program = app.session.program.as_ref().expect("drawn");
        if let Some(report) = app.critical.report(&program.formula, &app.session.scene) {
            let report = report.expect("a report");
            let values: Vec<(f64, Option<u8>)> = report
                .points
                .iter()
                .map(|p| (p.value.midpoint(), p.index))
                .collect();
            assert_eq!(values.len(), 2, "{values:?}");
            assert!((values[0].0 + 1.0).abs() < 1e-9 && values[0].1 == Some(0));
            assert!((values[1].0 - 1.0).abs() < 1e-9 && values[1].1 == Some(3));
            break;
        }
        assert!(Instant::now() < deadline, "no critical values");
        std::thread::sleep(Duration::from_millis(20));
    }
    h.step();
    h.get_by_label("2 proved");
    let slice = |h: &Harness<'static, FourfoldApp>| h.state().session.scene.view.slice.unwrap();
    h.get_by_role_and_label(egui::accesskit::Role::Button, "next change »")
        .click();
    h.step();
    assert!((slice(&h) + 1.0).abs() < 1e-9, "{}", slice(&h));
    h.get_by_role_and_label(egui::accesskit::Role::Button, "next change »")
        .click();
    h.step();
    assert!((slice(&h) - 1.0).abs() < 1e-9, "{}", slice(&h));
    h.get_by_role_and_label(egui::accesskit::Role::Button, "« previous change")
        .click();
    h.step();
    assert!((slice(&h) + 1.0).abs() < 1e-9, "{}", slice(&h));
    // A turn changes n2: the values are searched again once the view is still.
    h.state_mut().session.scene.view.angles[2] += 0.1;
    h.step();
    let app = h.state();
    let program = app.session.program.as_ref().unwrap();
    assert!(
        app.critical
            .report(&program.formula, &app.session.scene)
            .is_none()
    );
}

#[test]
fn the_embed_code_is_an_iframe_of_the_scene_on_screen() {
    let mut scene = small_scene();
    scene.formula = "x^2 + y^2 - z^2 - w^2 = 0.1".into();
    let mut h = harness(scene);
    settle(&mut h);
    // (The button is the page's: the desktop has no address an iframe could show.)
    let copied = h.state().embed_code();
    let link = h.state().session.link_fragment();
    assert!(
        copied.starts_with("<iframe src=\"index.html#embed&amp;")
            && copied.contains(&link.replace('&', "&amp;"))
            && copied.contains("title=\"fourfold: x^2 + y^2 - z^2 - w^2 = 0.1\"")
            && copied.ends_with("></iframe>"),
        "{copied}"
    );
}

/// Where new formulas preview on the CPU (the page's way), a new formula's caster comes
/// without pipelines, and its first picture on screen is the twin's, drawn in the texture
/// of its stage, before the GPU has compiled anything; the GPU's stages follow, and the
/// settled picture is certified.
#[test]
fn a_new_formula_previews_on_the_cpu_while_its_pipeline_is_not_built() {
    let mut h = harness(small_scene());
    settle_without_error(&mut h, "the first picture");
    h.state_mut().session.previews_on_cpu = true;
    let drawn = h.state().progressive.cpu_previews.drawn;
    replace_formula(&mut h, "x^2 + 2y^2 + z^2 + w^2 = 0.7");
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let app = h.state();
        let generation = app.session.picture_generation;
        if !app.session.building() && app.progressive.first_frame_of == Some(generation) {
            break;
        }
        h.step();
        assert!(Instant::now() < deadline, "no first frame in 120 s");
    }
    let app = h.state();
    let session = &app.session;
    assert!(session.error.is_none(), "{:?}", session.error);
    let caster = session.caster.as_ref().unwrap();
    assert_eq!(caster.pipelines_built(), 0, "the GPU compiled first");
    let progressive = &app.progressive;
    assert!(progressive.preview_from_cpu);
    assert_eq!(progressive.cpu_previews.drawn, drawn + 1);
    // The texture holds the twin's picture of the preview's frame, byte for byte.
    let div = progressive.cpu_previews.last.unwrap();
    let texture = progressive.texture_of(div).unwrap();
    let gpu = app.gpu().unwrap();
    let read = fourfold::render::gpu::start_texture_read(gpu, &texture.texture);
    let shown = loop {
        if let Some(rgba) = read.poll(gpu) {
            break rgba.unwrap();
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let mut scene = session.scene.clone();
    scene.render.certified = false;
    let hierarchy = session.hierarchy.as_ref().unwrap();
    let options = fourfold::render::FrameOptions {
        rays: Some(scene.render.rays.min(4)),
        ..Default::default()
    };
    let size = [texture.width, texture.height];
    let params = &session.tree_params;
    let (_, uniforms) = fourfold::render::view::frame(&scene, hierarchy, params, size, options);
    let formula = &session.program.as_ref().unwrap().formula;
    let twin = fourfold::render::twin::render_rgba(formula, params, hierarchy, None, &uniforms);
    assert_eq!(shown.len(), twin.len());
    assert!(
        shown == twin,
        "the preview on screen is not the twin's picture"
    );
    assert!(
        twin.chunks(4).any(|p| p[..3] != twin[..3]),
        "the preview shows nothing but background"
    );
    // Then the GPU's stages, with the pipelines their frames build.
    converge(&mut h);
    let app = h.state();
    assert!(app.session.caster.as_ref().unwrap().pipelines_built() > 0);
    let c = app
        .progressive
        .verdicts
        .expect("the settled picture is certified");
    assert!(c.hit > 0 && c.empty > 0, "{c:?}");
}
