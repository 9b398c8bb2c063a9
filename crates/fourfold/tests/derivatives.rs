//! Symbolic partials agree with central finite differences of F.

mod common;

use common::{Rng, example_scenes};
use fourfold::CompiledFormula;
use fourfold::eval::PointEvaluator;

/// Checks ∇F against central differences at random points of `domain`.
///
/// With step h = 1e-5·(1 + |p_i|) the difference quotient's error is O(h²·F''') from
/// truncation plus O(ε·|F|/h) from rounding; we accept
/// |symbolic − numeric| ≤ 1e-5 · (1 + |symbolic| + |F|/scale).
fn check_gradient(label: &str, formula: &CompiledFormula, params: &[f64], domain: [[f64; 2]; 4]) {
    let mut point = PointEvaluator::new();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ label.len() as u64);
    let mut checked = 0;
    for _ in 0..400 {
        let p = domain.map(|[lo, hi]| rng.range(lo, hi));
        let mut all = [0.0; 5];
        point.eval_into(&formula.tape_all, p, params, &mut all);
        if all.iter().any(|v| !v.is_finite() || v.abs() > 1e6) {
            continue;
        }
        for axis in 0..4 {
            let h = 1e-5 * (1.0 + p[axis].abs());
            let (mut plus, mut minus) = (p, p);
            plus[axis] += h;
            minus[axis] -= h;
            let fp = point.eval(&formula.tape_f, plus, params);
            let fm = point.eval(&formula.tape_f, minus, params);
            let numeric = (fp - fm) / (2.0 * h);
            let symbolic = all[1 + axis];
            let tolerance = 1e-5 * (1.0 + symbolic.abs() + all[0].abs());
            // Kinks (abs, min, max, step) are not differentiable: skip points near them,
            // recognisable by one-sided differences that disagree.
            let f0 = all[0];
            let (right, left) = ((fp - f0) / h, (f0 - fm) / h);
            if (right - left).abs() > 1e-2 * (1.0 + right.abs()) {
                continue;
            }
            assert!(
                (symbolic - numeric).abs() <= tolerance,
                "{label}: dF/d{} at {p:?} is {symbolic} symbolically, {numeric} numerically",
                ["x", "y", "z", "w"][axis]
            );
        }
        checked += 1;
    }
    assert!(checked >= 100, "{label}: only {checked} usable points");
}

#[test]
fn example_scenes_have_correct_gradients() {
    for (name, scene) in example_scenes() {
        let f = CompiledFormula::compile(&scene.formula).unwrap();
        let params = scene.param_values(&f.param_names());
        let domain = scene.domain.axes().map(|a| [a.lo, a.hi]);
        check_gradient(name, &f, &params, domain);
    }
}

#[test]
fn further_formulas_have_correct_gradients() {
    let formulas = [
        "x^2 + y^2 + z^2 + w^2 - 1",
        "x*y*z*w - 0.1",
        "sin(x)cos(y) + sin(z)cos(w)",
        "exp(x y) - z w",
        "ln(1 + x^2 + y^2) - z",
        "sqrt(x^2 + y^2 + 1) - z w",
        "tan(0.5x) + atan(y) - z",
        "sinh(x) + cosh(y) - tanh(z w)",
        "asin(0.5x) + acos(0.4y) - w",
        "cbrt(x + 3) - y^3 + z",
        "pow(x^2 + 1, 1.5) - y",
        "pow(x^2 + 1, y) - z",
        "atan2(y, x + 3) - w",
        "x/(1 + y^2) - z/(2 + w^2)",
        "(x^2 + y^2 - 1)^3 - x^2 y^3 + z w",
        "|x| + |y| - z^2",
        "min(x, y) + max(z, w)",
        "x^-2 + y^(-3) - 1",
        "(x + y + z + w)^5 - 2",
        "a x^2 + b y^2 - c z w",
        "sin(x + sin(y + sin(z + sin(w))))",
        "exp(-x^2 - y^2) - 0.5 + 0.1 z",
        "w - (x^2 + y^2 + z^2 + R^2 - r^2)^2 + 4R^2(x^2 + y^2)",
        "x^4 - 5x^2 + y^4 - 5y^2 + z^4 - 5z^2 + w^4 - 5w^2 + 10",
    ];
    for text in formulas {
        let f = CompiledFormula::compile(text).unwrap();
        let params: Vec<f64> = (0..f.params.len()).map(|i| 0.5 + 0.75 * i as f64).collect();
        let domain = [[0.2, 1.7]; 4];
        check_gradient(text, &f, &params, domain);
    }
}

#[test]
fn derivatives_are_simplified() {
    let f = CompiledFormula::compile("x^2").unwrap();
    assert_eq!(f.gradient_text(), ["2x", "0", "0", "0"]);
    let g = CompiledFormula::compile("x y + 3x").unwrap();
    assert_eq!(g.gradient_text()[0], "3 + y");
}
