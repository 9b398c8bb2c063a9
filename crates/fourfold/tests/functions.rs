//! The table of the language's operations (`fourfold::ops`), row by row: each operation is
//! written as a formula lowers to it, every evaluator agrees with its row (the point
//! evaluator is its `point`, the interval evaluators hold it and the batch one equals the
//! one-box one, the GPU's enclosures hold it), its continuity verdict is its row's, its
//! derivative matches finite differences wherever it is smooth, and its WGSL names exist.

use fourfold::CompiledFormula;
use fourfold::eval::{
    BatchEvaluator, Box4, Evaluator, Interval, IntervalEvaluator, PointEvaluator,
};
use fourfold::expr::Node;
use fourfold::headless::probe::GpuEnclosures;
use fourfold::ops::{BINARY, BinaryOp, Function, UNARY, UnaryOp, function, function_names};
use fourfold::render::Gpu;
use fourfold::render::shader::{INTERVAL_LIBRARY, generate};

/// Values every operation is tried at: both signs, near 0 and 1, inside and outside the
/// domains of sqrt, ln, asin and acos.
const AT: [f64; 9] = [-2.3, -1.0, -0.7, -0.3, 0.0, 0.4, 0.9, 1.7, 3.1];

/// The formula that lowers to `op` applied to x (and y).
fn unary_formula(op: UnaryOp) -> String {
    let s = op.spec();
    if s.callable {
        format!("{}(x)", s.name)
    } else {
        format!("{}x", s.name)
    }
}

fn binary_formula(op: BinaryOp) -> String {
    let s = op.spec();
    if s.callable {
        format!("{}(x, y)", s.name)
    } else {
        format!("x {} y", s.name)
    }
}

/// Whether `a` and `b` are the same value (both undefined counts).
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// A small box around (x, y, 0, 0).
fn around(x: f64, y: f64, r: f64) -> Box4 {
    [
        Interval::new(x - r, x + r),
        Interval::new(y - r, y + r),
        Interval::point(0.0),
        Interval::point(0.0),
    ]
}

/// Checks every evaluator on `formula` (F of (x, y) = `point(x, y)`) at the grid of AT²
/// (x alone for a unary row), and F's partial derivatives against central differences
/// where the row's continuity holds around the point.
fn check_row(
    what: &str,
    formula: &CompiledFormula,
    point: impl Fn(f64, f64) -> f64,
    continuous: impl Fn(Interval, Interval) -> bool,
    gpu: &Gpu,
) {
    let mut eval = PointEvaluator::new();
    let mut one = IntervalEvaluator::new();
    let mut batch = BatchEvaluator::new();
    let mut boxes = Vec::new();
    for x in AT {
        for y in AT {
            let p = [x, y, 0.0, 0.0];
            let expected = point(x, y);
            let got = eval.eval(&formula.tape_f, p, &[]);
            assert!(
                same(got, expected),
                "{what} at {p:?}: {got}, the row says {expected}"
            );
            boxes.push(around(x, y, 0.0));
            boxes.push(around(x, y, 0.05));
            check_derivative(what, formula, &mut eval, p, &continuous);
        }
    }
    for bx in &boxes {
        let mut e = [Interval::EMPTY; 5];
        one.evaluate(&formula.tape_all, std::slice::from_ref(bx), &[], &mut e)
            .unwrap();
        let mut b = [Interval::EMPTY; 5];
        batch
            .evaluate(&formula.tape_all, std::slice::from_ref(bx), &[], &mut b)
            .unwrap();
        assert_eq!(format!("{e:?}"), format!("{b:?}"), "{what} over {bx:?}");
        let v = point(bx[0].midpoint(), bx[1].midpoint());
        if v.is_finite() {
            assert!(e[0].contains(v), "{what}: {v} not in {} over {bx:?}", e[0]);
        }
        let row = continuous(bx[0], bx[1]);
        let told = one.continuous(&formula.tape_all, 0).unwrap();
        // The evaluator also asks every value to be bounded: it may say less than the row.
        assert!(
            !told || row,
            "{what}: continuous over {bx:?}, the row says not"
        );
    }
    let mut gpu_enclosures = GpuEnclosures::new(gpu, formula);
    let mut e = vec![Interval::EMPTY; boxes.len()];
    gpu_enclosures
        .evaluate(&formula.tape_f, &boxes, &[], &mut e)
        .unwrap();
    for (bx, e) in boxes.iter().zip(e) {
        let v = point(bx[0].midpoint(), bx[1].midpoint());
        if v.is_finite() {
            assert!(
                e.contains(v),
                "{what} on the GPU: {v} not in {e} over {bx:?}"
            );
        }
    }
}

/// ∂F/∂x and ∂F/∂y at `p` against central differences, where F is continuous around `p`
/// by its row and defined at the difference's points.
fn check_derivative(
    what: &str,
    formula: &CompiledFormula,
    eval: &mut PointEvaluator,
    p: [f64; 4],
    continuous: impl Fn(Interval, Interval) -> bool,
) {
    let h = 1e-6;
    let wide = around(p[0], p[1], 1e-3);
    if !continuous(wide[0], wide[1]) {
        return;
    }
    let mut grad = [0.0; 5];
    eval.eval_into(&formula.tape_all, p, &[], &mut grad);
    for axis in 0..2 {
        let (mut a, mut b) = (p, p);
        a[axis] += h;
        b[axis] -= h;
        let (fa, fb) = (
            eval.eval(&formula.tape_f, a, &[]),
            eval.eval(&formula.tape_f, b, &[]),
        );
        if !(fa.is_finite() && fb.is_finite() && grad[1 + axis].is_finite()) {
            continue;
        }
        let numeric = (fa - fb) / (2.0 * h);
        let symbolic = grad[1 + axis];
        assert!(
            (numeric - symbolic).abs() <= 1e-5 * (1.0 + symbolic.abs()),
            "{what}: d/d{} at {p:?} is {symbolic}, finite differences {numeric}",
            ["x", "y"][axis]
        );
    }
}

#[test]
fn every_unary_row_is_what_every_evaluator_does() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    for (i, spec) in UNARY.iter().enumerate() {
        assert_eq!(spec.op as usize, i, "the table follows the enum's order");
        let text = unary_formula(spec.op);
        let formula = CompiledFormula::compile(&text).unwrap();
        assert!(
            matches!(formula.graph.node(formula.f), Node::Unary(op, _) if op == spec.op),
            "{text} lowers to {:?}",
            formula.graph.node(formula.f)
        );
        let point = |x: f64, _: f64| (spec.point)(x);
        let continuous = |x: Interval, _: Interval| (spec.continuous)(x);
        check_row(&text, &formula, point, continuous, &gpu);
        check_wgsl(&text, &formula, spec.wgsl_interval);
    }
}

#[test]
fn every_binary_row_is_what_every_evaluator_does() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"));
    for (i, spec) in BINARY.iter().enumerate() {
        assert_eq!(spec.op as usize, i, "the table follows the enum's order");
        let text = binary_formula(spec.op);
        let formula = CompiledFormula::compile(&text).unwrap();
        assert!(
            matches!(formula.graph.node(formula.f), Node::Binary(op, ..) if op == spec.op),
            "{text} lowers to {:?}",
            formula.graph.node(formula.f)
        );
        check_row(&text, &formula, spec.point, spec.continuous, &gpu);
        check_wgsl(&text, &formula, spec.wgsl_interval);
    }
}

/// The row's interval function is in the interval library, and the whole shader for its
/// formula validates.
fn check_wgsl(what: &str, formula: &CompiledFormula, interval: &str) {
    assert!(
        INTERVAL_LIBRARY.contains(&format!("fn {interval}(")),
        "{what}: templates/interval.wgsl has no {interval}"
    );
    let shader = generate(formula).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(shader.source.contains(&format!("{interval}(")), "{what}");
}

#[test]
fn every_name_calls_its_row() {
    for name in function_names() {
        let f = function(name).unwrap_or_else(|| panic!("{name} calls nothing"));
        let (spec_name, aliases, arity) = match f {
            Function::Unary(op) => (op.spec().name, op.spec().aliases, 1),
            Function::Binary(op) => (op.spec().name, &[][..], 2),
        };
        assert!(spec_name == name || aliases.contains(&name), "{name}");
        assert_eq!(f.arity(), arity);
    }
    let listed: Vec<_> = function_names().collect();
    for spec in UNARY.iter().filter(|s| s.callable) {
        assert!(listed.contains(&spec.name), "{} is not listed", spec.name);
    }
    for spec in BINARY.iter().filter(|s| s.callable) {
        assert!(listed.contains(&spec.name), "{} is not listed", spec.name);
    }
}
