//! The evaluators' one conformance suite: every implementation of `Evaluator` over boxes (the
//! interval evaluator, the batch evaluator, the GPU's enclosures) holds the point evaluator's
//! values at the corners, the centre and random points of every box, on random formulas over
//! the whole language and boxes of every scale; the batch evaluator gives bit for bit the
//! one-box evaluator's enclosures and continuity; and every evaluator keeps the contract's
//! preconditions.

mod common;

use std::f64::consts::FRAC_PI_2;

use common::{Rng, example_scenes};
use fourfold::CompiledFormula;
use fourfold::eval::{
    BatchEvaluator, Box4, Evaluator, Interval, IntervalEvaluator, LANES, PointEvaluator, Tape,
};
use fourfold::headless::probe::GpuEnclosures;
use fourfold::render::Gpu;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, TestRng, TestRunner};

/// Random formulas over x, y, z, w, two parameters and every operation of the language,
/// each defined somewhere.
fn formula_text() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        Just("x".to_string()),
        Just("y".to_string()),
        Just("z".to_string()),
        Just("w".to_string()),
        Just("a".to_string()),
        (-30i32..30).prop_map(|n| format!("{}", n as f64 / 4.0)),
    ];
    leaf.prop_recursive(5, 40, 2, |inner| {
        let unary = [
            "-", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "exp", "ln",
            "sqrt", "cbrt", "abs", "sign", "step",
        ];
        let binary = ["+", "-", "*", "/", "^", "min", "max", "pow", "atan2"];
        prop_oneof![
            (prop::sample::select(unary.to_vec()), inner.clone()).prop_map(|(f, a)| {
                if f == "-" {
                    format!("-({a})")
                } else {
                    format!("{f}({a})")
                }
            }),
            (
                prop::sample::select(binary.to_vec()),
                inner.clone(),
                inner.clone()
            )
                .prop_map(|(op, a, b)| match op {
                    "min" | "max" | "pow" | "atan2" => format!("{op}({a}, {b})"),
                    _ => format!("({a}) {op} ({b})"),
                }),
            (inner.clone(), -4i32..6).prop_map(|(a, n)| format!("({a})^{n}")),
        ]
    })
    // One whose constants fold to an undefined F (ln(-2) + x) is refused when compiled:
    // there is nothing to evaluate.
    .prop_filter("F is defined somewhere", |t| {
        CompiledFormula::compile(t).is_ok()
    })
}

/// A box of moderate size anywhere near the origin.
fn a_box() -> impl Strategy<Value = Box4> {
    let axis = (-4.0f64..4.0, 0.0f64..3.0).prop_map(|(lo, w)| Interval::new(lo, lo + w));
    [axis.clone(), axis.clone(), axis.clone(), axis]
}

/// An interval of any scale: huge, tiny, negative, straddling zero, a point, unbounded.
fn any_scale_interval() -> impl Strategy<Value = Interval> {
    let scale = prop::sample::select(vec![1e-300, 1e-8, 1.0, 4.0, 1e3, 1e6, 1e15, 1e300]);
    let width = prop::sample::select(vec![0.0, 1e-12, 1e-3, 0.5, 1.0, 3.0]);
    prop_oneof![
        8 => (scale, -1.0f64..1.0, width).prop_map(|(s, u, w)| Interval::new(s * u, s * u + s * w)),
        1 => Just(Interval::new(f64::NEG_INFINITY, 1.0)),
        1 => Just(Interval::new(0.0, f64::INFINITY)),
    ]
}

fn any_scale_box() -> impl Strategy<Value = Box4> {
    [
        any_scale_interval(),
        any_scale_interval(),
        any_scale_interval(),
        any_scale_interval(),
    ]
}

/// A box among the kinds that break interval code on a GPU: huge, tiny, negative,
/// straddling 0, points, beside 0 (in f32, which the GPU takes exactly).
fn gpu_box() -> impl Strategy<Value = Box4> {
    let axis = prop_oneof![
        (-4.0f32..4.0, 0.0f32..2.0).prop_map(|(c, w)| (c, c + w)),
        (-1e6f32..1e6, 0.0f32..1e6).prop_map(|(c, w)| (c, c + w)),
        (-1.0f32..1.0, 0.0f32..1e-6).prop_map(|(c, w)| (c, c + w)),
        (-1e-30f32..1e-30, 0.0f32..1e-30).prop_map(|(c, w)| (c, c + w)),
        (-50.0f32..-1e-3, 0.0f32..1e-3).prop_map(|(c, w)| (c, c + w)),
        (0.0f32..3.0).prop_map(|h| (-h, h)),
        (-3.0f32..3.0).prop_map(|c| (c, c)),
        Just((0.0f32, 0.0f32)),
        (0.0f32..2.0).prop_map(|h| (0.0, h)),
    ]
    .prop_map(|(lo, hi)| Interval::new(f64::from(lo), f64::from(hi)));
    [axis.clone(), axis.clone(), axis.clone(), axis]
}

/// The corners, the centre and random points of a (bounded) box; `samples` are points of
/// the unit box mapped into it.
fn points_of(bx: &Box4, samples: &[[f64; 4]]) -> Vec<[f64; 4]> {
    let at = |t: [f64; 4]| -> [f64; 4] {
        std::array::from_fn(|i| (bx[i].lo() + t[i] * bx[i].width()).min(bx[i].hi()))
    };
    let corners = (0..16).map(|c| std::array::from_fn(|i| ((c >> i) & 1) as f64));
    corners
        .chain([[0.5; 4]])
        .chain(samples.iter().copied())
        .map(at)
        .collect()
}

/// Checks that `evaluator`'s enclosures of `tape`'s outputs over `boxes` hold the point
/// evaluator's values at the points of each box: every output where it is finite (an
/// undefined value or a pole has no real value to enclose).
fn encloses_point_values<E: Evaluator<Input = Box4, Output = Interval>>(
    evaluator: &mut E,
    what: &str,
    tape: &Tape,
    boxes: &[Box4],
    params: &[f64],
    samples: &[[f64; 4]],
) -> Result<(), String> {
    let n = tape.outputs().len();
    let mut point = PointEvaluator::new();
    for chunk in boxes.chunks(evaluator.batch_size()) {
        let mut enclosures = vec![Interval::EMPTY; chunk.len() * n];
        evaluator.evaluate(tape, chunk, params, &mut enclosures)?;
        for (bx, enclosure) in chunk.iter().zip(enclosures.chunks(n)) {
            for p in points_of(bx, samples) {
                let mut values = vec![0.0; n];
                point.eval_into(tape, p, params, &mut values);
                for (k, v) in values.iter().enumerate() {
                    if v.is_finite() && !enclosure[k].contains(*v) {
                        return Err(format!(
                            "{what}: output {k}: {v} at {p:?} not in {} over {bx:?}",
                            enclosure[k]
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}

/// Checks that `evaluator` gives bit for bit the one-box interval evaluator's enclosures and
/// continuity verdicts.
fn equals_one_box<E: Evaluator<Input = Box4, Output = Interval>>(
    evaluator: &mut E,
    what: &str,
    tape: &Tape,
    boxes: &[Box4],
    params: &[f64],
) -> Result<(), String> {
    let n = tape.outputs().len();
    let mut one = IntervalEvaluator::new();
    let mut got = vec![Interval::EMPTY; boxes.len() * n];
    evaluator.evaluate(tape, boxes, params, &mut got)?;
    for (lane, bx) in boxes.iter().enumerate() {
        let mut expected = vec![Interval::EMPTY; n];
        one.evaluate(tape, std::slice::from_ref(bx), params, &mut expected)?;
        for (k, e) in expected.iter().enumerate() {
            let g = got[lane * n + k];
            if g.lo().to_bits() != e.lo().to_bits() || g.hi().to_bits() != e.hi().to_bits() {
                return Err(format!("{what}: output {k} over {bx:?}: {g}, one box {e}"));
            }
        }
        if evaluator.continuous(tape, lane) != one.continuous(tape, 0) {
            return Err(format!("{what}: continuity over {bx:?} differs"));
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, ..ProptestConfig::default() })]

    /// The interval and batch evaluators hold every point value of F and ∇F over every box.
    #[test]
    fn interval_evaluators_hold_the_point_values(
        text in formula_text(),
        bx in a_box(),
        samples in prop::collection::vec([0.0f64..=1.0, 0.0f64..=1.0, 0.0f64..=1.0, 0.0f64..=1.0], 8),
        a in -2.0f64..2.0,
    ) {
        let formula = CompiledFormula::compile(&text).unwrap();
        let params = vec![a; formula.params.len()];
        let boxes = [bx];
        let tape = &formula.tape_all;
        let one = encloses_point_values(&mut IntervalEvaluator::new(), &text, tape, &boxes, &params, &samples);
        prop_assert!(one.is_ok(), "{}", one.unwrap_err());
        let batch = encloses_point_values(&mut BatchEvaluator::new(), &text, tape, &boxes, &params, &samples);
        prop_assert!(batch.is_ok(), "{}", batch.unwrap_err());
    }

    /// The batch evaluator (16 boxes a pass, branch-free lane loops) gives bit for bit the
    /// one-box evaluator's enclosures, and the same continuity verdicts, over every scale.
    #[test]
    fn batches_equal_one_box_at_a_time(
        text in formula_text(),
        boxes in prop::collection::vec(any_scale_box(), 1..=LANES),
        a in -2.0f64..2.0,
    ) {
        let formula = CompiledFormula::compile(&text).unwrap();
        let params = vec![a; formula.params.len()];
        let checked = equals_one_box(&mut BatchEvaluator::new(), &text, &formula.tape_all, &boxes, &params);
        prop_assert!(checked.is_ok(), "{}", checked.unwrap_err());
    }
}

/// One formula per operation of the language (and both kinds of power).
const OPERATIONS: &[&str] = &[
    "x + y - z - w",
    "x * y * z - w",
    "x / y - z",
    "(x - y)^2 - z^3 + w^4 - x^5",
    "x^-2 - y^-3",
    "1 / sqrt(x) - y",
    "(y - 2) / x^2 + x / abs(y)",
    "-1 / (x^2 + y^2) + z / -abs(w)",
    "tanh(1 / sqrt(x)) - y",
    "1 / x^4 - y / z^3",
    "(1 / x) * (1 / y) - z / (1 / w)",
    "ln(x) * y - exp(1 / z) / w",
    "sqrt(x) - y",
    "sqrt(x^2 + y^2) - z",
    "cbrt(x) - y",
    "abs(x) - y",
    "exp(x) - y",
    "ln(x) - y",
    "sin(x) - y",
    "cos(3x) + w",
    "sin(x * y) * cos(z - w)",
    "tan(x) - y",
    "asin(x) - y",
    "acos(x) - y",
    "atan(x) - y",
    "sinh(x) - y",
    "cosh(x) - y",
    "tanh(x) - y",
    "sign(x) + y",
    "step(x) - y",
    "min(x, y) - max(z, w)",
    "pow(x, y) - z",
    "x^0.5 - y",
    "atan2(y, x) - z",
    "a x - b y + 1e-30 z + 1e30 w",
];

/// For every operation and every example formula, over boxes of every kind, the GPU's
/// enclosures of F (`ff_f_box`) and of F and ∇F (`ff_f_grad_box`) hold their values at the
/// corners, the centre and random points.
#[test]
fn gpu_enclosures_hold_the_point_values() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::deterministic_rng(proptest::test_runner::RngAlgorithm::ChaCha),
    );
    let strategy = proptest::collection::vec(gpu_box(), 400);
    let examples = example_scenes();
    let formulas = OPERATIONS
        .iter()
        .map(|t| (t.to_string(), vec![1.5, -0.25]))
        .chain(examples.iter().map(|(_, s)| {
            let f = CompiledFormula::compile(&s.formula).unwrap();
            (s.formula.clone(), s.param_values(&f.param_names()))
        }));
    let mut rng = Rng(0x5eed);
    let samples: Vec<[f64; 4]> = (0..8)
        .map(|_| std::array::from_fn(|_| rng.unit()))
        .collect();
    for (text, params) in formulas {
        let formula = CompiledFormula::compile(&text).unwrap();
        let params = &params[..formula.params.len().min(params.len())];
        let boxes = strategy.new_tree(&mut runner).unwrap().current();
        let mut gpu_enclosures = GpuEnclosures::new(&gpu, &formula);
        for tape in [&formula.tape_f, &formula.tape_all] {
            encloses_point_values(&mut gpu_enclosures, &text, tape, &boxes, params, &samples)
                .unwrap();
        }
    }
}

/// The GPU's enclosure of the formula `text` of x over x in [lo, hi] (y, z, w at 0).
fn gpu_enclosure_over_x(gpu: &Gpu, text: &str, lo: f64, hi: f64) -> Interval {
    gpu_enclosure_with_params(gpu, text, lo, hi, &[])
}

/// The same, with the formula's parameters (in order of first use) set to `params`.
fn gpu_enclosure_with_params(gpu: &Gpu, text: &str, lo: f64, hi: f64, params: &[f64]) -> Interval {
    let formula = CompiledFormula::compile(text).unwrap();
    let zero = Interval::new(0.0, 0.0);
    let bx = [Interval::new(lo, hi), zero, zero, zero];
    let mut out = [Interval::EMPTY];
    GpuEnclosures::new(gpu, &formula)
        .evaluate(&formula.tape_f, &[bx], params, &mut out)
        .unwrap();
    out[0]
}

/// Over a box where a divisor reaches 0 at one end (|x|, x^2, sqrt(x)), the GPU's quotient
/// is the half-line that the CPU's intervals give, not the whole line: 1 / sqrt(y) is
/// proved positive (a fuzzed scene's pixels were left undecided by the GPU, proved empty
/// by the CPU twin); and quotients by such a half-line, and its tanh, are the CPU's too.
#[test]
fn gpu_quotients_by_a_divisor_from_zero_are_half_lines() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let cases = [
        ("1 / sqrt(x)", (0.0, 4.0), (0.5, f64::INFINITY)),
        ("1 / x^2", (-1.0, 1.0), (1.0, f64::INFINITY)),
        ("-3 / abs(x)", (-2.0, 0.0), (f64::NEG_INFINITY, -1.5)),
        ("(x^2 + 1) / abs(x)", (-1.0, 2.0), (0.5, f64::INFINITY)),
        ("3 / -(x^2)", (-1.0, 1.0), (f64::NEG_INFINITY, -3.0)),
        ("-(x^2 + 1) / -abs(x)", (-1.0, 2.0), (0.5, f64::INFINITY)),
        // An operand with a bound at inf: quotients by it, and tanh of it, are not the
        // whole line.
        ("tanh(1 / sqrt(x))", (0.0, 1.0), (0.7615942, 1.0)),
        ("2 / (1 + 1 / x^2)", (-1.0, 1.0), (0.0, 1.0)),
    ];
    for (text, (lo, hi), (want_lo, want_hi)) in cases {
        let got = gpu_enclosure_over_x(&gpu, text, lo, hi);
        let near = |a: f64, b: f64| a == b || (a - b).abs() <= 1e-5 * b.abs().max(1e-30);
        assert!(
            near(got.lo(), want_lo) && near(got.hi(), want_hi),
            "{text} over x in [{lo}, {hi}]: {got}, not the half-line [{want_lo}, {want_hi}]"
        );
    }
}

/// A real power of a base that reaches 0 is bounded on the GPU as on the CPU: ln a's lower
/// bound of -inf made b ln a the whole line, and a^b [0, +inf] (fuzzed: tau^2 = pow(xy, e)
/// left the pixels along xy = 0 undecided on the GPU, proved empty by the CPU twin).
#[test]
fn gpu_real_powers_of_a_base_from_zero_are_bounded() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let cases = [
        ("pow(x, 2.5) - 1.5", (-1e-38, 1e-38), (-1.5, -1.5)),
        ("pow(x, 2.5)", (-1.0, 4.0), (0.0, 32.0)),
        ("pow(x, 2.718)", (0.0, 1e-30), (0.0, 0.0)),
        ("pow(x, -1.5)", (-1.0, 4.0), (0.125, f64::INFINITY)),
        ("pow(x, 0.5 + 0*y)", (-2.0, 0.0), (0.0, 0.0)),
    ];
    for (text, (lo, hi), (want_lo, want_hi)) in cases {
        let got = gpu_enclosure_over_x(&gpu, text, lo, hi);
        // (Sound, and within a thousandth, or 1e-12 near 0, past the exact range.)
        let outside = |a: f64, b: f64| a == b || (a - b).abs() <= 1e-3 * b.abs() + 1e-12;
        assert!(
            got.lo() <= want_lo && got.hi() >= want_hi,
            "{text} over x in [{lo}, {hi}]: {got} does not hold [{want_lo}, {want_hi}]"
        );
        assert!(
            outside(got.lo(), want_lo) && outside(got.hi(), want_hi),
            "{text} over x in [{lo}, {hi}]: {got}, not about [{want_lo}, {want_hi}]"
        );
    }
}

/// A parameter whose value is an f32 is that point on the GPU, not widened by an ulp:
/// pow(x, R) at R = 0 is 1 where x reaches 0, where a widened R (straddling 0) made it
/// [0, +inf] (fuzzed: the pixels along x = 0 were undecided on the GPU, proved empty by the
/// CPU twin). A value that is no f32 (0.1) is still enclosed.
#[test]
fn gpu_parameters_that_are_f32_values_are_points() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let cases = [
        ("pow(x, R)", (0.0, 1.0), 0.0, (1.0, 1.0)),
        ("pow(x, R)", (-1e-8, 1e-8), 0.0, (1.0, 1.0)),
        ("pow(x, R) + y", (-1.0, 1.0), 0.0, (1.0, 1.0)),
        ("x - R", (2.0, 2.0), 2.0, (0.0, 0.0)),
        ("pow(x, R)", (1.0, 2.0), 0.1, (1.0, 1.0717734625362931)),
    ];
    for (text, (lo, hi), r, (want_lo, want_hi)) in cases {
        let got = gpu_enclosure_with_params(&gpu, text, lo, hi, &[r]);
        let near = |a: f64, b: f64| (a - b).abs() <= 1e-3 * b.abs().max(1.0);
        assert!(
            got.lo() <= want_lo && got.hi() >= want_hi,
            "{text} over x in [{lo}, {hi}], R = {r}: {got} does not hold [{want_lo}, {want_hi}]"
        );
        assert!(
            near(got.lo(), want_lo) && near(got.hi(), want_hi),
            "{text} over x in [{lo}, {hi}], R = {r}: {got}, not about [{want_lo}, {want_hi}]"
        );
    }
}

/// sinh and cosh keep their sign on the GPU where e^x has no f32 upper bound (|x| beyond
/// 42): there they were the whole line, and a fuzzed formula, sinh(1000 y) = 0, had pixels
/// left undecided that the CPU twin proved empty.
#[test]
fn gpu_sinh_and_cosh_keep_their_sign_beyond_e_s_range() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let cases = [
        ("sinh(x)", (50.0, 60.0), 1.0),
        ("sinh(x)", (-60.0, -50.0), -1.0),
        ("sinh(1000 x)", (0.05, 0.2), 1.0),
        ("sinh(x)", (30.0, 300.0), 1.0),
        ("cosh(x) - 2", (50.0, 60.0), 1.0),
        ("cosh(1000 x) - 2", (-0.2, -0.05), 1.0),
    ];
    for (text, (lo, hi), sign) in cases {
        let got = gpu_enclosure_over_x(&gpu, text, lo, hi);
        let kept = if sign > 0.0 {
            got.lo() > 0.0
        } else {
            got.hi() < 0.0
        };
        assert!(kept, "{text} over x in [{lo}, {hi}]: {got} lost its sign");
    }
}

/// A product with an unbounded operand keeps the sign and the bound nearest 0 that the
/// CPU's intervals give where both operands are one-signed, and is the whole line where
/// they are not: it was the whole line always, and fuzzed formulas (2.29·x^x + 3,
/// cosh(e^(xyz))·τ) had pixels left undecided on the GPU that the CPU twin proved empty.
#[test]
fn gpu_products_with_an_unbounded_operand_keep_their_sign() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let inf = f64::INFINITY;
    let cases = [
        ("2.29 * (1 / sqrt(x)) + 3", (0.0, 4.0), (4.145, inf)),
        ("(1 / sqrt(x)) * (x + 1)", (0.0, 4.0), (0.5, inf)),
        ("-(1 / sqrt(x)) * (x + 1)", (0.0, 4.0), (-inf, -0.5)),
        ("(1 / sqrt(x)) * (-2 - x)", (0.0, 4.0), (-inf, -1.0)),
        ("(-1 / sqrt(x)) * (-1 / sqrt(x))", (0.0, 4.0), (0.25, inf)),
        ("(1 / sqrt(x)) * (x - 1)", (0.0, 4.0), (-inf, inf)),
        ("(1 / x) * 2", (-1.0, 1.0), (-inf, inf)),
    ];
    for (text, (lo, hi), (want_lo, want_hi)) in cases {
        let got = gpu_enclosure_over_x(&gpu, text, lo, hi);
        let near = |a: f64, b: f64| a == b || (a - b).abs() <= 1e-5 * b.abs();
        assert!(
            got.lo() <= want_lo && got.hi() >= want_hi,
            "{text} over x in [{lo}, {hi}]: {got} does not hold [{want_lo}, {want_hi}]"
        );
        assert!(
            near(got.lo(), want_lo) && near(got.hi(), want_hi),
            "{text} over x in [{lo}, {hi}]: {got}, not about [{want_lo}, {want_hi}]"
        );
    }
}

/// The GPU's sin and cos are tight as well as sound: over a point (an f32 x) the enclosure
/// is within 1e-5 + 4e-7 |x| of the value on each side (a few ulps of x: cos adds pi/2
/// first), for |x| up to 100 (WGSL's own sin promises only 2^-11, which left
/// trigonometric scenes' pixels near M undecided); a box's enclosure is as close to the
/// exact range.
#[test]
fn gpu_sin_and_cos_enclosures_are_tight() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let mut rng = Rng(0x51de);
    for text in ["sin(x)", "cos(x)"] {
        let formula = CompiledFormula::compile(text).unwrap();
        let mut gpu_enclosures = GpuEnclosures::new(&gpu, &formula);
        let point = |x: f64| Interval::new(x, x);
        let mut boxes: Vec<Box4> = (0..200)
            .map(|i| {
                let scale = [1.0, 4.0, 100.0][i % 3];
                let x = f64::from(rng.range(-scale, scale) as f32);
                [point(x), point(0.0), point(0.0), point(0.0)]
            })
            .collect();
        boxes.extend((0..100).map(|_| {
            let lo = f64::from(rng.range(-6.0, 6.0) as f32);
            let hi = f64::from((lo + rng.range(0.0, 2.0)) as f32);
            [Interval::new(lo, hi), point(0.0), point(0.0), point(0.0)]
        }));
        let mut out = vec![Interval::EMPTY; boxes.len()];
        gpu_enclosures
            .evaluate(&formula.tape_f, &boxes, &[], &mut out)
            .unwrap();
        let f = |x: f64| if text == "sin(x)" { x.sin() } else { x.cos() };
        for (bx, got) in boxes.iter().zip(&out) {
            let (lo, hi) = (bx[0].lo(), bx[0].hi());
            // The exact range, from a fine grid and the extremes it holds.
            let mut range = (f(lo).min(f(hi)), f(lo).max(f(hi)));
            for i in 1..2000 {
                let v = f(lo + (hi - lo) * f64::from(i) / 2000.0);
                range = (range.0.min(v), range.1.max(v));
            }
            let slack = 1e-5 + 4e-7 * lo.abs().max(hi.abs()) + (hi - lo) * 2e-3;
            assert!(
                got.lo() >= range.0 - slack && got.hi() <= range.1 + slack,
                "{text} over [{lo}, {hi}]: {got} is wider than [{}, {}] by more than {slack}",
                range.0,
                range.1
            );
        }
    }
}

/// The GPU's atan, asin, acos and atan2 are tight as well as sound (they were the whole
/// range once, which left every pixel of a formula with one undecided): over points, within
/// 2^-9 of the value plus 1e-6 on each side (the library widens WGSL's value by 2^-10 of
/// itself, twice WGSL's 4096 ULPs; acos is pi/2 - asin, so 2^-9 of asin's value); over a
/// box of x, within that of the exact range; and a
/// point's enclosure has the value's sign however near 0 (atan2: y's, off its branch cut).
#[test]
fn gpu_arc_function_enclosures_are_tight() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let mut rng = Rng(0xa7c5);
    let point = |x: f64| Interval::new(x, x);
    // Each function, its value at (x, y), how far x reaches, and what its error scales with.
    type Arc = (&'static str, fn(f64, f64) -> f64, f64, fn(f64) -> f64);
    let functions: [Arc; 4] = [
        ("atan(x)", |x, _| x.atan(), 50.0, f64::abs),
        ("asin(x)", |x, _| x.asin(), 1.0, f64::abs),
        ("acos(x)", |x, _| x.acos(), 1.0, |v| (FRAC_PI_2 - v).abs()),
        ("atan2(y, x)", |x, y| y.atan2(x), 3.0, f64::abs),
    ];
    for (text, f, reach, scale) in functions {
        let formula = CompiledFormula::compile(text).unwrap();
        let mut gpu_enclosures = GpuEnclosures::new(&gpu, &formula);
        let f32_in = |rng: &mut Rng, a: f64, b: f64| f64::from(rng.range(a, b) as f32);
        let mut boxes: Vec<Box4> = (0..200)
            .map(|i| {
                // Near 0 and far from it.
                let scale = if i % 4 == 0 { 1e-4 * reach } else { reach };
                let x = f32_in(&mut rng, -scale, scale);
                // atan2 off its cut: x > 0, or y away from 0.
                let y = f32_in(&mut rng, 0.01, 2.0) * if i % 2 == 0 { 1.0 } else { -1.0 };
                [point(x), point(y), point(0.0), point(0.0)]
            })
            .collect();
        boxes.extend((0..100).map(|_| {
            let lo = f32_in(&mut rng, -reach, reach);
            let hi = f64::from((lo + rng.range(0.0, reach / 4.0)).min(reach) as f32);
            [Interval::new(lo, hi), point(0.5), point(0.0), point(0.0)]
        }));
        let mut out = vec![Interval::EMPTY; boxes.len()];
        gpu_enclosures
            .evaluate(&formula.tape_f, &boxes, &[], &mut out)
            .unwrap();
        for (bx, got) in boxes.iter().zip(&out) {
            let (lo, hi, y) = (bx[0].lo(), bx[0].hi(), bx[1].lo());
            let (a, b) = (f(lo, y), f(hi, y));
            let range = (a.min(b), a.max(b));
            let slack = |v: f64| 2f64.powi(-9) * scale(v) + 1e-6;
            assert!(
                got.lo() <= range.0
                    && got.hi() >= range.1
                    && got.lo() >= range.0 - slack(range.0)
                    && got.hi() <= range.1 + slack(range.1),
                "{text} at x in [{lo}, {hi}], y = {y}: {got} does not hold [{}, {}] within {}",
                range.0,
                range.1,
                slack(range.0).max(slack(range.1))
            );
            if lo == hi && a != 0.0 {
                let sign = if got.lo() > 0.0 {
                    1.0
                } else if got.hi() < 0.0 {
                    -1.0
                } else {
                    0.0
                };
                assert_eq!(sign, a.signum(), "{text} at x = {lo}, y = {y}: {got}");
            }
        }
    }
}

/// Every evaluator refuses a call outside the contract with a reason, never a panic: no
/// input, more than its batch, an output buffer too short; the GPU a tape not its formula's.
#[test]
fn every_evaluator_keeps_the_contract_s_preconditions() {
    let formula = CompiledFormula::compile("x^2 + y^2 + z^2 + w^2 = 1").unwrap();
    let tape = &formula.tape_all;
    let unit: Box4 = [Interval::new(0.0, 1.0); 4];
    fn refuses<E: Evaluator>(e: &mut E, tape: &Tape, inputs: &[E::Input], out: &mut [E::Output]) {
        let result = e.evaluate(tape, inputs, &[], out);
        assert!(result.is_err(), "a call outside the contract was taken");
    }
    let mut out = vec![Interval::EMPTY; 5 * (LANES + 1)];
    refuses(&mut IntervalEvaluator::new(), tape, &[], &mut out);
    refuses(&mut IntervalEvaluator::new(), tape, &[unit, unit], &mut out);
    refuses(&mut IntervalEvaluator::new(), tape, &[unit], &mut out[..4]);
    refuses(&mut BatchEvaluator::new(), tape, &[], &mut out);
    refuses(
        &mut BatchEvaluator::new(),
        tape,
        &[unit; LANES + 1],
        &mut out,
    );
    refuses(&mut PointEvaluator::new(), tape, &[], &mut [0.0; 5]);
    refuses(
        &mut PointEvaluator::new(),
        tape,
        &[[0.0; 4]; 2],
        &mut [0.0; 9],
    );
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    let other = CompiledFormula::compile("x - y").unwrap();
    refuses(
        &mut GpuEnclosures::new(&gpu, &formula),
        &other.tape_f,
        &[unit],
        &mut out,
    );
    // And within it, each fills what it is asked for.
    let mut values = [0.0; 10];
    PointEvaluator::new()
        .evaluate(tape, &[[1.0, 0.0, 0.0, 0.0], [0.0; 4]], &[], &mut values)
        .unwrap();
    assert_eq!(values[0], 0.0);
    assert_eq!(values[5], -1.0);
}
