//! The command line's `render` flags: each overrides the scene file, and a bad value is a
//! usage error (exit code 2) that names the flag and says what it takes, never a panic.

use clap::Parser;
use fourfold::scene::{Sampling, Scene};
use fourfold_cli::{Cli, Command, Failure, RenderArgs, render_scene_of};

mod common;
use common::fourfold;

#[path = "../../fourfold/tests/support/undefined_constants.rs"]
mod support;
use support::{carets, undefined_constants};

const SCENE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../examples/scenes/fig-3-9-left.toml"
);

fn render_args(flags: &[&str]) -> RenderArgs {
    let argv: Vec<&str> = ["render", SCENE, "-o", "x.png"]
        .iter()
        .chain(flags)
        .copied()
        .collect();
    parse_render(&argv)
}

/// `fourfold ARGV...` parsed as a render command.
fn parse_render<S: AsRef<str> + std::fmt::Debug>(argv: &[S]) -> RenderArgs {
    let words = std::iter::once("fourfold").chain(argv.iter().map(|a| a.as_ref()));
    match Cli::try_parse_from(words).unwrap_or_else(|e| panic!("{argv:?}: {e}")) {
        Cli {
            command: Some(Command::Render(args)),
        } => args,
        other => panic!("{argv:?} parsed as {other:?}"),
    }
}

fn scene(flags: &[&str]) -> Result<Scene, Failure> {
    render_scene_of(&render_args(flags))
}

#[test]
fn certified_flags_set_the_scene_s_keys() {
    let s = scene(&["--certified", "--cert-budget", "64", "--undecided", "hatch"]).unwrap();
    assert!(s.render.certified);
    assert_eq!(s.render.cert_budget, 64);
    assert_eq!(s.render.undecided, fourfold::scene::Undecided::Hatch);
    // Certified by default; --uncertified asks for the plain pencil, and not with
    // --certified.
    assert!(scene(&[]).unwrap().render.certified);
    assert!(!scene(&["--uncertified"]).unwrap().render.certified);
    let both = ["fourfold", "render", "x", "--certified", "--uncertified"];
    assert!(Cli::try_parse_from(both).is_err());
}

#[test]
fn render_flags_override_the_scene_file() {
    let file = Scene::load(std::path::Path::new(SCENE)).unwrap();
    let plain = scene(&[]).unwrap();
    assert_eq!(plain.render, file.render);
    assert_eq!(plain.view, file.view);
    let s = scene(&[
        "--rays",
        "5",
        "--hits",
        "2",
        "--steps",
        "12",
        "--bisection-iters",
        "7",
        "--approximation",
        "0.001",
        "--seed",
        "42",
        "--sampling",
        "random",
        "--alpha",
        "0.25",
        "--zoom",
        "2",
        "--angles",
        "0.1,-0.2,0.3,0,0,1",
        "--max-level",
        "5",
        "--min-level",
        "3",
        "--background",
        "102030",
        "--no-silhouette",
        "--no-border",
        "--no-lighting",
        "--brute-force",
    ])
    .unwrap();
    let r = &s.render;
    assert_eq!((r.rays, r.hits, r.steps, r.bisection_iters), (5, 2, 12, 7));
    assert_eq!((r.approximation, r.seed, r.alpha), (0.001, 42, 0.25));
    assert_eq!(r.sampling, Sampling::Random);
    assert_eq!(r.background.0, [0x10, 0x20, 0x30]);
    assert!(!r.silhouette.enabled && !r.border.enabled && !r.lighting.enabled);
    assert!(r.brute_force);
    assert_eq!(s.view.angles, [0.1, -0.2, 0.3, 0.0, 0.0, 1.0]);
    assert_eq!(s.view.zoom, 2.0);
    assert_eq!((s.tree.max_level, s.tree.min_level), (5, 3));
    // What no flag touched is the file's.
    assert_eq!(s.formula, file.formula);
    assert_eq!(s.domain, file.domain);
    assert_eq!(s.render.lighting.shininess, file.render.lighting.shininess);
}

#[test]
fn bad_render_flags_are_usage_errors_that_name_the_flag() {
    let cases: &[(&[&str], &str)] = &[
        (&["--rays", "0"], "--rays 0: between 1 and 1024"),
        (&["--hits", "17"], "--hits 17: between 1 and 16"),
        (&["--steps", "0"], "--steps 0: between 1 and 256"),
        (
            &["--bisection-iters", "257"],
            "--bisection-iters 257: between 1 and 256",
        ),
        (
            &["--approximation", "-1"],
            "--approximation -1: a number ≥ 0",
        ),
        (
            &["--approximation", "inf"],
            "--approximation inf: a number ≥ 0",
        ),
        (&["--alpha", "1.5"], "--alpha 1.5: between 0 and 1"),
        (&["--zoom", "-2"], "--zoom -2: a positive number"),
        (
            &["--angles", "1,2"],
            "--angles 1,2: expected six numbers, got 2",
        ),
        (
            &["--sampling", "even"],
            "--sampling even: use random or stratified",
        ),
        (
            &["--max-level", "13"],
            "--max-level 13: the deepest level is 12",
        ),
        (
            &["--min-level", "6", "--max-level", "5"],
            "--min-level 6 is above --max-level 5",
        ),
        (&["--background", "zz"], "--background"),
        (
            &["--certified", "--cert-budget", "0"],
            "--cert-budget 0: between 1 and 8192",
        ),
        (
            &["--undecided", "grey"],
            "--undecided grey: use marker or hatch",
        ),
        (&["--param", "R=nan"], "parameter R must be a finite number"),
        // (f32's range: beyond it the GPU's F is unspecified, lavapipe's 0·a zero.)
        (
            &["--param", "R=-1e300"],
            "parameter R = -1e300 is beyond ±3.4e38",
        ),
    ];
    for (flags, expected) in cases {
        let failure = scene(flags).expect_err(&format!("{flags:?} was accepted"));
        assert_eq!(failure.code, 2, "{flags:?}: {}", failure.message);
        assert!(
            failure.message.contains(expected),
            "{flags:?}: {:?} does not say {expected:?}",
            failure.message
        );
    }
}

/// A name the picture cannot be written under is said before anything is drawn (a long
/// render is not lost to it); any other name gets the PNG.
#[test]
fn bad_outputs_are_said_before_anything_is_drawn() {
    let dir = std::env::temp_dir().join(format!("fourfold-outputs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("no-such-folder").join("x.png");
    let cases = [
        (
            dir.join("x.jpg"),
            "fourfold writes PNG pictures, not '.jpg': name it",
        ),
        (missing.clone(), "there is no folder"),
        (dir.clone(), "name a file to write the PNG to"),
    ];
    for (out, expected) in cases {
        // (A picture that takes long to draw: the failure must come before it.)
        let argv = [
            "render",
            SCENE,
            "--size",
            "2000x2000",
            "--max-level",
            "12",
            "-o",
        ];
        let args = parse_render(&[&argv[..], &[out.to_str().unwrap()]].concat());
        let failure = fourfold_cli::render(&args, &mut |_| {}).expect_err(expected);
        assert_eq!(failure.code, 2, "{}", failure.message);
        assert!(
            failure.message.contains(expected),
            "{:?} does not say {expected:?}",
            failure.message
        );
    }
    assert!(!dir.join("x.jpg").exists() && !missing.exists());
    for name in ["picture.png", "PICTURE.PNG", "no-extension"] {
        let out = dir.join(name);
        let argv = ["render", SCENE, "--size", "24x16", "--cpu", "-o"];
        let args = parse_render(&[&argv[..], &[out.to_str().unwrap()]].concat());
        fourfold_cli::render(&args, &mut |_| {}).unwrap_or_else(|f| panic!("{}", f.message));
        let reader = image::ImageReader::open(&out).unwrap();
        let reader = reader.with_guessed_format().unwrap();
        assert_eq!(reader.format(), Some(image::ImageFormat::Png), "{name}");
        let picture = reader.decode().unwrap();
        assert_eq!((picture.width(), picture.height()), (24, 16), "{name}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_negative_number_for_a_count_is_clap_s_clear_error_not_an_unknown_flag() {
    for flag in ["--rays", "--seed", "--max-level", "--steps"] {
        let err = Cli::try_parse_from(["fourfold", "render", SCENE, "-o", "x.png", flag, "-3"])
            .expect_err(flag)
            .to_string();
        assert!(
            err.contains("invalid value '-3'") && err.contains(flag),
            "{flag}: {err}"
        );
    }
}

#[test]
fn the_help_states_the_defaults_the_scene_really_has() {
    use clap::CommandFactory;
    use fourfold::scene::{RenderSettings, TreeSettings};
    let (r, t) = (RenderSettings::default(), TreeSettings::default());
    let cli = Cli::command();
    let render = cli.find_subcommand("render").unwrap();
    let expected = [
        ("rays", r.rays.to_string()),
        ("hits", r.hits.to_string()),
        ("steps", r.steps.to_string()),
        ("bisection_iters", r.bisection_iters.to_string()),
        ("approximation", format!("{:e}", r.approximation)),
        ("seed", r.seed.to_string()),
        ("alpha", r.alpha.to_string()),
        ("max_level", t.max_level.to_string()),
        ("min_level", t.min_level.to_string()),
    ];
    let states = |command: &clap::Command, id: &str, default: &str| {
        let arg = command.get_arguments().find(|a| a.get_id() == id).unwrap();
        let help = arg.get_help().unwrap().to_string();
        assert!(
            help.contains(&format!("else {default}")),
            "{} --{id}: {help:?} does not give the default {default}",
            command.get_name()
        );
    };
    for (id, default) in expected {
        states(render, id, &default);
    }
    // `tree` states the tree's defaults too.
    let tree = cli.find_subcommand("tree").unwrap();
    states(tree, "max_level", &t.max_level.to_string());
    states(tree, "min_level", &t.min_level.to_string());
}

#[test]
fn a_scene_file_s_bad_value_is_told_as_the_flag_s_with_the_line_it_is_on() {
    // The scene file and the flags share one check: the same range, said with the key's
    // name and pointing at the line that sets it.
    let cases = [
        ("[render]\nrays = 0\n", "rays = 0: between 1 and 1024", 2),
        (
            "[tree]\nmax_level = 13\n",
            "max_level = 13: the deepest level is 12",
            2,
        ),
        (
            "[tree]\nmax_level = 3\nmin_level = 5\n",
            "min_level 5 is above max_level 3",
            3,
        ),
        ("[view]\nzoom = -1.0\n", "zoom = -1: a positive number", 2),
        (
            "[render.silhouette]\nenabled = true\ntolerance = 0.1\ncolor = \"#ffffff\"\n\
             [render.border]\nenabled = true\ntolerance = -0.5\ncolor = \"#ffffff\"\n",
            "tolerance = -0.5: a number ≥ 0",
            7,
        ),
    ];
    for (body, expected, line) in cases {
        let text = format!("formula = \"x^2 + y^2 + z^2 + w^2 - 1\"\n{body}");
        let message = Scene::parse(&text, "bad.toml").expect_err(body).to_string();
        assert!(message.contains(expected), "{body:?}: {message}");
        // codespan names the line: bad.toml:LINE:COLUMN (the formula is line 1).
        assert!(
            message.contains(&format!("bad.toml:{}:", line + 1)),
            "{body:?} should point at line {}: {message}",
            line + 1
        );
    }
}

#[test]
fn render_fit_frames_the_manifold_not_the_domain() {
    // The glome in a domain four times its size: at zoom 1 it is a few pixels wide; --fit
    // zooms to the tree's boxes around it (level 4 by default: half a unit wide), so that
    // it fills half the picture or more.
    let dir = std::env::temp_dir().join(format!("fourfold-fit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let widths: Vec<u32> = [false, true]
        .into_iter()
        .map(|fit| {
            let out = dir.join(format!("glome-{fit}.png"));
            let mut argv = vec![
                "render".to_string(),
                "x^2 + y^2 + z^2 + w^2 = 1".into(),
                "--domain".into(),
                "-4,4,-4,4,-4,4,-4,4".into(),
                "--size".into(),
                "48x48".into(),
                "--rays".into(),
                "4".into(),
                "--cpu".into(),
                "-o".into(),
                out.display().to_string(),
            ];
            if fit {
                argv.push("--fit".into());
            }
            let args = parse_render(&argv);
            fourfold_cli::render(&args, &mut |_| {}).unwrap_or_else(|f| panic!("{}", f.message));
            let image = image::open(&out).unwrap().to_rgba8();
            let background = Scene::from_formula("x").render.background.0;
            let xs: Vec<u32> = image
                .enumerate_pixels()
                .filter(|(_, _, p)| p.0[..3] != background)
                .map(|(x, _, _)| x)
                .collect();
            let (lo, hi) = (*xs.iter().min().unwrap(), *xs.iter().max().unwrap());
            assert!(
                lo > 0 && hi < 47,
                "fit {fit}: runs off the picture: {lo}..{hi}"
            );
            hi - lo + 1
        })
        .collect();
    std::fs::remove_dir_all(&dir).ok();
    assert!(widths[1] >= 24, "fitted: {} of 48 pixels wide", widths[1]);
    assert!(
        widths[1] >= 3 * widths[0],
        "fitted {} against unfitted {} pixels wide",
        widths[1],
        widths[0]
    );
}

#[test]
fn render_certifies_by_default_and_uncertified_draws_the_plain_pencil() {
    // A formula with no flag writes a proved picture and its counts; --uncertified the
    // plain pencil, without counts.
    let dir = std::env::temp_dir().join(format!("fourfold-default-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("d.png");
    let run = |extra: &[&str]| {
        let mut argv = vec![
            "render",
            "(sqrt(x^2 + y^2) - 0.8)^2 + z^2 + w^2 = 0.02",
            "--size",
            "32x32",
            "-o",
            out.to_str().unwrap(),
        ];
        argv.extend(extra);
        let (code, stdout, stderr) = fourfold(&argv);
        assert_eq!(code, Some(0), "{stderr}");
        stdout
    };
    let proved = run(&[]);
    let counts = proved
        .lines()
        .find_map(|l| l.strip_prefix("certified pixels (budget 2048 cells): "))
        .unwrap_or_else(|| panic!("no counts: {proved}"));
    let numbers: Vec<usize> = counts
        .split([' ', ','])
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!(numbers[0] >= 10, "{counts}");
    assert_eq!(numbers[..3].iter().sum::<usize>(), 32 * 32, "{counts}");
    let plain = run(&["--uncertified"]);
    assert!(!plain.contains("certified pixels"), "{plain}");
    std::fs::remove_dir_all(&dir).ok();
}

/// What `fourfold render ARGS…` prints (run in this process), its picture written in `dir`.
fn render_report(dir: &std::path::Path, args: &[&str]) -> String {
    let out = dir.join("report.png");
    let mut argv = vec!["render"];
    argv.extend_from_slice(args);
    argv.extend(["-o", out.to_str().unwrap()]);
    fourfold_cli::render(&parse_render(&argv), &mut |_| {})
        .unwrap_or_else(|f| panic!("{}", f.message))
}

#[test]
fn certified_render_says_why_pixels_stay_undecided() {
    // y = 1/x turned so that the plane x = 0 crosses many pixels' observer planes: a cell
    // holding the pole encloses every value, so those pixels stay undecided and the advice
    // says that a budget cannot help them. The same set written x·y = 1 is continuous.
    let dir = std::env::temp_dir().join(format!("fourfold-pole-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let report = |formula: &str| {
        render_report(
            &dir,
            &[
                formula,
                "--domain=-2,2,-2,2,-2,2,-2,2",
                "--angles",
                "0.5,0.3,0.7,0.2,0.4,0.6",
                "--size",
                "40x40",
                "--rays",
                "4",
                "--certified",
                "--cert-budget",
                "64",
                "--cpu",
            ],
        )
    };
    let pole = report("1/x - y = 0");
    assert!(pole.contains("may have a pole"), "{pole}");
    let smooth = report("x*y - 1 = 0");
    assert!(!smooth.contains("may have a pole"), "{smooth}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_formula_that_only_touches_zero_is_told_so() {
    // (r − 1)^2 and |y| never change sign: the rays' sign changes cannot show their zeros,
    // and no budget proves them, so render says so instead of advising a larger budget.
    // x·|x| changes sign across x = 0, where no box's enclosure does: no note.
    let dir = std::env::temp_dir().join(format!("fourfold-touch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let report = |formula: &str| render_report(&dir, &[formula, "--size", "24x24", "--cpu"]);
    let note = fourfold::render::verdict::TOUCHING_NOTE;
    for touching in ["(x^2 + y^2 + z^2 + w^2 - 1)^2", "|y|", "-(x - 0.3)^2"] {
        let said = report(touching);
        assert!(said.contains(note), "{touching}: {said}");
        assert!(
            !said.contains("a larger --cert-budget"),
            "{touching}: {said}"
        );
    }
    // x·y² changes sign across x = 0 and touches 0 along y = 0; (r − 1)·w² the other way
    // round: the note names the part, and the advice the budget for the rest.
    for partly in ["x*y^2", "(x^2 + y^2 + z^2 - 1)*w^2"] {
        let said = report(partly);
        assert!(
            said.contains("note: F does not change sign across part of M") && !said.contains(note),
            "{partly}: {said}"
        );
    }
    // x, x·y and x³ change sign across faces of the tree's boxes (each box of x is [0, h]
    // or [−h, 0]): no note.
    for crossing in ["x^2 + y^2 + z^2 + w^2 - 1", "x*|x|", "y", "x", "x*y", "x^3"] {
        let said = report(crossing);
        assert!(!said.contains("note: F"), "{crossing}: {said}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

fn animate_args(flags: &[&str]) -> fourfold_cli::AnimateArgs {
    let argv = ["fourfold", "animate"].iter().chain(flags).copied();
    match Cli::try_parse_from(argv).unwrap_or_else(|e| panic!("{flags:?}: {e}")) {
        Cli {
            command: Some(Command::Animate(args)),
        } => args,
        other => panic!("{flags:?} parsed as {other:?}"),
    }
}

/// The frames of an animated GIF, decoded.
fn gif_frames(path: &std::path::Path) -> Vec<image::RgbaImage> {
    use image::AnimationDecoder;
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .map(|f| f.unwrap().into_buffer())
        .collect()
}

/// The frames of an animated PNG, decoded by the png crate.
fn apng_frames(path: &std::path::Path) -> Vec<Vec<u8>> {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let count = reader
        .info()
        .animation_control()
        .expect("an animated PNG")
        .num_frames;
    (0..count)
        .map(|_| {
            let mut buf = vec![0; reader.output_buffer_size().unwrap()];
            let info = reader.next_frame(&mut buf).unwrap();
            buf.truncate(info.buffer_size());
            buf
        })
        .collect()
}

#[test]
fn a_certified_animation_counts_every_frame_s_pixels() {
    let dir = std::env::temp_dir().join(format!("fourfold-cert-anim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("turn.gif").display().to_string();
    let flags = [
        SCENE,
        "--size",
        "24x20",
        "--rays",
        "4",
        "--frames",
        "3",
        "--turn",
        "xw",
        "--certified",
        "--cpu",
        "-o",
        &out,
    ];
    let said = fourfold_cli::animate(&animate_args(&flags), &mut |_| {})
        .unwrap_or_else(|f| panic!("{}", f.message));
    std::fs::remove_dir_all(&dir).ok();
    let counts = said
        .lines()
        .find_map(|l| l.strip_prefix("certified pixels over 3 frames (budget 2048 cells): "))
        .unwrap_or_else(|| panic!("no counts in {said:?}"));
    let numbers: Vec<usize> = counts
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|n| n.parse().ok())
        .take(3)
        .collect();
    assert_eq!(numbers.iter().sum::<usize>(), 3 * 24 * 20, "{counts}");
    assert!(numbers[0] > 0, "no pixel hit: {counts}");
}

/// `render` times its start-up and its file too: the GPU's opening (not on the CPU) and the
/// PNG written, beside the pipeline's stages.
#[test]
fn render_times_opening_the_gpu_and_writing_the_png() {
    let out = std::env::temp_dir().join(format!("fourfold-times-{}.png", std::process::id()));
    let out = out.display().to_string();
    for cpu in [false, true] {
        let mut argv = vec![
            "render",
            "x^2 + y^2 + z^2 + w^2 = 1",
            "--size",
            "16x16",
            "-o",
            &out,
        ];
        if cpu {
            argv.push("--cpu");
        }
        let said = fourfold_cli::render(&parse_render(&argv), &mut |_| {})
            .unwrap_or_else(|f| panic!("{}", f.message));
        let times = said
            .lines()
            .find(|l| l.starts_with("times (ms): "))
            .unwrap();
        assert_eq!(times.contains("GPU opened "), !cpu, "{times}");
        assert!(times.contains(", PNG "), "{times}");
        assert!(
            times.contains("pipeline ") && times.contains("frame "),
            "{times}"
        );
    }
    std::fs::remove_file(&out).ok();
}

#[test]
fn a_swept_parameter_needs_no_value_of_its_own() {
    let out = std::env::temp_dir().join(format!("fourfold-sweep-{}.gif", std::process::id()));
    let out = out.display().to_string();
    let mut warnings = Vec::new();
    let flags = [
        "x^2 + y^2 + z^2 + w^2 = R",
        "--sweep",
        "R=0.5..1.5",
        "--frames",
        "2",
        "--size",
        "16x16",
        "--cpu",
        "-o",
        &out,
    ];
    fourfold_cli::animate(&animate_args(&flags), &mut |w| warnings.push(w.to_string()))
        .unwrap_or_else(|f| panic!("{}", f.message));
    assert!(warnings.is_empty(), "{warnings:?}");
    std::fs::remove_file(&out).ok();
}

#[test]
fn animate_writes_frames_that_differ_in_every_format() {
    let dir = std::env::temp_dir().join(format!("fourfold-animate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |out: &std::path::Path, motion: &[&str]| {
        let out = out.display().to_string();
        let mut flags = vec![SCENE, "--size", "40x32", "--rays", "4", "--frames", "4"];
        flags.extend(motion);
        flags.extend(["-o", &out]);
        fourfold_cli::animate(&animate_args(&flags), &mut |_| {})
            .unwrap_or_else(|f| panic!("{}", f.message))
    };
    let distinct = |frames: &[Vec<u8>]| {
        frames
            .iter()
            .enumerate()
            .all(|(i, a)| frames[..i].iter().all(|b| a != b))
    };

    let gif = dir.join("turn.gif");
    let said = run(&gif, &["--turn", "xw", "--fit"]);
    assert!(said.contains("4 frames"), "{said}");
    let frames: Vec<Vec<u8>> = gif_frames(&gif).into_iter().map(|f| f.into_raw()).collect();
    assert_eq!(frames.len(), 4);
    assert!(distinct(&frames), "the turning frames repeat");

    let apng = dir.join("sweep.png");
    run(&apng, &["--sweep", "R=1.5..2.5"]);
    let frames = apng_frames(&apng);
    assert_eq!(frames.len(), 4);
    assert!(frames.iter().all(|f| f.len() == 40 * 32 * 4));
    assert!(distinct(&frames), "the sweeping frames repeat");

    let slices = dir.join("slices.gif");
    run(&slices, &["--slice-sweep", "-0.5..0.5"]);
    let frames: Vec<Vec<u8>> = gif_frames(&slices)
        .into_iter()
        .map(|f| f.into_raw())
        .collect();
    assert_eq!(frames.len(), 4);
    assert!(distinct(&frames), "the moving slice's frames repeat");

    let folder = dir.join("frames");
    run(&folder, &["--turn", "t3:0.5"]);
    let frames: Vec<Vec<u8>> = (1..=4)
        .map(|k| {
            let path = folder.join(format!("frame-{k:04}.png"));
            image::open(&path).unwrap().to_rgba8().into_raw()
        })
        .collect();
    assert!(distinct(&frames), "the folder's frames repeat");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_animate_flags_are_usage_errors_that_say_what_to_do() {
    let dir = std::env::temp_dir();
    let gif = dir.join("fourfold-bad-animate.gif").display().to_string();
    let cases: &[(&[&str], &str)] = &[
        (&["--turn", "xq"], "--turn: unknown plane 'xq'"),
        (&["--turn", "xw:0"], "--turn: 0 turns"),
        (&["--turn", "xw:fast"], "'fast' is not a number of turns"),
        (&["--sweep", "R=1..1"], "is an empty range"),
        (&["--sweep", "R=1"], "is not a range"),
        (
            &["--sweep", "q=1..2"],
            "the formula has no parameter q (its parameters: R, r)",
        ),
        (
            &["--turn", "xw", "--frames", "0"],
            "--frames 0: between 1 and 10000",
        ),
        (
            &["--turn", "xw", "--fps", "0"],
            "--fps 0: above 0 and at most 100",
        ),
        (
            &["--slice-sweep", "0.5..0.5"],
            "--slice-sweep: 0.5..0.5 is an empty range",
        ),
        (
            &["--slice-sweep", "up"],
            "--slice-sweep: 'up' is not a range",
        ),
        (&[], "nothing moves"),
    ];
    for (flags, expected) in cases {
        let mut argv = vec![SCENE, "-o", &gif];
        argv.extend(*flags);
        let failure = fourfold_cli::animate(&animate_args(&argv), &mut |_| {}).expect_err(expected);
        assert_eq!(failure.code, 2, "{flags:?}: {}", failure.message);
        assert!(
            failure.message.contains(expected),
            "{flags:?}: {:?} does not say {expected:?}",
            failure.message
        );
    }
    // An output that cannot be written, or of an unknown kind, is said before any frame.
    for (out, expected) in [
        (
            "/nonexistent-folder/x.gif",
            "cannot write /nonexistent-folder/x.gif",
        ),
        ("x.jpg", "unknown kind of file '.jpg'"),
    ] {
        let failure = fourfold_cli::animate(
            &animate_args(&[SCENE, "--turn", "xw", "-o", out]),
            &mut |_| {},
        )
        .expect_err(out);
        assert_eq!(failure.code, 2);
        assert!(failure.message.contains(expected), "{}", failure.message);
    }
}

#[test]
fn an_animation_stopped_early_keeps_its_frames_readable() {
    // As after Ctrl-C: a file that was to hold 6 frames gets 2, and says so.
    use fourfold::headless::Output;
    let dir = std::env::temp_dir().join(format!("fourfold-stopped-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let frame = |v: u8| vec![v; 8 * 6 * 4];
    for name in ["stopped.gif", "stopped.png"] {
        let path = dir.join(name);
        let mut writer = Output::from_path(&path)
            .unwrap()
            .open(8, 6, 24.0, 6)
            .unwrap();
        writer.add(frame(40)).unwrap();
        writer.add(frame(200)).unwrap();
        let said = writer.finish().unwrap();
        assert!(said.contains("2 frames"), "{said}");
        let count = if name.ends_with(".gif") {
            gif_frames(&path).len()
        } else {
            apng_frames(&path).len()
        };
        assert_eq!(count, 2, "{name}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn no_adapter_gives_a_clear_message_not_a_panic() {
    // No Vulkan driver can load, and only Vulkan is allowed: wgpu finds no adapter.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fourfold"))
        .args(["render", "x^2 + y^2 + z^2 + w^2 = 1", "--size", "8x8", "-o"])
        .arg(std::env::temp_dir().join("fourfold-no-adapter.png"))
        .env("WGPU_BACKEND", "vulkan")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "rendering without an adapter succeeded"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains("no GPU adapter found"), "{stderr}");
    assert!(stderr.contains("mesa-vulkan-drivers"), "{stderr}");
}

#[test]
fn the_device_takes_the_largest_picture_its_adapter_can_draw() {
    // The CLI's largest (8192x8192) on lavapipe failed on wgpu's default limits.
    let gpu = fourfold::render::Gpu::new().expect("GPU tests need an adapter");
    let limits = gpu.device.limits();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fourfold"))
        .args(["render", "x + y + z + w = 9", "--size", "3000x8"])
        .args(["--max-level", "2", "-o"])
        .arg(std::env::temp_dir().join("fourfold-wide.png"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    if limits.max_texture_dimension_2d >= 3000 {
        assert!(out.status.success(), "{stderr}");
    } else {
        assert!(stderr.contains("over this GPU's limit"), "{stderr}");
    }
}

#[test]
fn constants_outside_a_domain_draw_or_are_refused_with_the_culprit() {
    // The formulas that ended in a raw wgpu error (wgpu's pipeline creation evaluated
    // asin(2), ln(0), an infinite literal... and refused the shader): each is now refused
    // with F's undefined part underlined (exit 2), or drawn on the GPU (exit 0).
    let dir = std::env::temp_dir().join("fourfold-undefined");
    std::fs::create_dir_all(&dir).unwrap();
    let cases = undefined_constants();
    assert_eq!(cases.len(), 12, "the issue's twelve formulas");
    for (formula, culprit) in cases {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_fourfold"))
            .args([
                "render",
                formula,
                "--size",
                "16x12",
                "--max-level",
                "4",
                "-o",
            ])
            .arg(dir.join("picture.png"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        for raw in [
            "Validation Error",
            "Caused by",
            "panicked",
            "internal error",
        ] {
            assert!(!stderr.contains(raw), "{formula}: {stderr}");
        }
        match culprit {
            Some(part) => {
                assert_eq!(out.status.code(), Some(2), "{formula}: {stderr}");
                assert!(
                    stderr.contains("F is undefined everywhere in the domain"),
                    "{formula}: {stderr}"
                );
                assert_eq!(carets(&stderr), part.chars().count(), "{formula}: {stderr}");
            }
            None => assert!(out.status.success(), "{formula}: {stderr}"),
        }
    }
}

#[test]
fn a_formula_may_start_with_a_minus_sign() {
    let args = parse_render(&["render", "-x^2 - y^2 + z + w", "-o", "x.png"]);
    assert_eq!(args.input.formula_or_scene, "-x^2 - y^2 + z + w");
    let args = parse_render(&["render", "--size", "8x8", "-1 + x", "-o", "x.png"]);
    assert_eq!(args.input.formula_or_scene, "-1 + x");
}

#[test]
fn parameter_warnings_reach_the_caller_and_the_binary_s_stderr() {
    // A parameter without a value and a value without a parameter: both are warned of, and
    // the command still succeeds.
    let argv = ["fourfold", "check", "x + a*y", "--param", "b=2"];
    let mut warnings = Vec::new();
    let text = fourfold_cli::run(&Cli::try_parse_from(argv).unwrap(), &mut |w| {
        warnings.push(w.to_string())
    })
    .unwrap_or_else(|f| panic!("{}", f.message));
    assert!(text.starts_with("ok: F = "), "{text}");
    assert_eq!(
        warnings,
        [
            "warning: parameter a has no value; using 1.0 (set it with --param a=VALUE)",
            "warning: parameter b is set but the formula does not use it",
        ]
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fourfold"))
        .args(&argv[1..])
        .output()
        .unwrap();
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().collect::<Vec<_>>(), warnings, "{stderr}");
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("ok: F = "));
}

#[test]
fn a_tiny_constant_f_draws_nothing_on_the_gpu_as_on_the_cpu() {
    // Found by the fuzzer: F is the constant 7e-22, so there is no surface. The march's
    // sign-change test multiplied two such samples; the product, below f32's normals, was
    // flushed to 0 on the GPU and taken for a sign change. (The march's test: the plain
    // pencil; certified, the enclosures of atan2^90 hold 0 and pixels stay undecided.)
    let dir = std::env::temp_dir().join("fourfold-tiny-constant");
    std::fs::create_dir_all(&dir).unwrap();
    let mut pictures = Vec::new();
    for cpu in [false, true] {
        let png = dir.join(format!("cpu-{cpu}.png"));
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_fourfold"));
        command.args([
            "render",
            "atan2(t, 1.52)^90",
            "--size",
            "22x18",
            "--angles",
            "-2.8298,1.3799,-2.8522,-0.2305,3.1545,-0.6284",
            "--max-level",
            "5",
            "--min-level",
            "2",
            "--brute-force",
            "--uncertified",
            "-o",
        ]);
        command.arg(&png);
        if cpu {
            command.arg("--cpu");
        }
        let out = command.output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        pictures.push(image::open(&png).unwrap().to_rgba8());
    }
    let background = pictures[1].get_pixel(0, 0);
    for picture in &pictures {
        let covered = picture.pixels().filter(|p| *p != background).count();
        assert_eq!(covered, 0, "pixels drawn where F is 7e-22 everywhere");
    }
}

#[test]
fn mesh_writes_the_glome_s_slice_as_a_closed_sphere() {
    // The command: the glome's slice at 0.3 is a ball of radius √0.91.
    let dir = std::env::temp_dir().join("fourfold-mesh-cli");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("s.stl");
    let _ = std::fs::remove_file(&path);
    let glome = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/scenes/glome.toml"
    );
    let (code, stdout, stderr) = fourfold(&[
        "mesh",
        glome,
        "--slice",
        "0.3",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    let bytes = std::fs::read(&path).unwrap();
    let triangles = u32::from_le_bytes(bytes[80..84].try_into().unwrap());
    assert!(triangles > 1000 && bytes.len() == 84 + 50 * triangles as usize);
    assert!(
        stdout.contains(&format!("{triangles} triangles")),
        "{stdout}"
    );
    assert!(stdout.contains("closed"), "{stdout}");
    let volume: f64 = stdout
        .split("volume ")
        .nth(1)
        .and_then(|v| v.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no volume in {stdout}"));
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.91f64.powf(1.5);
    assert!(
        (volume - exact).abs() / exact < 0.005,
        "{volume} against {exact}"
    );
    // In millimetres, the longest side is the size asked for.
    let mm = dir.join("s.obj");
    let (code, stdout, stderr) = fourfold(&[
        "mesh",
        glome,
        "--slice",
        "0.3",
        "--units",
        "mm",
        "--size",
        "80",
        "-o",
        mm.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stdout.contains("80.0000 ×") || stdout.contains("× 80.0000"),
        "{stdout}"
    );
}

#[test]
fn bad_mesh_requests_say_what_to_do_and_write_nothing() {
    let dir = std::env::temp_dir().join("fourfold-mesh-cli-bad");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("m.stl");
    let out = out.to_str().unwrap();
    let glome = "x^2 + y^2 + z^2 + w^2 = 1";
    for (args, said) in [
        (vec!["--slice", "3"], "misses the domain"),
        (vec!["--slice", "1.5"], "does not cut M inside the domain"),
        (vec![], "give --slice C"),
        (vec!["--slice", "0", "--max-level", "0"], "--max-level 0"),
        (vec!["--slice", "0", "--tolerance", "0"], "--tolerance 0"),
        (
            vec!["--slice", "0", "--units", "cm"],
            "expected model or mm",
        ),
        (vec!["--slice", "0", "--size", "80"], "with --units mm"),
        (
            vec!["--slice", "0", "--units", "mm", "--size", "-1"],
            "above 0",
        ),
        (vec!["--slice", "nan"], "a finite number"),
    ] {
        let _ = std::fs::remove_file(out);
        let mut argv = vec!["mesh", glome, "-o", out];
        argv.extend(args.iter());
        let (code, _, stderr) = fourfold(&argv);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(said), "{args:?}: {stderr}");
        assert!(!std::path::Path::new(out).exists(), "{args:?} wrote a file");
    }
    let (code, _, stderr) = fourfold(&["mesh", glome, "--slice", "0", "-o", "m.gltf"]);
    assert_eq!(code, Some(2));
    assert!(
        stderr.contains("write a .stl, .obj, .ply or .glb file"),
        "{stderr}"
    );
    // A folder that does not exist, said before the mesh is made (at level 9, seconds).
    let missing = dir.join("no-such-folder").join("m.stl");
    let argv = ["mesh", glome, "--slice", "0", "--max-level", "9", "-o"];
    let (code, _, stderr) = fourfold(&[&argv[..], &[missing.to_str().unwrap()]].concat());
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("there is no folder"), "{stderr}");
}

/// `render` of a slice or a slab builds its tree within the slice's hyperplane or the
/// slab's band, and says so; a projection's, and a slice framed with `--fit` (which frames
/// all of M), cover the domain, as `fourfold tree` does.
#[test]
fn render_builds_a_slice_s_tree_within_its_hyperplane() {
    let out = std::env::temp_dir().join(format!("fourfold-cli-within-{}.png", std::process::id()));
    let glome = "x^2 + y^2 + z^2 + w^2 = 1";
    // The tree's node count, its line, and all that `render` printed.
    let rendered = |flags: &[&str]| {
        let mut args = vec!["render", glome, "--size", "48x36", "--cpu", "-o"];
        args.push(out.to_str().unwrap());
        args.extend_from_slice(flags);
        let (code, stdout, stderr) = fourfold(&args);
        assert_eq!(code, Some(0), "{flags:?}: {stderr}");
        let line = stdout
            .lines()
            .find(|l| l.starts_with("tree: "))
            .unwrap_or_default()
            .to_string();
        let nodes: u64 = line["tree: ".len()..]
            .split(' ')
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{flags:?}: no node count in {line:?}"));
        (nodes, line, stdout)
    };
    let tree_line = |flags: &[&str]| {
        let (nodes, line, _) = rendered(flags);
        (nodes, line)
    };
    let (whole, line) = tree_line(&[]);
    assert!(!line.contains("within"), "{line}");
    let (fitted, line) = tree_line(&["--slice", "0.3", "--fit"]);
    assert!(
        !line.contains("within") && fitted == whole,
        "{line}: {whole} nodes projected"
    );
    for (flags, said) in [
        (&["--slice", "0.3"][..], "(within the slice's hyperplane)"),
        (
            &["--slice", "-0.5", "--angles", "0.3,0.5,0.7,0.1,0.2,0.3"],
            "(within the slice's hyperplane)",
        ),
        (&["--slab", "0.2,0.1"], "(within the slab)"),
    ] {
        let (nodes, line) = tree_line(flags);
        assert!(line.contains(said), "{flags:?}: {line}");
        assert!(
            0 < nodes && nodes * 2 < whole,
            "{flags:?}: {nodes} nodes, {whole} in all"
        );
    }
    // A slice that misses M: nothing to build, and render says where to look instead.
    let (nodes, _, stdout) = rendered(&["--slice", "1.4"]);
    assert!(
        nodes == 0 && stdout.contains("no surface in this slice"),
        "{stdout}"
    );
    let _ = std::fs::remove_file(&out);
}

/// A small slice is drawn on the CPU unless `--gpu` asks for the GPU, and `render` says
/// which; a projection, a slab and a slice beyond 2^17 pixels a thread stay on the GPU.
#[test]
fn render_draws_a_small_slice_on_the_cpu_and_says_so() {
    let out = std::env::temp_dir().join(format!("fourfold-cli-device-{}.png", std::process::id()));
    let glome = "x^2 + y^2 + z^2 + w^2 = 1";
    // Just over the CPU's share (2^17 pixels a thread), as a picture 2^10 wide.
    let rows = fourfold::render::cpu_slice_pixels().div_ceil(1024) + 1;
    let beyond = format!("1024x{rows}");
    let drawn_by = |flags: &[&str]| {
        let mut args = vec!["render", glome, "-o", out.to_str().unwrap()];
        args.extend_from_slice(flags);
        let (code, stdout, stderr) = fourfold(&args);
        assert_eq!(code, Some(0), "{flags:?}: {stderr}");
        let adapter = stdout.lines().next().unwrap_or_default().to_string();
        let said = stdout.contains("drawn on the CPU: a slice of up to");
        (adapter, said)
    };
    let on_cpu = "adapter: CPU reference renderer".to_string();
    assert_eq!(
        drawn_by(&["--slice", "0.2", "--size", "64x48"]),
        (on_cpu.clone(), true)
    );
    assert_eq!(
        drawn_by(&["--slice", "0.2", "--size", "64x48", "--cpu"]),
        (on_cpu.clone(), false)
    );
    for flags in [
        &["--slice", "0.2", "--size", "64x48", "--gpu"][..],
        &["--size", "64x48"],
        &["--slab", "0.2,0.1", "--size", "64x48"],
        &["--slice", "0.2", "--size", &beyond, "--uncertified"],
    ] {
        let (adapter, said) = drawn_by(flags);
        assert!(adapter != on_cpu && !said, "{flags:?}: {adapter}");
    }
    let (code, _, stderr) = fourfold(&["render", glome, "--cpu", "--gpu", "-o", "x.png"]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("--gpu") && stderr.contains("cannot be used with"),
        "{stderr}"
    );
    let _ = std::fs::remove_file(&out);
}

/// `fourfold render` keeps its pipelines between runs in FOURFOLD_CACHE_DIR, says so among
/// the stages, warns about a broken cache file and still writes the picture; `off` keeps
/// none.
#[test]
fn render_keeps_pipelines_between_runs_and_warns_about_a_broken_cache() {
    let tag = format!("fourfold-cli-pcache-{}", std::process::id());
    let dir = std::env::temp_dir().join(&tag);
    let out = std::env::temp_dir().join(format!("{tag}.png"));
    let _ = std::fs::remove_dir_all(&dir);
    let run = |cache: &std::ffi::OsStr| {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_fourfold"))
            .args([
                "render",
                "x^2 + y^2 + z^2 + w^2 = 1",
                "--slice",
                "0.2",
                "--gpu",
            ])
            .args(["--size", "24x16", "-o"])
            .arg(&out)
            .env("FOURFOLD_CACHE_DIR", cache)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&output.stdout).to_string()
            + &String::from_utf8_lossy(&output.stderr);
        assert!(output.status.success(), "{text}");
        assert!(out.exists(), "{text}");
        std::fs::remove_file(&out).unwrap();
        text
    };
    let first = run(dir.as_os_str());
    if !first.contains("(pipeline cache: new)") {
        eprintln!("skipped: this adapter keeps no pipeline cache:\n{first}");
        return;
    }
    let second = run(dir.as_os_str());
    assert!(second.contains("bytes loaded)"), "{second}");
    for entry in std::fs::read_dir(&dir).unwrap() {
        std::fs::write(entry.unwrap().path(), b"not a cache").unwrap();
    }
    let broken = run(dir.as_os_str());
    assert!(
        broken.contains("warning: ignored the pipeline cache")
            && broken.contains("(not a fourfold pipeline cache); it is written anew"),
        "{broken}"
    );
    assert!(run(dir.as_os_str()).contains("bytes loaded)"));
    let off = run(std::ffi::OsStr::new("off"));
    assert!(!off.contains("pipeline cache"), "{off}");
    std::fs::remove_dir_all(&dir).unwrap();
}
