//! The formula language: precedence, associativity, implicit multiplication, equations,
//! functions, and the messages for bad input (pinned as snapshots).

mod common;

use common::{Rng, eval_f};
use fourfold::CompiledFormula;
use fourfold::syntax::parse;

/// Two formulas mean the same function if they agree at many points.
fn same_function(a: &str, b: &str) {
    let fa = CompiledFormula::compile(a).unwrap_or_else(|e| panic!("{a}: {}", e.render("a", a)));
    let fb = CompiledFormula::compile(b).unwrap_or_else(|e| panic!("{b}: {}", e.render("b", b)));
    assert_eq!(fa.param_names(), fb.param_names(), "{a} vs {b}");
    let params: Vec<f64> = (0..fa.params.len()).map(|i| 1.3 + i as f64 * 0.7).collect();
    let mut rng = Rng(0x5eed);
    for _ in 0..50 {
        let p = [(); 4].map(|_| rng.range(0.1, 2.0));
        let (va, vb) = (eval_f(&fa, p, &params), eval_f(&fb, p, &params));
        let tolerance = 1e-12 * (1.0 + va.abs());
        assert!(
            (va - vb).abs() <= tolerance || (va.is_nan() && vb.is_nan()),
            "{a} = {va} but {b} = {vb} at {p:?}"
        );
    }
}

#[test]
fn precedence_and_associativity() {
    same_function("x + y * z", "x + (y * z)");
    same_function("x - y - z", "(x - y) - z");
    same_function("x / y / z", "(x / y) / z");
    same_function("x ^ y ^ z", "x ^ (y ^ z)");
    same_function("2^3^2 + x", "512 + x");
    same_function("-x^2", "-(x^2)");
    same_function("-x*y", "(-x)*y");
    same_function("x^-2*y", "(x^(-2))*y");
    same_function("x*-y", "x*(-y)");
    same_function("x**2", "x^2");
    same_function("+x - -y", "x + y");
    same_function("x · y × z", "x*y*z");
}

#[test]
fn implicit_multiplication() {
    same_function("2x", "2*x");
    same_function("2x^2", "2*(x^2)");
    same_function("4R^2(x^2 + y^2)", "4*R^2*(x^2 + y^2)");
    same_function("(x+1)(x-1)", "(x+1)*(x-1)");
    same_function("3 sin(w)", "3*sin(w)");
    same_function("2 x y", "2*x*y");
    same_function("xy + zw", "x*y + z*w");
    same_function("x(y + 1)", "x*(y + 1)");
    same_function("R(x + 1)", "R*(x + 1)");
    same_function("|x||y|", "abs(x)*abs(y)");
    same_function("2|x - 1|", "2*abs(x - 1)");
    same_function("a/2b", "(a/2)*b");
    same_function("2e", "2*e");
    same_function(".5x + 1e-3y + 2.5", "0.5*x + 0.001*y + 2.5");
}

#[test]
fn equations_mean_lhs_minus_rhs() {
    same_function("x^2 + y^2 + z^2 + w^2 = 1", "x^2 + y^2 + z^2 + w^2 - 1");
    same_function("x = y^2 + 1", "x - (y^2 + 1)");
}

#[test]
fn the_chapters_formula_parses_as_printed() {
    let chapter = "w - (x^2 + y^2 + z^2 + R^2 - r^2)^2 + 4R^2(x^2 + y^2)";
    same_function(
        chapter,
        "w - (x^2 + y^2 + z^2 + R^2 - r^2)^2 + 4*R^2*(x^2 + y^2)",
    );
    let f = CompiledFormula::compile(chapter).unwrap();
    assert_eq!(f.param_names(), ["R", "r"]);
    // At the origin with R = 2, r = 1: w - (4 - 1)^2 = -9.
    assert_eq!(eval_f(&f, [0.0; 4], &[2.0, 1.0]), -9.0);
}

#[test]
fn every_function() {
    let x = 0.3_f64;
    let cases: &[(&str, f64)] = &[
        ("sin(x)", x.sin()),
        ("cos(x)", x.cos()),
        ("tan(x)", x.tan()),
        ("asin(x)", x.asin()),
        ("acos(x)", x.acos()),
        ("atan(x)", x.atan()),
        ("sinh(x)", x.sinh()),
        ("cosh(x)", x.cosh()),
        ("tanh(x)", x.tanh()),
        ("exp(x)", x.exp()),
        ("ln(x)", x.ln()),
        ("log(x)", x.ln()),
        ("sqrt(x)", x.sqrt()),
        ("cbrt(x)", x.cbrt()),
        ("abs(-x)", x),
        ("sign(-x)", -1.0),
        ("step(x)", 1.0),
        ("min(x, 0.2)", 0.2),
        ("max(x, 0.2)", x),
        ("pow(x, 2.5)", x.powf(2.5)),
        ("atan2(x, -1)", x.atan2(-1.0)),
        ("pi", std::f64::consts::PI),
        ("e", std::f64::consts::E),
        ("tau", std::f64::consts::TAU),
    ];
    for (text, expected) in cases {
        let f = CompiledFormula::compile(text).unwrap();
        let got = eval_f(&f, [x, 0.0, 0.0, 0.0], &[]);
        assert!(
            (got - expected).abs() < 1e-15,
            "{text}: {got} vs {expected}"
        );
    }
}

#[test]
fn parameters_are_names_in_order_of_appearance() {
    let f = CompiledFormula::compile("a1 x + b_2 y^2 - a1 = Rr").unwrap();
    assert_eq!(f.param_names(), ["a1", "b_2", "Rr"]);
    assert_eq!(f.params[1].span, 7..10);
}

fn error_of(source: &str) -> String {
    match CompiledFormula::compile(source) {
        Ok(_) => panic!("{source:?} should not compile"),
        Err(e) => e.render("formula", source),
    }
}

#[test]
fn error_messages() {
    let bad = [
        "",
        "x^",
        "x +",
        "sn(x)",
        "sqr(x)",
        "sin x",
        "x^2 + (y",
        "x)",
        "|x + 1",
        "x + * y",
        "()",
        "x = y = z",
        "min(x)",
        "sin(x, y)",
        "2 $ x",
        "x²",
        "1e999",
        "x,y",
        "foo(x, y)",
        "x = ",
        "1.2.3",
        "|x| |",
        "2 ** ",
    ];
    let mut all = String::new();
    for source in bad {
        all.push_str(&format!("=== {source:?}\n{}\n", error_of(source)));
    }
    insta::assert_snapshot!(all);
}

#[test]
fn huge_and_deep_input_errors_or_works_without_overflow() {
    // 10 000 nested parentheses: refused with a message, no stack overflow.
    let deep = format!("{}x{}", "(".repeat(10_000), ")".repeat(10_000));
    assert!(error_of(&deep).contains("nested more than"));
    // A 1 MB formula: refused with a message.
    let huge = "x+".repeat(500_000) + "x";
    assert!(error_of(&huge).contains("bytes long"));
    // Long chains under the limit work: left-deep sums, right-deep powers, many minus signs.
    let sum = "x+".repeat(20_000) + "x";
    let f = CompiledFormula::compile(&sum).unwrap();
    assert_eq!(eval_f(&f, [1.0, 0.0, 0.0, 0.0], &[]), 20_001.0);
    let tower = "1^".repeat(20_000) + "x";
    CompiledFormula::compile(&tower).unwrap();
    let minus = "-".repeat(20_000) + "x";
    CompiledFormula::compile(&minus).unwrap();
    // Many absolute values side by side parse in bounded time.
    let bars = "|x|".repeat(2_000);
    CompiledFormula::compile(&bars).unwrap();
    // Nested bars parse without backtracking.
    let nested = format!("{}x{}", "|".repeat(200), "|".repeat(200));
    let f = CompiledFormula::compile(&nested).unwrap();
    assert_eq!(eval_f(&f, [-2.0, 0.0, 0.0, 0.0], &[]), 2.0);
    same_function("||x| - 1|", "abs(abs(x) - 1)");
}

#[test]
fn the_syntax_tree_keeps_spans() {
    let ast = parse("x + sin(y)").unwrap();
    assert_eq!(ast.lhs.span, 0..10);
    assert!(ast.rhs.is_none());
}

#[test]
fn the_caret_window_keeps_the_caret_and_its_label_in_view_at_any_width() {
    // Errors early, in the middle and at the end of a long formula, and in a short one.
    let long = "sin(3x)cos(3y) + sin(3z)cos(3w) - 0.2 + ".repeat(4);
    let sources = [
        format!("{long}sn(x"),
        format!("{long}x +* y"),
        format!("sn(x) + {long}"),
        format!("{}foo(x) + {}", &long[..80], &long[80..]),
        "x +".to_string(),
        "x² + y".to_string(),
    ];
    for source in &sources {
        let error = CompiledFormula::compile(source).expect_err(source);
        let first = source[error.span.start..].chars().next();
        for columns in [12, 20, 33, 48, 80, 400] {
            let w = error.caret_window(source, columns);
            let width = |s: &str| s.chars().count();
            assert!(width(&w.source) <= columns, "{columns}: {w:?}");
            assert!(width(&w.carets) <= columns, "{columns}: {w:?}");
            let caret = w.carets.find('^').expect("a caret");
            assert!(w.carets[..caret].chars().all(|c| c == ' '));
            // The caret is under the span's first character (or just past the line's end).
            let under = w.source.chars().nth(caret);
            assert!(
                under == first || (first.is_none() && under.is_none()),
                "{columns} columns: caret under {under:?}, span starts with {first:?}: {w:?}"
            );
            let label = w.label.as_deref().unwrap_or(&w.carets);
            assert!(label.contains(&error.label), "{w:?}");
            if let Some(label) = &w.label {
                assert!(
                    width(label) <= columns.max(width(&error.label)),
                    "{columns}: {w:?}"
                );
            }
        }
    }
}

#[test]
fn a_control_character_gets_a_caret_too() {
    // A NUL has no width: shown as it is, the caret under it vanished.
    let source = "x + \u{0} y";
    let error = CompiledFormula::compile(source).expect_err("a NUL is not in the language");
    let shown = error.render("formula", source);
    assert!(
        shown.contains("^ not part of the formula language"),
        "{shown}"
    );
    assert!(
        shown.contains("'\\u{0}'"),
        "the character is named: {shown}"
    );
    assert!(!shown.contains('\u{0}'), "{shown}");
}
