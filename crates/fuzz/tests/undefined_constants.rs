//! The issue's class of formulas: every function of the language at constants outside its
//! domain or where it overflows, alone and inside a formula that has a surface. Each is
//! refused with "F is undefined everywhere" and the culprit underlined, or drawn; none
//! reaches wgpu's evaluation of the shader's pipeline constants with an out-of-range
//! builtin or an infinite literal (what refused these formulas before).

use fourfold::CompiledFormula;
use fourfold::ops::{BINARY, UNARY};
use fourfold_fuzz::cases::{FormulaCase, Mode};
use fourfold_fuzz::check::{UNCOMPARED_RANGE, UNCOMPARED_TRIG, Verdict, check_formula};
use fourfold_fuzz::formulas::{Formula, Term};

#[path = "../../fourfold/tests/support/undefined_constants.rs"]
mod support;
use support::undefined_constants;

/// Outside a domain, at an edge, overflowing f32 or f64, ±∞ (a literal over f64's range is
/// refused as written, so ∞ is made by a product), and one that underflows to 0.
const CONSTANTS: &[&str] = &[
    "2",
    "-3",
    "0",
    "-1",
    "710",
    "1e39",
    "(1e308*10)",
    "(-1e308*10)",
    "1e-400",
];

fn case(text: &str) -> FormulaCase {
    FormulaCase {
        formula: Formula {
            lhs: Term::Text(text.to_string()),
            rhs: None,
        },
        params: Vec::new(),
        angles: [0.3, 0.5, 0.7, 0.1, 0.2, 0.3],
        size: [6, 5],
        max_level: 3,
        mode: Mode::Plain,
        gpu: false,
    }
}

/// `formula` draws or is refused on every path; refused, it says F is undefined and
/// underlines `culprit`.
fn drawn_or_refused(formula: &str, culprit: &str, dir: &std::path::Path) {
    let verdict = check_formula(&case(formula), dir).unwrap_or_else(|e| panic!("{formula}: {e}"));
    if let Verdict::Refused(_) = verdict {
        let error = CompiledFormula::compile(formula).expect_err(formula);
        assert_eq!(
            error.message, "F is undefined everywhere in the domain",
            "{formula}"
        );
        assert_eq!(&formula[error.span.clone()], culprit, "{formula}");
    }
}

#[test]
fn every_function_at_every_edge_constant_draws_or_says_why() {
    let dir = std::env::temp_dir().join("fourfold-undefined-constants");
    std::fs::create_dir_all(&dir).unwrap();
    for row in UNARY.iter().filter(|r| r.callable) {
        for c in CONSTANTS {
            let call = format!("{}({c})", row.name);
            drawn_or_refused(
                &format!("max({call}, x^2 + y^2 + z^2 + w^2 - 1)"),
                &call,
                &dir,
            );
            drawn_or_refused(&format!("{call}*x + y"), &call, &dir);
        }
    }
    for row in BINARY.iter() {
        for (a, b) in [
            ("-2", "0.5"),
            ("0", "-1"),
            ("2", "0"),
            ("1e308*10", "-1e308*10"),
            ("0", "1e308*10"),
        ] {
            let call = if row.callable {
                format!("{}({a}, {b})", row.name)
            } else {
                format!("({a}){}({b})", row.name)
            };
            drawn_or_refused(&format!("{call} + x^2 + y^2 + z^2 + w^2 - 1"), &call, &dir);
        }
    }
}

#[test]
fn the_issue_s_formulas_draw_or_say_why() {
    let dir = std::env::temp_dir().join("fourfold-issue-formulas");
    std::fs::create_dir_all(&dir).unwrap();
    // The issue's list (which every front end's test reads), and a few more of its kinds.
    let listed = undefined_constants()
        .into_iter()
        .map(|(formula, culprit)| (formula, culprit.unwrap_or("")));
    let more = [
        ("acos(-3)*x + y", "acos(-3)"),
        ("x/0 + y", "x/0"),
        ("1e300*1e300 = x", ""),
        ("x^2 + y^2 + z^2 + w^2 = 1e39", ""),
    ];
    let (mut refused, mut drawn) = (0, 0);
    for (formula, culprit) in listed.chain(more) {
        let verdict = check_formula(&case(formula), &dir);
        if culprit.is_empty() {
            // An overflow is ±∞, not undefined: these draw (nothing, or where F is finite).
            assert_eq!(verdict, Ok(Verdict::Drew), "{formula}");
            drawn += 1;
        } else {
            assert!(
                matches!(verdict, Ok(Verdict::Refused(_))),
                "{formula}: {verdict:?}"
            );
            drawn_or_refused(formula, culprit, &dir);
            refused += 1;
        }
    }
    assert_eq!((refused, drawn), (9, 7));
}

#[test]
fn huge_trigonometry_draws_on_the_gpu_but_is_not_compared_with_the_twin() {
    // Found by the long run: cos(1e30 xyz) is noise on the GPU and on the twin, a different
    // noise (WGSL bounds cos's error on [−π, π] only). It must still draw cleanly on both;
    // its pictures are not compared, and the run counts it. A moderate frequency is.
    let dir = std::env::temp_dir().join("fourfold-huge-trigonometry");
    std::fs::create_dir_all(&dir).unwrap();
    let on_gpu = |text: &str| FormulaCase {
        gpu: true,
        size: [12, 10],
        ..case(text)
    };
    let verdict = check_formula(&on_gpu("cos(1e30 xyz)"), &dir);
    assert!(
        verdict == Ok(Verdict::DrewUncompared(UNCOMPARED_TRIG)),
        "{verdict:?}"
    );
    assert_eq!(
        check_formula(&on_gpu("sin(40x) - y"), &dir),
        Ok(Verdict::Drew)
    );
}

#[test]
fn values_beyond_the_gpu_s_range_draw_but_are_not_compared_with_the_twin() {
    // Found by a long run (seed 77): 1e300 is beyond f32, and the GPU left undecided
    // (magenta) pixels of 1e300 z that the twin's f64 proves; since the GPU's products keep
    // a one-signed operand's sign it proves them too. 1e30 z^3's gradient still reaches
    // beyond the GPU's range (2^61). Both must draw cleanly on both; where the pictures
    // differ they are not compared, and the run counts it. Pictures that agree are still
    // compared, values beyond f32 or not.
    let dir = std::env::temp_dir().join("fourfold-beyond-f32");
    std::fs::create_dir_all(&dir).unwrap();
    let found = |text: &str| FormulaCase {
        gpu: true,
        size: [7, 5],
        angles: [3.0401, 0.8213, -3.4069, 1.5021, -2.4956, 2.4999],
        mode: Mode::Slice(0.085),
        ..case(text)
    };
    let beyond = FormulaCase {
        gpu: true,
        size: [12, 10],
        mode: Mode::Slice(0.1),
        ..case("1e30 z^3 - 1e30 x")
    };
    let verdict = check_formula(&beyond, &dir);
    assert!(
        verdict == Ok(Verdict::DrewUncompared(UNCOMPARED_RANGE)),
        "{verdict:?}"
    );
    assert_eq!(
        check_formula(&found("((1e300 z))"), &dir),
        Ok(Verdict::Drew)
    );
    let agreeing = FormulaCase {
        gpu: true,
        size: [12, 10],
        ..case("1e300 z")
    };
    assert_eq!(check_formula(&agreeing, &dir), Ok(Verdict::Drew));
}

#[test]
fn values_nearer_0_than_the_gpu_can_tell_draw_but_are_not_compared_with_the_twin() {
    // Found by a long run (seed 4242): 1e-320 is 0 in f32, so the GPU cannot prove that
    // F = 1e-320 has no zero, which the twin's f64 does: undecided pixels against empty
    // ones. Drawn cleanly on both, not compared where they differ, counted.
    let dir = std::env::temp_dir().join("fourfold-below-f32");
    std::fs::create_dir_all(&dir).unwrap();
    let found = FormulaCase {
        gpu: true,
        size: [7, 7],
        angles: [2.7038, 2.4976, 2.3582, 1.2644, -0.7326, -1.4046],
        max_level: 5,
        mode: Mode::BruteForce,
        ..case("1e-320")
    };
    let verdict = check_formula(&found, &dir);
    assert!(
        verdict == Ok(Verdict::DrewUncompared(UNCOMPARED_RANGE)),
        "{verdict:?}"
    );
}
