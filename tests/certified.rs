//! Certified pixels (docs/method.md §5.9): the GPU's interval arithmetic is sound, and every
//! pixel's verdict holds against an independent, dense look at its observer plane.

mod common;

use common::{Rng, example_scenes, example_scenes_named};
use fourfold::CompiledFormula;
use fourfold::eval::PointEvaluator;
use fourfold::render::certify::Verdict;
use fourfold::render::pipeline::{Device, render_prepared};
use fourfold::render::probe::{Enclosures, enclose};
use fourfold::render::{Camera, Gpu, Prepared};
use fourfold::scene::Scene;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, TestRng, TestRunner};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"))
}

/// One formula per operation of the language (and both kinds of power).
const OPERATIONS: &[&str] = &[
    "x + y - z - w",
    "x * y * z - w",
    "x / y - z",
    "(x - y)^2 - z^3 + w^4 - x^5",
    "x^-2 - y^-3",
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

/// A box among the kinds that break interval code: huge, tiny, negative, straddling 0,
/// points, beside 0.
fn box_strategy() -> impl Strategy<Value = ([f32; 4], [f32; 4])> {
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
    ];
    [axis.clone(), axis.clone(), axis.clone(), axis].prop_map(|a| {
        (
            std::array::from_fn(|i| a[i].0),
            std::array::from_fn(|i| a[i].1),
        )
    })
}

/// Where an enclosure [lo, hi] from the GPU holds v: ±2^62 stand for ±inf.
fn holds(e: [f32; 2], v: f64) -> bool {
    const BIG: f64 = 4_611_686_018_427_387_904.0;
    let lo = if f64::from(e[0]) <= -BIG {
        f64::NEG_INFINITY
    } else {
        f64::from(e[0])
    };
    let hi = if f64::from(e[1]) >= BIG {
        f64::INFINITY
    } else {
        f64::from(e[1])
    };
    lo <= v && v <= hi
}

/// The corners, the centre and random points of a box.
fn points_of((lo, hi): ([f32; 4], [f32; 4]), rng: &mut Rng) -> Vec<[f64; 4]> {
    let mut points: Vec<[f64; 4]> = (0..16)
        .map(|k| std::array::from_fn(|i| f64::from(if k >> i & 1 == 1 { hi[i] } else { lo[i] })))
        .collect();
    points.push(std::array::from_fn(|i| {
        0.5 * (f64::from(lo[i]) + f64::from(hi[i]))
    }));
    for _ in 0..8 {
        points.push(std::array::from_fn(|i| {
            rng.range(f64::from(lo[i]), f64::from(hi[i]))
        }));
    }
    points
}

/// Checks the GPU's enclosures of `formula` over `boxes` against F and ∇F at points of each.
fn check_enclosures(gpu: &Gpu, text: &str, formula: &CompiledFormula, params: &[f64], boxes: &[([f32; 4], [f32; 4])]) {
    let found: Vec<Enclosures> = enclose(gpu, formula, params, boxes).expect("probe runs");
    let mut eval = PointEvaluator::new();
    let mut rng = Rng(0x5eed);
    for (b, e) in boxes.iter().zip(&found) {
        for p in points_of(*b, &mut rng) {
            let mut all = [0.0; 5];
            eval.eval_into(&formula.tape_all, p, params, &mut all);
            let f = eval.eval(&formula.tape_f, p, params);
            if f.is_finite() {
                assert!(
                    holds(e.f, f) && holds(e.f_grad[0], f),
                    "{text}: F({p:?}) = {f} outside the GPU's {:?} / {:?} over {b:?}",
                    e.f,
                    e.f_grad[0]
                );
            }
            for k in 1..5 {
                if all[k].is_finite() && all.iter().all(|v| v.is_finite()) {
                    assert!(
                        holds(e.f_grad[k], all[k]),
                        "{text}: dF/d{}({p:?}) = {} outside the GPU's {:?} over {b:?}",
                        ["x", "y", "z", "w"][k - 1],
                        all[k],
                        e.f_grad[k]
                    );
                }
            }
        }
    }
}

/// For every operation and every example formula, over boxes of every kind, the GPU's
/// enclosures of F and ∇F hold their values at the corners, the centre and random points.
#[test]
fn gpu_enclosures_hold_the_values() {
    let gpu = gpu();
    let mut runner = TestRunner::new_with_rng(Config::default(), TestRng::deterministic_rng(proptest::test_runner::RngAlgorithm::ChaCha));
    let strategy = proptest::collection::vec(box_strategy(), 400);
    let examples = example_scenes();
    let formulas = OPERATIONS
        .iter()
        .map(|t| (t.to_string(), vec![1.5, -0.25]))
        .chain(examples.iter().map(|(_, s)| {
            let f = CompiledFormula::compile(&s.formula).unwrap();
            (s.formula.clone(), s.param_values(&f.param_names()))
        }));
    for (text, params) in formulas {
        let formula = CompiledFormula::compile(&text).unwrap();
        let params = &params[..formula.params.len().min(params.len())];
        let boxes = strategy.new_tree(&mut runner).unwrap().current();
        check_enclosures(&gpu, &text, &formula, params, &boxes);
    }
}
