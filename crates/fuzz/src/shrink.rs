//! Shrinking a failing formula: try one-step simplifications (a term replaced by one of its
//! parts, by `x` or by `1`; the right side dropped) and keep the first that still fails,
//! until none does, so that the formula a failure prints is one a person can read.

use crate::formulas::{Formula, Term};

/// The smallest formula reached from `formula` by simplifications that keep `fails` true,
/// trying at most `tries` candidates.
pub fn shrink(formula: &Formula, tries: usize, mut fails: impl FnMut(&Formula) -> bool) -> Formula {
    let mut best = formula.clone();
    let mut left = tries;
    'outer: while left > 0 {
        for candidate in simpler(&best) {
            if left == 0 {
                break 'outer;
            }
            left -= 1;
            if fails(&candidate) {
                best = candidate;
                continue 'outer;
            }
        }
        break;
    }
    best
}

/// Every formula one simplification away from `formula`, the biggest cuts first.
fn simpler(formula: &Formula) -> Vec<Formula> {
    let mut out = Vec::new();
    if let Some(rhs) = &formula.rhs {
        out.push(Formula {
            lhs: formula.lhs.clone(),
            rhs: None,
        });
        out.push(Formula {
            lhs: rhs.clone(),
            rhs: None,
        });
        for r in simpler_terms(rhs) {
            out.push(Formula {
                lhs: formula.lhs.clone(),
                rhs: Some(r),
            });
        }
    }
    for l in simpler_terms(&formula.lhs) {
        out.push(Formula {
            lhs: l,
            rhs: formula.rhs.clone(),
        });
    }
    out
}

/// Every term one simplification away from `term`: itself replaced by a part, `x` or `1`,
/// or one of its parts simplified.
fn simpler_terms(term: &Term) -> Vec<Term> {
    let mut out: Vec<Term> = parts(term).into_iter().cloned().collect();
    for leaf in ["x", "1"] {
        let small = if leaf == "x" {
            Term::Name(leaf.into())
        } else {
            Term::Number(leaf.into())
        };
        if *term != small && !matches!(term, Term::Number(_) | Term::Name(_) | Term::Text(_)) {
            out.push(small);
        }
    }
    if let Term::Number(n) = term
        && n != "1"
    {
        out.push(Term::Number("1".into()));
    }
    let rebuild = |i: usize, part: Term| -> Term {
        let boxed = Box::new(part);
        match term {
            Term::Prefix(c, _) => Term::Prefix(*c, boxed),
            Term::Bars(_) => Term::Bars(boxed),
            Term::Group(_) => Term::Group(boxed),
            Term::Infix(op, _, b) if i == 0 => Term::Infix(op, boxed, b.clone()),
            Term::Infix(op, a, _) => Term::Infix(op, a.clone(), boxed),
            Term::Juxtaposed(_, b) if i == 0 => Term::Juxtaposed(boxed, b.clone()),
            Term::Juxtaposed(a, _) => Term::Juxtaposed(a.clone(), boxed),
            Term::Call(name, args) => {
                let mut args = args.clone();
                args[i] = *boxed;
                Term::Call(name.clone(), args)
            }
            Term::Number(_) | Term::Name(_) | Term::Text(_) => unreachable!("leaves have no parts"),
        }
    };
    for (i, part) in parts(term).into_iter().enumerate() {
        for p in simpler_terms(part) {
            out.push(rebuild(i, p));
        }
    }
    out
}

fn parts(term: &Term) -> Vec<&Term> {
    match term {
        Term::Number(_) | Term::Name(_) | Term::Text(_) => Vec::new(),
        Term::Prefix(_, a) | Term::Bars(a) | Term::Group(a) => vec![a],
        Term::Infix(_, a, b) | Term::Juxtaposed(a, b) => vec![a, b],
        Term::Call(_, args) => args.iter().collect(),
    }
}
