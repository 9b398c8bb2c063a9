//! The table of one-argument operations: for each, its name, its value at a real number,
//! its interval extension and where it is continuous, its derivative rule, and its WGSL at
//! a point and over a box. A new function of the language is a new row (and, where it needs
//! one, an `iv_` function in `templates/interval.wgsl` and an `Interval` method).

use crate::interval::Interval;

use super::op::{Build, Builder, NodeId, UnaryOp};

/// Everything fourfold knows about one unary operation.
pub struct UnarySpec {
    pub op: UnaryOp,
    /// How a formula calls it and how it is printed (`sin`); `-` for negation.
    pub name: &'static str,
    /// Other names a formula may call it by (`log` for `ln`).
    pub aliases: &'static [&'static str],
    /// Whether a formula calls it by name (negation is written as an operator).
    pub callable: bool,
    /// Its value at a real number: NaN outside its domain.
    pub point: fn(f64) -> f64,
    /// Its interval extension (sound: holds every value over the argument).
    pub interval: fn(Interval) -> Interval,
    /// Whether it is defined and continuous on all of an argument's enclosure.
    pub continuous: fn(Interval) -> bool,
    /// d f(u), given u, f = f(u) and du (not 0).
    pub derivative: fn(&mut dyn Builder, NodeId, NodeId, NodeId) -> NodeId,
    /// Its WGSL at a point, from the WGSL of its argument (NaN outside its domain).
    pub wgsl: fn(&str) -> String,
    /// Its rigorous interval function in `templates/interval.wgsl`.
    pub wgsl_interval: &'static str,
    /// Where a defined argument gives an undefined value, as a message says it.
    pub undefined: &'static str,
}

impl UnaryOp {
    /// This operation's row of the table.
    pub fn spec(self) -> &'static UnarySpec {
        let spec = &UNARY[self as usize];
        debug_assert_eq!(spec.op, self, "the table follows the enum's order");
        spec
    }
}

fn always(_: Interval) -> bool {
    true
}

fn away_from_zero(a: Interval) -> bool {
    !a.contains_zero()
}

/// f'(u)·du with f'(u) = `fprime(b, u, f)`: the chain rule of most rows.
fn chain(
    b: &mut dyn Builder,
    du: NodeId,
    fprime: impl FnOnce(&mut dyn Builder) -> NodeId,
) -> NodeId {
    let fp = fprime(&mut *b);
    b.mul(fp, du)
}

/// du / (1 ∓ u²)-style rules: du over `den`.
fn over(b: &mut dyn Builder, du: NodeId, den: NodeId) -> NodeId {
    b.div(du, den)
}

/// The rows, in the order of [`UnaryOp`]'s variants.
pub static UNARY: [UnarySpec; 17] = [
    UnarySpec {
        op: UnaryOp::Sin,
        name: "sin",
        aliases: &[],
        callable: true,
        point: f64::sin,
        interval: Interval::sin,
        continuous: always,
        derivative: |b, u, _, du| chain(b, du, |b| b.unary(UnaryOp::Cos, u)),
        wgsl: |a| format!("sin({a})"),
        wgsl_interval: "iv_sin",
        undefined: "sin is undefined at ±∞",
    },
    UnarySpec {
        op: UnaryOp::Cos,
        name: "cos",
        aliases: &[],
        callable: true,
        point: f64::cos,
        interval: Interval::cos,
        continuous: always,
        derivative: |b, u, _, du| {
            chain(b, du, |b| {
                let s = b.unary(UnaryOp::Sin, u);
                b.neg(s)
            })
        },
        wgsl: |a| format!("cos({a})"),
        wgsl_interval: "iv_cos",
        undefined: "cos is undefined at ±∞",
    },
    UnarySpec {
        op: UnaryOp::Tan,
        name: "tan",
        aliases: &[],
        callable: true,
        point: f64::tan,
        interval: Interval::tan,
        continuous: always,
        derivative: |b, u, _, du| {
            let c = b.unary(UnaryOp::Cos, u);
            let c2 = b.powi(c, 2);
            over(b, du, c2)
        },
        wgsl: |a| format!("tan({a})"),
        wgsl_interval: "iv_tan",
        undefined: "tan is undefined at ±∞",
    },
    UnarySpec {
        op: UnaryOp::Asin,
        name: "asin",
        aliases: &[],
        callable: true,
        point: f64::asin,
        interval: Interval::asin,
        continuous: |a| a.lo() >= -1.0 && a.hi() <= 1.0,
        derivative: |b, u, _, du| over_root_of_one_minus_square(b, u, du),
        wgsl: |a| format!("select(asin({a}), ff_nan(), abs({a}) > 1.0)"),
        wgsl_interval: "iv_asin",
        undefined: "asin is undefined outside [−1, 1]",
    },
    UnarySpec {
        op: UnaryOp::Acos,
        name: "acos",
        aliases: &[],
        callable: true,
        point: f64::acos,
        interval: Interval::acos,
        continuous: |a| a.lo() >= -1.0 && a.hi() <= 1.0,
        derivative: |b, u, _, du| {
            let q = over_root_of_one_minus_square(b, u, du);
            b.neg(q)
        },
        wgsl: |a| format!("select(acos({a}), ff_nan(), abs({a}) > 1.0)"),
        wgsl_interval: "iv_acos",
        undefined: "acos is undefined outside [−1, 1]",
    },
    UnarySpec {
        op: UnaryOp::Atan,
        name: "atan",
        aliases: &[],
        callable: true,
        point: f64::atan,
        interval: Interval::atan,
        continuous: always,
        derivative: |b, u, _, du| {
            let one = b.constant(1.0);
            let u2 = b.powi(u, 2);
            let den = b.add(one, u2);
            over(b, du, den)
        },
        wgsl: |a| format!("atan({a})"),
        wgsl_interval: "iv_atan",
        undefined: "atan is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Sinh,
        name: "sinh",
        aliases: &[],
        callable: true,
        point: f64::sinh,
        interval: Interval::sinh,
        continuous: always,
        derivative: |b, u, _, du| chain(b, du, |b| b.unary(UnaryOp::Cosh, u)),
        wgsl: |a| format!("sinh({a})"),
        wgsl_interval: "iv_sinh",
        undefined: "sinh is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Cosh,
        name: "cosh",
        aliases: &[],
        callable: true,
        point: f64::cosh,
        interval: Interval::cosh,
        continuous: always,
        derivative: |b, u, _, du| chain(b, du, |b| b.unary(UnaryOp::Sinh, u)),
        wgsl: |a| format!("cosh({a})"),
        wgsl_interval: "iv_cosh",
        undefined: "cosh is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Tanh,
        name: "tanh",
        aliases: &[],
        callable: true,
        point: f64::tanh,
        interval: Interval::tanh,
        continuous: always,
        derivative: |b, _, f, du| {
            chain(b, du, |b| {
                let one = b.constant(1.0);
                let t2 = b.powi(f, 2);
                b.sub(one, t2)
            })
        },
        wgsl: |a| format!("tanh({a})"),
        wgsl_interval: "iv_tanh",
        undefined: "tanh is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Exp,
        name: "exp",
        aliases: &[],
        callable: true,
        point: f64::exp,
        interval: Interval::exp,
        continuous: always,
        derivative: |b, _, f, du| b.mul(f, du),
        wgsl: |a| format!("exp({a})"),
        wgsl_interval: "iv_exp",
        undefined: "exp is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Ln,
        name: "ln",
        aliases: &["log"],
        callable: true,
        // ln(0) is a pole: undefined, like x/0 (IEEE's −∞ would look like a value).
        point: |v| if v == 0.0 { f64::NAN } else { v.ln() },
        interval: Interval::ln,
        continuous: |a| a.lo() > 0.0,
        derivative: |b, u, _, du| b.div(du, u),
        wgsl: |a| format!("select(log({a}), ff_nan(), {a} <= 0.0)"),
        wgsl_interval: "iv_ln",
        undefined: "ln is undefined at 0 and below",
    },
    UnarySpec {
        op: UnaryOp::Sqrt,
        name: "sqrt",
        aliases: &[],
        callable: true,
        point: f64::sqrt,
        interval: Interval::sqrt,
        continuous: |a| a.lo() >= 0.0,
        // 1 / (2 sqrt u)
        derivative: |b, _, f, du| {
            let two = b.constant(2.0);
            let den = b.mul(two, f);
            b.div(du, den)
        },
        wgsl: |a| format!("select(sqrt({a}), ff_nan(), {a} < 0.0)"),
        wgsl_interval: "iv_sqrt",
        undefined: "sqrt is undefined below 0",
    },
    UnarySpec {
        op: UnaryOp::Cbrt,
        name: "cbrt",
        aliases: &[],
        callable: true,
        point: f64::cbrt,
        interval: Interval::cbrt,
        continuous: always,
        derivative: |b, _, f, du| {
            let three = b.constant(3.0);
            let sq = b.powi(f, 2);
            let den = b.mul(three, sq);
            b.div(du, den)
        },
        wgsl: |a| format!("sign({a}) * pow(abs({a}), 1.0 / 3.0)"),
        wgsl_interval: "iv_cbrt",
        undefined: "cbrt is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Abs,
        name: "abs",
        aliases: &[],
        callable: true,
        point: f64::abs,
        interval: Interval::abs,
        continuous: always,
        derivative: |b, u, _, du| chain(b, du, |b| b.unary(UnaryOp::Sign, u)),
        wgsl: |a| format!("abs({a})"),
        wgsl_interval: "iv_abs",
        undefined: "abs is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Sign,
        name: "sign",
        aliases: &[],
        callable: true,
        point: |v| {
            if v > 0.0 {
                1.0
            } else if v < 0.0 {
                -1.0
            } else if v == 0.0 {
                0.0
            } else {
                f64::NAN
            }
        },
        interval: Interval::sign,
        continuous: away_from_zero,
        derivative: |b, _, _, _| b.constant(0.0),
        wgsl: |a| format!("sign({a})"),
        wgsl_interval: "iv_sign",
        undefined: "sign is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Step,
        name: "step",
        aliases: &[],
        callable: true,
        point: |v| {
            if v > 0.0 {
                1.0
            } else if v < 0.0 {
                0.0
            } else if v == 0.0 {
                0.5
            } else {
                f64::NAN
            }
        },
        interval: Interval::step,
        continuous: away_from_zero,
        derivative: |b, _, _, _| b.constant(0.0),
        wgsl: |a| format!("select(select(0.0, 1.0, {a} > 0.0), 0.5, {a} == 0.0)"),
        wgsl_interval: "iv_step",
        undefined: "step is defined everywhere",
    },
    UnarySpec {
        op: UnaryOp::Neg,
        name: "-",
        aliases: &[],
        callable: false,
        point: |v| -v,
        interval: Interval::neg,
        continuous: always,
        derivative: |b, _, _, du| b.neg(du),
        wgsl: |a| format!("-{a}"),
        wgsl_interval: "iv_neg",
        undefined: "negation is defined everywhere",
    },
];

/// ±du / √(1 − u²): asin's and acos's rule (without the sign).
fn over_root_of_one_minus_square(b: &mut dyn Builder, u: NodeId, du: NodeId) -> NodeId {
    let one = b.constant(1.0);
    let u2 = b.powi(u, 2);
    let diff = b.sub(one, u2);
    let root = b.unary(UnaryOp::Sqrt, diff);
    b.div(du, root)
}
