//! Running a formula case through every path a user has: `fourfold check`, `wgsl`,
//! `critical` and `render` (on the CPU twin, and on the GPU where the case says), in
//! process, through the command line's own parser; and beneath them wgpu's own evaluation
//! of the shader's pipeline constants and its SPIR-V output, which need no GPU. A case
//! passes when every path draws or refuses it with the same clear message.

use std::path::Path;

use clap::Parser as _;
use fourfold::render::Program;
use fourfold_cli::Cli;

use crate::cases::{FormulaCase, Mode};

/// Text that only a raw wgpu or naga error, or a panic, prints: never a user's message.
const RAW_MARKERS: &[&str] = &[
    "Validation Error",
    "Caused by",
    "In Device::",
    "Pipeline constant error",
    "Shader validation error",
    "panicked at",
    "internal error",
];

/// The most pixels of a picture the GPU and the CPU twin may see differently (one covered,
/// the other background): f32 on the GPU against f64 on the CPU moves the odd root across a
/// pixel's edge, where a formula has thin parts or a huge slope.
pub const MAX_COVERAGE_DISAGREEMENT: f64 = 0.1;

/// Why a GPU's picture was not compared: trigonometry beyond [`TRIG_ARGUMENT_BOUND`],
/// values beyond [`GPU_RANGE_BOUND`] or nearer 0 than [`GPU_PRECISION_BOUND`], pixels the
/// driver cut short, or an F that only touches 0, on all of M or a part (render's note:
/// what shows of it is where f32's rounding lands on an exact zero, which differs between
/// the GPU and the twin).
pub const UNCOMPARED_TRIG: &str = "sin, cos or tan of large arguments";
pub const UNCOMPARED_RANGE: &str = "values beyond the GPU's intervals' range or precision";
pub const UNCOMPARED_CUT: &str = "pixels cut short by the driver";
pub const UNCOMPARED_TOUCHING: &str = "F touches 0 without changing sign";

/// Beyond this, the GPU's sin, cos and tan are not the twin's to compare: WGSL bounds their
/// error on [−π, π] only, and each implementation reduces a larger argument with its own
/// precision (`cos(1e30 xyz)` is noise on either, a different noise).
pub const TRIG_ARGUMENT_BOUND: f64 = 1e4;

/// Beyond this (2^61), a bound of the GPU's f32 intervals stands for ±∞, and a product with
/// such an operand is the whole line (docs/method.md, the GPU's intervals): where F or
/// ∇F gets there (`1e300 z`, `y exp(100 x)`), the GPU may leave undecided what the twin's
/// f64 intervals prove.
pub const GPU_RANGE_BOUND: f64 = 2305843009213693952.0;

/// Below this (2^-125) a bound of the GPU's f32 intervals may have been a flushed
/// subnormal, and is widened past 0: a value of F or ∇F this close to 0 but not 0
/// (`1e-320`, which f32 rounds to 0) may be undecided on the GPU where the twin proves it.
pub const GPU_PRECISION_BOUND: f64 = 2.350_988_701_644_575e-38;

/// What a case did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Verdict {
    /// Every path drew it.
    Drew,
    /// Every path drew it, but the GPU's picture was not compared with the twin's: why
    /// ([`UNCOMPARED_TRIG`], [`UNCOMPARED_CUT`]).
    DrewUncompared(&'static str),
    /// Every path refused it, with this message (its first line).
    Refused(String),
}

/// The exit code and text of `fourfold ARGS…`, run in this process: what it prints, then
/// its warnings (which are held to the same standard).
pub fn cli(args: &[String]) -> (i32, String) {
    let argv = std::iter::once("fourfold".to_string()).chain(args.iter().cloned());
    let parsed = match Cli::try_parse_from(argv) {
        Err(e) => return (e.exit_code(), e.to_string()),
        Ok(parsed) => parsed,
    };
    let mut warnings = String::new();
    let (code, mut text) = match fourfold_cli::run(&parsed, &mut |w| {
        warnings.push('\n');
        warnings.push_str(w);
    }) {
        Ok(text) => (0, text),
        Err(failure) => (failure.code, failure.message),
    };
    text.push_str(&warnings);
    (code, text)
}

/// Fails where `text` is raw: a GPU compiler's, naga's or a panic's words.
fn clean(what: &str, code: i32, text: &str) -> Result<(), String> {
    if let Some(marker) = RAW_MARKERS.iter().find(|m| text.contains(*m)) {
        return Err(format!("{what}: raw text ({marker:?}) in:\n{text}"));
    }
    if code != 0 && code != 2 {
        return Err(format!("{what}: exit code {code}:\n{text}"));
    }
    Ok(())
}

/// The first line of a refusal: what every path must agree on.
fn headline(text: &str) -> &str {
    text.lines().next().unwrap_or("").trim()
}

/// Runs `case` through every path, writing pictures under `dir`.
pub fn check_formula(case: &FormulaCase, dir: &Path) -> Result<Verdict, String> {
    let text = case.text();
    let mut input = vec![text.clone()];
    input.extend(case.param_args());
    let with = |command: &str| {
        let mut args = vec![command.to_string()];
        args.extend(input.iter().cloned());
        args
    };
    let (checked, said) = cli(&with("check"));
    clean("check", checked, &said)?;
    let (exported, wgsl) = cli(&with("wgsl"));
    clean("wgsl", exported, &wgsl)?;
    if exported != checked {
        return Err(format!(
            "check exits {checked}, wgsl {exported}:\n{said}\n{wgsl}"
        ));
    }
    if checked == 0 {
        pipeline_constants(&text, case)?;
        interpreter_program(&text)?;
    }
    // The slice sweep's critical values: searched (a small budget: any formula's search
    // ends, proved or undecided) or refused as check refuses.
    let mut critical_args = with("critical");
    let angles: Vec<String> = case.angles.iter().map(|a| format!("{a:.4}")).collect();
    critical_args.extend(
        [
            "--angles",
            &angles.join(","),
            "--max-level",
            "4",
            "--budget",
            "4000",
            "--json",
        ]
        .map(String::from),
    );
    let (critical, critical_said) = cli(&critical_args);
    clean("critical", critical, &critical_said)?;
    if critical != checked || (checked == 2 && headline(&critical_said) != headline(&said)) {
        return Err(format!(
            "check exits {checked}, critical {critical}:\n{said}\n{critical_said}"
        ));
    }
    let cpu_png = dir.join("cpu.png");
    let (cpu, cpu_said) = cli(&case.render_args(&cpu_png, true));
    clean("render --cpu", cpu, &cpu_said)?;
    if checked == 2 && (cpu != 2 || headline(&cpu_said) != headline(&said)) {
        return Err(format!(
            "check refuses it, render --cpu exits {cpu}:\n{said}\n{cpu_said}"
        ));
    }
    if case.gpu {
        let gpu_png = dir.join("gpu.png");
        let (gpu, gpu_said) = cli(&case.render_args(&gpu_png, false));
        clean("render", gpu, &gpu_said)?;
        if gpu != cpu || (gpu == 2 && headline(&gpu_said) != headline(&cpu_said)) {
            return Err(format!(
                "render exits {gpu}, render --cpu {cpu}:\n{gpu_said}\n{cpu_said}"
            ));
        }
        if gpu == 0 {
            // (The pixels the driver cut short miss what they did not reach: the render
            // warns of them, and they are not the twin's to match.)
            if gpu_said.contains(fourfold_cli::CUT_WARNING) {
                return Ok(Verdict::DrewUncompared(UNCOMPARED_CUT));
            }
            if gpu_said.contains(fourfold::render::verdict::TOUCHING_OPENING) {
                return Ok(Verdict::DrewUncompared(UNCOMPARED_TOUCHING));
            }
            let compiled = scene_of(case);
            if compiled.as_ref().is_some_and(precision_unspecified) {
                return Ok(Verdict::DrewUncompared(UNCOMPARED_TRIG));
            }
            if let Err(why) = compare(&gpu_png, &cpu_png) {
                if compiled.as_ref().is_some_and(beyond_gpu_range) {
                    return Ok(Verdict::DrewUncompared(UNCOMPARED_RANGE));
                }
                return Err(why);
            }
        }
    }
    Ok(if cpu == 0 {
        Verdict::Drew
    } else {
        Verdict::Refused(headline(&cpu_said).to_string())
    })
}

/// What wgpu does to the shader when it makes a pipeline, without a GPU: evaluate the
/// pipeline constants (where the formulas were refused) and write SPIR-V, for the
/// constants of the case's mode and for the pipeline every caster makes first.
fn pipeline_constants(text: &str, case: &FormulaCase) -> Result<(), String> {
    let program = Program::new(text).map_err(|e| format!("check accepts it, but: {e}"))?;
    let module = &program.shader.module;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(module)
    .map_err(|e| format!("naga: {e}"))?;
    let section = match case.mode {
        Mode::Slab(..) => 1,
        Mode::Slice(_) => 2,
        _ => 0,
    };
    use fourfold::render::gpu::{Mode as Boxes, Variant};
    let boxes = if case.mode == Mode::BruteForce {
        Boxes::BruteForce
    } else {
        Boxes::Tiles
    };
    // (Every mode but the plain one draws certified, as the command line does by default.)
    let certified = case.mode != Mode::Plain;
    for variant in [
        Variant::first(),
        Variant::new(boxes, 16, true, section, certified),
    ] {
        let values = variant.constants();
        let constants = values.iter().map(|&(n, v)| (n.to_string(), v)).collect();
        let stage = naga::ShaderStage::Fragment;
        // (Each mode, plain or certified, draws with its own entry point.)
        let entry = variant.entry_point();
        let (module, info) = naga::back::pipeline_constants::process_overrides(
            module,
            &info,
            Some((stage, entry)),
            &constants,
        )
        .map_err(|e| format!("pipeline constants {values:?}: {e}"))?;
        let options = naga::back::spv::PipelineOptions {
            shader_stage: stage,
            entry_point: entry.into(),
        };
        naga::back::spv::write_vec(&module, &info, &Default::default(), Some(&options))
            .map_err(|e| format!("SPIR-V {values:?}: {e}"))?;
    }
    Ok(())
}

/// The interpreting shader's program for the formula (what the viewer draws a new formula
/// with on a GPU while its own shader compiles): made, or refused for its registers, and
/// every tape's range and every register within the program and the interpreter.
fn interpreter_program(text: &str) -> Result<(), String> {
    use fourfold::render::shader::{InterpretError, REGISTERS, program};
    let formula = Program::new(text)
        .map_err(|e| format!("check accepts it, but: {e}"))?
        .formula;
    let words = match program(&formula) {
        Ok(words) => words,
        Err(InterpretError::TooManyRegisters(n)) if n > REGISTERS => return Ok(()),
        Err(e) => return Err(format!("interpreter: {e}")),
    };
    let registers = REGISTERS as u32;
    for t in 0..3 {
        let [start, end, out, _] = words[2 * t];
        let outs = words[2 * t + 1];
        if start < 6 || start > end || end as usize > words.len() {
            return Err(format!(
                "interpreter: tape {t} runs {start}..{end} of {}",
                words.len()
            ));
        }
        if out >= registers || outs.iter().any(|&r| r >= registers) {
            return Err(format!("interpreter: tape {t}'s outputs {out}, {outs:?}"));
        }
    }
    // Operation codes 0-2 read no register (a constant's bits, an index).
    let bad = words[6..].iter().find(|&&[code, a, b, out]| {
        out >= registers || (code > 2 && (a >= registers || b >= registers))
    });
    match bad {
        Some(word) => Err(format!("interpreter: instruction {word:?}")),
        None => Ok(()),
    }
}

/// A case's scene and its compiled formula.
type Compiled = (fourfold::scene::Scene, fourfold::CompiledFormula);

/// The scene and compiled formula `case` renders, as the command line reads them.
fn scene_of(case: &FormulaCase) -> Option<Compiled> {
    let args = case.render_args(Path::new("unused.png"), true);
    let argv = std::iter::once("fourfold".to_string()).chain(args);
    let Ok(Cli {
        command: Some(fourfold_cli::Command::Render(render)),
    }) = Cli::try_parse_from(argv)
    else {
        return None;
    };
    let scene = fourfold_cli::render_scene_of(&render).ok()?;
    let formula = fourfold::CompiledFormula::compile(&scene.formula).ok()?;
    Some((scene, formula))
}

/// The bounds of the enclosures over the domain (interval evaluations over the whole
/// domain) of the nodes of F and ∇F that `of` picks, as magnitudes.
fn magnitudes(
    (scene, formula): &Compiled,
    of: impl Fn(usize, &fourfold::expr::Node) -> Option<fourfold::expr::NodeId>,
) -> Vec<f64> {
    use fourfold::eval::{IntervalEvaluator, Tape};
    let graph = &formula.graph;
    let mut roots = vec![formula.f];
    roots.extend(formula.gradient);
    let reached = graph.reachable(&roots);
    let nodes: Vec<_> = graph
        .nodes()
        .iter()
        .enumerate()
        .zip(reached)
        .filter(|&(_, reached)| reached)
        .filter_map(|((i, node), _)| of(i, node))
        .collect();
    if nodes.is_empty() {
        return Vec::new();
    }
    let tape = Tape::new(graph, &nodes);
    let params = scene.param_values(&formula.param_names());
    let mut out = vec![fourfold::interval::Interval::EMPTY; nodes.len()];
    IntervalEvaluator::new().eval_into(&tape, &scene.domain.to_box(), &params, &mut out);
    out.iter()
        .filter(|v| !v.is_empty())
        .flat_map(|v| [v.lo().abs(), v.hi().abs()])
        .collect()
}

/// Whether the GPU's picture of a case (its `compiled` scene and formula) is not the
/// twin's to compare: a sin, cos or tan whose argument reaches beyond
/// ±[`TRIG_ARGUMENT_BOUND`] in the domain (an enclosure over the whole domain, so a formula
/// may be left uncompared that never gets there).
fn precision_unspecified(compiled: &Compiled) -> bool {
    use fourfold::expr::{Node, UnaryOp};
    let argument = |_, node: &Node| match *node {
        Node::Unary(UnaryOp::Sin | UnaryOp::Cos | UnaryOp::Tan, a) => Some(a),
        _ => None,
    };
    magnitudes(compiled, argument)
        .into_iter()
        .any(|b| b > TRIG_ARGUMENT_BOUND)
}

/// Whether a difference between the GPU's picture of a case (its `compiled` scene and
/// formula) and the twin's may be the GPU's intervals' range: a finite value of F or ∇F
/// beyond ±[`GPU_RANGE_BOUND`] over the domain (a pole's infinite bound is ±∞ to both), or
/// a bound other than 0 within ±[`GPU_PRECISION_BOUND`] of it (`1e-320` is 0 to the GPU).
/// Asked only of pictures that differ, so that every other one is still compared.
fn beyond_gpu_range(compiled: &Compiled) -> bool {
    let every = |i: usize, _: &_| Some(fourfold::expr::NodeId(i as u32));
    magnitudes(compiled, every)
        .into_iter()
        .any(|b| b.is_finite() && (b > GPU_RANGE_BOUND || (b > 0.0 && b < GPU_PRECISION_BOUND)))
}

/// The GPU's picture and the CPU twin's cover the same pixels, but for a few.
fn compare(gpu: &Path, cpu: &Path) -> Result<(), String> {
    let read = |p: &Path| {
        image::open(p)
            .map(|i| i.to_rgba8())
            .map_err(|e| format!("reading {}: {e}", p.display()))
    };
    let (a, b) = (read(gpu)?, read(cpu)?);
    if a.dimensions() != b.dimensions() {
        return Err(format!(
            "GPU picture {:?}, CPU {:?}",
            a.dimensions(),
            b.dimensions()
        ));
    }
    let background = fourfold::scene::RenderSettings::default().background.0;
    let covered = |p: &image::Rgba<u8>| p.0[..3] != background;
    let differ = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| covered(p) != covered(q))
        .count();
    let share = differ as f64 / f64::from(a.width() * a.height());
    if share > MAX_COVERAGE_DISAGREEMENT {
        return Err(format!(
            "the GPU and the CPU twin disagree on {:.0}% of the pixels",
            share * 100.0
        ));
    }
    Ok(())
}
