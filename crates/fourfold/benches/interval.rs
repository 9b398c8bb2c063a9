//! Interval-evaluation throughput: `cargo bench -p fourfold --bench interval`.
//!
//! Boxes per second, on one thread, for F alone and for F + ∇F (five outputs), on the chapter's
//! formula, the glome, the tiger (square roots) and a trigonometric formula, over the same
//! boxes: the 16 children of cells of a 32⁴ grid of the scene's domain (so 1/64 of the domain
//! per axis), cells drawn by a fixed pseudo-random sequence. Ours is the rigorous f64
//! evaluator with outward rounding, as the tree build calls it: the 16 children of a box in one
//! pass ([`BatchEvaluator`]), and for comparison one box per call ([`IntervalEvaluator`]). The
//! peer is the `fidget` crate's f32 interval evaluator (VM interpreter and JIT), which takes
//! one box per call, fed the same expression graph (our F and our symbolic gradient,
//! translated node for node, parameters as constants). Everything is measured in one run and
//! printed as a table with ratios; each figure is the best of at least 0.3 s of passes.

use std::hint::black_box;
use std::time::Instant;

use fidget::context::{Context, Node as FNode};

#[path = "common/fidget_graph.rs"]
mod fidget_graph;
use fidget::eval::{Function, MathFunction, TracingEvaluator};
use fidget::types::Interval as FInterval;
use fidget::var::Var;

use fourfold::CompiledFormula;

use fourfold::eval::{BatchEvaluator, Box4, Interval, IntervalEvaluator, LANES, Tape};
use fourfold::scene::Scene;

const BOXES: usize = 200_000;
const PASSES: usize = 5;

/// The trigonometric formula, on the default domain.
const TRIG: &str = "sin(3x)cos(3y) + sin(3z)cos(3w) - 0.2";

/// The 16 children of cells of the 32⁴ grid over the scene's domain, the cells drawn by a
/// 64-bit LCG: boxes of the 64⁴ grid, in the groups the tree build evaluates together.
fn boxes(scene: &Scene) -> Vec<Box4> {
    let axes = [
        &scene.domain.x,
        &scene.domain.y,
        &scene.domain.z,
        &scene.domain.w,
    ];
    let mut state = 0x9E37_79B9_7F4A_7C15_u64;
    let mut out = Vec::with_capacity(BOXES);
    while out.len() < BOXES {
        let parent: [u64; 4] = std::array::from_fn(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            state >> 59 // 0..32
        });
        for k in 0..LANES as u64 {
            out.push(std::array::from_fn(|a| {
                let cell = (2 * parent[a] + ((k >> a) & 1)) as f64;
                let step = (axes[a].hi - axes[a].lo) / 64.0;
                Interval::new(axes[a].lo + cell * step, axes[a].lo + (cell + 1.0) * step)
            }));
        }
    }
    out
}

/// The best rate of at least PASSES passes and 0.3 s of them (so that the first row is not
/// measured on a cold machine).
fn best_rate(mut pass: impl FnMut() -> f64) -> f64 {
    let mut best = 0.0_f64;
    let mut sink = 0.0;
    let started = Instant::now();
    let mut passes = 0;
    while passes < PASSES || started.elapsed().as_secs_f64() < 0.3 {
        let t = Instant::now();
        sink += pass();
        best = best.max(BOXES as f64 / t.elapsed().as_secs_f64());
        passes += 1;
    }
    black_box(sink);
    best
}

/// Ours, the 16 children of a box per pass.
fn ours(tape: &Tape, params: &[f64], bx: &[Box4]) -> f64 {
    let mut eval = BatchEvaluator::new();
    best_rate(|| {
        let mut acc = 0.0;
        for group in bx.chunks(LANES) {
            eval.eval(tape, group, params);
            for lane in 0..group.len() {
                acc += eval.output(tape, 0, lane).lo();
            }
        }
        acc
    })
}

/// Ours, one box per call.
fn ours_one(tape: &Tape, params: &[f64], bx: &[Box4]) -> f64 {
    let mut eval = IntervalEvaluator::new();
    let mut out = vec![Interval::EMPTY; tape.outputs().len()];
    best_rate(|| {
        let mut acc = 0.0;
        for b in bx {
            eval.eval_into(tape, b, params, &mut out);
            acc += out[0].lo();
        }
        acc
    })
}

fn peer<F: Function + MathFunction>(
    ctx: &Context,
    outs: &[FNode],
    w_var: Var,
    bx: &[Box4],
) -> Result<f64, String> {
    let func = F::new(ctx, outs).map_err(|e| e.to_string())?;
    if std::env::var_os("FOURFOLD_BENCH_SIZES").is_some() {
        eprintln!("fidget function size: {}", func.size());
    }
    let tape = func.interval_tape(Default::default());
    let mut eval = F::new_interval_eval();
    let vars = fidget::eval::Tape::vars(&tape);
    let slots: Vec<Option<usize>> = [Var::X, Var::Y, Var::Z, w_var]
        .iter()
        .map(|v| vars.get(v))
        .collect();
    let n = vars.len();
    let boxes: Vec<Vec<FInterval>> = bx
        .iter()
        .map(|b| {
            let mut v = vec![FInterval::from(0.0); n];
            for (axis, slot) in slots.iter().enumerate() {
                if let Some(s) = slot {
                    v[*s] = FInterval::new(b[axis].lo() as f32, b[axis].hi() as f32);
                }
            }
            v
        })
        .collect();
    let mut error = None;
    let rate = best_rate(|| {
        let mut acc = 0.0;
        for v in &boxes {
            match eval.eval(&tape, v) {
                Ok((out, _)) => acc += out[0].lower() as f64,
                Err(e) => error = Some(e.to_string()),
            }
        }
        acc
    });
    match error {
        Some(e) => Err(e),
        None => Ok(rate),
    }
}

fn main() {
    println!(
        "{BOXES} boxes (1/64 of the domain per axis, 16 children of a box at a time), one thread, best of {PASSES} or more passes (0.3 s); Mboxes/s\n"
    );
    println!(
        "scene         outputs   ours (16 per pass)   ours (1 per call)   fidget VM   fidget JIT   ours/VM   ours/JIT"
    );
    for name in ["fig-3-9-left", "glome", "tiger", "trig"] {
        let scene = match name {
            "trig" => Scene::from_formula(TRIG),
            name => Scene::example(name).unwrap(),
        };
        let f = CompiledFormula::compile(&scene.formula).unwrap();
        let params = scene.param_values(&f.param_names());
        let bx = boxes(&scene);
        let grad = [
            f.f,
            f.gradient[0],
            f.gradient[1],
            f.gradient[2],
            f.gradient[3],
        ];
        for (label, tape, roots) in [
            ("F", &f.tape_f, &[f.f][..]),
            ("F+grad", &f.tape_all, &grad[..]),
        ] {
            let mine = ours(tape, &params, &bx);
            let one = ours_one(tape, &params, &bx);
            if std::env::var_os("FOURFOLD_BENCH_SIZES").is_some() {
                eprintln!(
                    "{name} {label}: our tape {} instructions ({} per box)",
                    tape.len(),
                    tape.len() - tape.uniform_len()
                );
            }
            let ours = format!(
                "{name:<13} {label:<9} {:>12.2} {:>19.2}",
                mine / 1e6,
                one / 1e6
            );
            let mut ctx = Context::new();
            let w_var = Var::new();
            let axes = [ctx.x(), ctx.y(), ctx.z(), ctx.var(w_var)];
            let outs = match fidget_graph::translate(&mut ctx, &f, &params, roots, axes) {
                Ok(t) => t,
                Err(e) => {
                    println!("{ours}   (fidget: {e})");
                    continue;
                }
            };
            let vm = peer::<fidget::vm::VmFunction>(&ctx, &outs, w_var, &bx);
            let jit = peer::<fidget::jit::JitFunction>(&ctx, &outs, w_var, &bx);
            match (vm, jit) {
                (Ok(vm), Ok(jit)) => println!(
                    "{ours} {:>11.2} {:>12.2} {:>9.2}x {:>9.2}x",
                    vm / 1e6,
                    jit / 1e6,
                    mine / vm,
                    mine / jit
                ),
                (vm, jit) => println!("{ours}  fidget: {vm:?} {jit:?}"),
            }
        }
    }
}
