//! Constant folding in the expression graph: total (no node applies an operation to
//! constants alone, whatever its value: NaN for undefined, ±∞ for an overflow), with the
//! language's meaning; a formula that folds to an undefined constant is refused with the
//! operation that made it undefined underlined, and one that folds to 0 as having no
//! 3-manifold to draw.

use fourfold::CompiledFormula;
use fourfold::expr::graph::operands;
use fourfold::ops::{BINARY, UNARY};

/// Whether some node of `formula`'s graph that F, ∇F or the second derivatives use
/// applies an operation to constants alone.
fn folds_fully(formula: &CompiledFormula) -> bool {
    let graph = &formula.graph;
    graph.nodes().iter().all(|node| {
        let inputs: Vec<_> = operands(*node).collect();
        inputs.is_empty() || !inputs.iter().all(|&i| graph.const_value(i).is_some())
    })
}

#[test]
fn no_node_applies_an_operation_to_constants_alone() {
    for text in [
        "exp(1e9) = x",
        "x^2 + (1e300*1e300) - y",
        "2^0.5 * x + tan(pi/2) * y",
        "pow(0, x) - y",
        "x / (1e-160 * 1e-160) + sinh(800) * z",
        "atan2(0, 0) + x - cosh(-1e3)",
        "(1e-320)^(-2) + x",
        "x*tau - e^(710) + w",
    ] {
        let formula = CompiledFormula::compile(text).unwrap_or_else(|e| panic!("{text}: {e:?}"));
        assert!(folds_fully(&formula), "{text}: {:?}", formula.graph.nodes());
    }
}

#[test]
fn an_undefined_constant_is_refused_with_its_culprit() {
    for (text, culprit, why) in [
        ("max(asin(2), x^2 + y^2 + z^2 + w^2 - 1)", "asin(2)", "asin"),
        ("sqrt(-1) + x", "sqrt(-1)", "sqrt"),
        ("x/0 + y", "x/0", "division by 0"),
        ("(e - pi)^(x^a)", "(e - pi)^(x^a)", "real power"),
        ("0 * ln(0) + x", "ln(0)", "ln"),
        (
            "min(x, 1) + (1e308*10 - 1e308*10)",
            "(1e308*10 - 1e308*10)",
            "∞ − ∞",
        ),
        ("1e308*10 = 1e308*10", "1e308*10 = 1e308*10", "∞ − ∞"),
        ("x(1/0)", "1/0", "division by 0"),
    ] {
        let error = CompiledFormula::compile(text).expect_err(text);
        assert_eq!(
            error.message, "F is undefined everywhere in the domain",
            "{text}"
        );
        assert_eq!(&text[error.span.clone()], culprit, "{text}");
        assert!(error.label.contains(why), "{text}: {}", error.label);
        let shown = error.render("formula", text);
        assert!(
            shown.contains(&"^".repeat(culprit.chars().count())),
            "{shown}"
        );
    }
}

#[test]
fn a_formula_that_folds_to_zero_is_refused() {
    for (text, label) in [
        ("0", "this is 0"),
        ("x - x", "this is 0"),
        ("(sin(x) - sin(x))*y + 0/z", "this is 0"),
        ("x^2 + y = y + x*x", "the two sides are equal"),
    ] {
        let error = CompiledFormula::compile(text).expect_err(text);
        assert_eq!(error.message, "F is 0 everywhere", "{text}");
        assert_eq!(error.span, 0..text.len(), "{text}");
        assert!(error.label.starts_with(label), "{text}: {}", error.label);
        assert!(error.render("formula", text).contains("nothing to draw"));
    }
    // A constant that is not 0 has no surface, and one that is 0 only for some parameter
    // values is drawn: neither is refused.
    for text in ["1", "x - x + 1", "a - a*a", "a*(x - x) + y"] {
        CompiledFormula::compile(text).unwrap_or_else(|e| panic!("{text}: {e:?}"));
    }
}

#[test]
fn every_row_says_where_it_is_undefined_by_its_name() {
    // The culprit's label is the row's `undefined`: it names the function a user typed.
    for row in UNARY.iter().filter(|r| r.callable) {
        assert!(
            row.undefined.starts_with(row.name),
            "{}: {}",
            row.name,
            row.undefined
        );
    }
    for row in BINARY.iter().filter(|r| r.callable && r.name != "pow") {
        assert!(
            row.undefined.starts_with(row.name),
            "{}: {}",
            row.name,
            row.undefined
        );
    }
    // And each is true: a row undefined somewhere has a defined argument where it is NaN.
    for row in UNARY.iter() {
        let undefined_at = [2.0, -3.0, 0.0, f64::INFINITY, f64::NEG_INFINITY]
            .into_iter()
            .any(|v| (row.point)(v).is_nan());
        assert_eq!(
            undefined_at,
            !row.undefined.contains("defined everywhere"),
            "{}",
            row.name
        );
    }
}

#[test]
fn an_undefined_operand_leaves_every_operation_undefined() {
    // The graph's folding (NaN absorbs) is what every evaluator does.
    for row in UNARY.iter() {
        assert!((row.point)(f64::NAN).is_nan(), "{}", row.name);
    }
    for row in BINARY.iter() {
        for v in [0.0, 1.0, -2.0, f64::INFINITY] {
            assert!((row.point)(f64::NAN, v).is_nan(), "{}(NaN, {v})", row.name);
            assert!((row.point)(v, f64::NAN).is_nan(), "{}({v}, NaN)", row.name);
        }
    }
}

#[test]
fn a_negative_number_has_its_integer_powers_however_large() {
    // Folded: (−2)^3 is −8 as x^3 is at x = −2, not the undefined real power.
    let formula = CompiledFormula::compile("x + (-2)^3").expect("(-2)^3 is -8");
    let at = |formula: &CompiledFormula, x: f64| {
        fourfold::eval::PointEvaluator::new().eval(&formula.tape_f, [x, 0.0, 0.0, 0.0], &[])
    };
    assert_eq!(at(&formula, 1.0), -7.0);
    assert!(folds_fully(&formula));
    // Beyond the exponents multiplied out (1024), x^n keeps its value at a negative x, and
    // so does each partial derivative.
    for (n, x, want) in [
        (2000, -1.0002, 1.0002f64.powi(2000)),
        (2001, -1.0002, -(1.0002f64.powi(2001))),
        (2001, 0.5, 0.5f64.powi(2001)),
        (-2001, -1.5, -(1.5f64.powi(-2001))),
    ] {
        let text = format!("x^{n} - 1");
        let formula = CompiledFormula::compile(&text).unwrap_or_else(|e| panic!("{text}: {e:?}"));
        let got = at(&formula, x) + 1.0;
        assert!(
            (got - want).abs() <= 1e-9 * want.abs(),
            "{text} at {x}: {got}"
        );
        let mut grad = [0.0; 5];
        fourfold::eval::PointEvaluator::new().eval_into(
            &formula.tape_all,
            [x, 0.0, 0.0, 0.0],
            &[],
            &mut grad,
        );
        let slope = f64::from(n) * want / x;
        assert!(
            (grad[1] - slope).abs() <= 1e-9 * slope.abs(),
            "d/dx {text} at {x}: {}",
            grad[1]
        );
    }
    // A constant's large power folds with its sign, too.
    let formula = CompiledFormula::compile("x + (-1)^2001").expect("(-1)^2001 is -1");
    assert_eq!(at(&formula, 3.0), 2.0);
}
