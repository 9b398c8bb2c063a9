//! WGSL for a tape: one `let` per instruction, in order, so that shared subexpressions are
//! computed once and a deep formula never nests deeply; at a point in f32, or as rigorous
//! intervals over a box (with `templates/interval.wgsl`).
//!
//! Each operation's WGSL is its row of the table in `crate::ops`. Undefined values follow the
//! CPU point evaluator: sqrt/ln/asin/acos outside their domain, division by 0, a negative or
//! zero base of a real power with an exponent that needs a positive one — all give NaN (from
//! the uniform, `ff_nan()`), and a NaN sample never makes a sign change, so no root is drawn
//! there. The graph folds every operation on constants, so no WGSL operation here has
//! constant operands only; each constant is read from the formula's table (`constants`).
//!
//! WGSL leaves a builtin's value on a NaN indeterminate (lavapipe's `pow(NaN, x)` is a
//! number), so at a point each value carries a flag, `n{i}`, set where it or a value it was
//! made from was NaN before a builtin saw it; an output whose flag is set is NaN. The flags
//! are booleans tested on the values' bits (integer work no compiler treats as NaN-free).

use std::fmt::Write as _;

use crate::eval::{Instr, Tape};

use super::constants::Constants;

/// How a tape becomes WGSL: in f32 at a point, or as rigorous intervals over a box.
pub(super) struct Flavour {
    /// The parameters after the function's name.
    params: &'static str,
    /// An instruction's value, as an expression of earlier `s{i}` and the formula's
    /// constants (all but Powi).
    expression: fn(Instr, &Constants) -> String,
    /// `let s{i} = s{a}^n`, through helper lets as needed.
    powi_lets: fn(&mut String, usize, u32, i32),
    /// Carry the undefined flags (at a point; intervals carry emptiness instead).
    flags: bool,
}

pub(super) const POINT: Flavour = Flavour {
    params: "p: vec4<f32>",
    expression,
    powi_lets,
    flags: true,
};

/// With the operations of `templates/interval.wgsl` (see docs/method.md §5.9).
pub(super) const INTERVAL: Flavour = Flavour {
    params: "lo: vec4<f32>, hi: vec4<f32>",
    expression: interval_expression,
    powi_lets: interval_powi_lets,
    flags: false,
};

/// The WGSL function `name` computing `tape` in `flavour`, its numbers read from
/// `constants`' table: one `let` per instruction, then the return of `result` of the
/// outputs, of type `ret`.
pub(super) fn tape_function(
    (flavour, constants): (&Flavour, &Constants),
    name: &str,
    ret: &str,
    tape: &Tape,
    result: impl Fn(&[String]) -> String,
) -> String {
    let mut body = String::new();
    let _ = writeln!(body, "fn {name}({}) -> {ret} {{", flavour.params);
    let mut flags = Flags::new(tape.len());
    for (i, instr) in tape.instrs().iter().enumerate() {
        if flavour.flags {
            flags.write(&mut body, i, *instr);
        }
        if let Instr::Powi(a, n) = *instr {
            (flavour.powi_lets)(&mut body, i, a, n);
        } else {
            let expression = (flavour.expression)(*instr, constants);
            let _ = writeln!(body, "    let s{i} = {expression};");
        }
    }
    let outputs: Vec<String> = tape
        .outputs()
        .iter()
        .map(|&o| {
            if flavour.flags {
                flags.guarded(o)
            } else {
                format!("s{o}")
            }
        })
        .collect();
    let _ = writeln!(body, "    return {};", result(&outputs));
    body.push('}');
    body
}

/// Which values carry an undefined flag (those made, at any depth, from a value a builtin
/// takes), and which are leaves: a coordinate, a parameter or a defined constant, never NaN.
struct Flags {
    flagged: Vec<bool>,
    leaf: Vec<bool>,
}

impl Flags {
    fn new(len: usize) -> Self {
        Self {
            flagged: vec![false; len],
            leaf: vec![false; len],
        }
    }

    /// The flag of value `a` OR'd with a test of its bits: what an operation on it inherits.
    /// The flags join with `|`, not `||`: a short-circuit or is a branch in naga's and the
    /// browsers' output, and SwiftShader's compile time grows superlinearly with branches (the
    /// tiger's first frame there took 4.5–4.8 s with `||`, 0.3 s with `|`).
    fn of_input(&self, a: u32, test_bits: bool) -> Option<String> {
        let mut parts = Vec::new();
        if self.flagged[a as usize] {
            parts.push(format!("n{a}"));
        }
        if test_bits && !self.leaf[a as usize] {
            parts.push(format!("ff_undefined(s{a})"));
        }
        (!parts.is_empty()).then(|| parts.join(" | "))
    }

    /// `let n{i} = …;` for instruction i, where it carries a flag. Arithmetic (+, −, ×,
    /// negation, integer powers) keeps a NaN in hardware, so only its inputs' flags pass
    /// on; every other operation is a builtin or a select, and its inputs' bits are tested.
    fn write(&mut self, body: &mut String, i: usize, instr: Instr) {
        use crate::expr::{BinaryOp, UnaryOp};
        let (inputs, builtin): (Vec<u32>, bool) = match instr {
            // An undefined constant is the run-time NaN: tested like a computed value.
            Instr::Const(v) => {
                self.leaf[i] = !v.is_nan();
                return;
            }
            Instr::Var(_) | Instr::Param(_) => {
                self.leaf[i] = true;
                return;
            }
            Instr::Powi(a, _) | Instr::Unary(UnaryOp::Neg, a) => (vec![a], false),
            Instr::Binary(BinaryOp::Add | BinaryOp::Sub | BinaryOp::Mul, a, b) => {
                (vec![a, b], false)
            }
            Instr::Unary(_, a) => (vec![a], true),
            Instr::Binary(_, a, b) => (vec![a, b], true),
        };
        let parts: Vec<String> = inputs
            .iter()
            .filter_map(|&a| self.of_input(a, builtin))
            .collect();
        if !parts.is_empty() {
            let _ = writeln!(body, "    let n{i} = {};", parts.join(" | "));
            self.flagged[i] = true;
        }
    }

    /// Output `o`: NaN where its flag is set (a NaN it is itself stays one).
    fn guarded(&self, o: u32) -> String {
        if self.flagged[o as usize] {
            format!("select(s{o}, ff_nan(), n{o})")
        } else {
            format!("s{o}")
        }
    }
}

fn interval_expression(instr: Instr, constants: &Constants) -> String {
    let s = |i: u32| format!("s{i}");
    match instr {
        Instr::Const(v) => format!("ff_const_box({}u)", constants.index(v)),
        Instr::Var(a) => {
            let c = ["x", "y", "z", "w"][a as usize & 3];
            format!("vec2<f32>(lo.{c}, hi.{c})")
        }
        Instr::Param(i) => format!("iv_param({i}u)"),
        Instr::Powi(..) => unreachable!("integer powers are written by interval_powi_lets"),
        Instr::Unary(op, a) => format!("{}({})", op.spec().wgsl_interval, s(a)),
        Instr::Binary(op, a, b) => format!("{}({}, {})", op.spec().wgsl_interval, s(a), s(b)),
    }
}

/// `let s{i} = s{a}^n` in intervals: square and multiply (squares through `iv_sqr`, never
/// negative), and 1 / x^|n| for a negative n.
fn interval_powi_lets(body: &mut String, i: usize, a: u32, n: i32) {
    let mut result: Option<String> = None;
    let mut square = format!("s{a}");
    let mut bits = n.unsigned_abs();
    let mut j = 0;
    while bits > 0 {
        if bits & 1 == 1 {
            result = Some(match result {
                None => square.clone(),
                Some(r) => {
                    let next = format!("s{i}_m{j}");
                    let _ = writeln!(body, "    let {next} = iv_mul({r}, {square});");
                    next
                }
            });
        }
        bits >>= 1;
        if bits > 0 {
            let next = format!("s{i}_q{j}");
            let _ = writeln!(body, "    let {next} = iv_sqr({square});");
            square = next;
        }
        j += 1;
    }
    let positive = result.unwrap_or_else(|| "vec2<f32>(1.0)".into());
    let value = if n < 0 {
        format!("iv_div(vec2<f32>(1.0), {positive})")
    } else {
        positive
    };
    let _ = writeln!(body, "    let s{i} = {value};");
}

fn expression(instr: Instr, constants: &Constants) -> String {
    let s = |i: u32| format!("s{i}");
    match instr {
        Instr::Const(v) => format!("ff_const({}u)", constants.index(v)),
        Instr::Var(a) => format!("p.{}", ["x", "y", "z", "w"][a as usize]),
        Instr::Param(i) => format!("ff_param({i}u)"),
        Instr::Powi(..) => unreachable!("integer powers are written by powi_lets"),
        Instr::Unary(op, a) => (op.spec().wgsl)(&s(a)),
        Instr::Binary(op, a, b) => (op.spec().wgsl)(&s(a), &s(b)),
    }
}

/// `let s{i} = s{a}^n` as multiplications: square and multiply, one `let` per square.
fn powi_lets(body: &mut String, i: usize, a: u32, n: i32) {
    let k = n.unsigned_abs();
    let x = format!("s{a}");
    let positive = if k <= 4 {
        vec![x.as_str(); k as usize].join(" * ")
    } else {
        let mut factors = Vec::new();
        let mut square = x.clone();
        let mut bits = k;
        let mut j = 0;
        while bits > 0 {
            if bits & 1 == 1 {
                factors.push(square.clone());
            }
            bits >>= 1;
            if bits > 0 {
                let next = format!("s{i}_{j}");
                let _ = writeln!(body, "    let {next} = {square} * {square};");
                square = next;
                j += 1;
            }
        }
        factors.join(" * ")
    };
    let value = if n < 0 {
        format!("select(1.0 / ({positive}), ff_nan(), {x} == 0.0)")
    } else {
        format!("({positive})")
    };
    let _ = writeln!(body, "    let s{i} = {value};");
}
