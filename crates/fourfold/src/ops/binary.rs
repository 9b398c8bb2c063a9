//! The table of two-argument operations: as `unary.rs`'s, with the infix symbol of the
//! arithmetic operators.

use crate::interval::Interval;

use super::op::{BinaryOp, Build, Builder, NodeId, UnaryOp};

/// Everything fourfold knows about one binary operation.
pub struct BinarySpec {
    pub op: BinaryOp,
    /// How a formula calls it and how it is printed (`min`); the symbol for an operator.
    pub name: &'static str,
    /// Whether a formula calls it by name (`min(a, b)`) rather than writing an operator.
    pub callable: bool,
    /// Its value at two real numbers: NaN outside its domain.
    pub point: fn(f64, f64) -> f64,
    /// Its interval extension (sound: holds every value over the arguments).
    pub interval: fn(Interval, Interval) -> Interval,
    /// Whether it is defined and continuous on all of its arguments' enclosures.
    pub continuous: fn(Interval, Interval) -> bool,
    /// d f(u, v), given u, v, f = f(u, v), du and dv (not both 0).
    pub derivative: fn(&mut dyn Builder, Operands) -> NodeId,
    /// Its WGSL at a point, from the WGSL of its arguments (NaN outside its domain).
    pub wgsl: fn(&str, &str) -> String,
    /// Its rigorous interval function in `templates/interval.wgsl`.
    pub wgsl_interval: &'static str,
    /// Where defined arguments give an undefined value, as a message says it.
    pub undefined: &'static str,
}

/// What a binary derivative rule is given.
#[derive(Debug, Clone, Copy)]
pub struct Operands {
    pub u: NodeId,
    pub v: NodeId,
    pub f: NodeId,
    pub du: NodeId,
    pub dv: NodeId,
}

impl BinaryOp {
    /// This operation's row of the table.
    pub fn spec(self) -> &'static BinarySpec {
        let spec = &BINARY[self as usize];
        debug_assert_eq!(spec.op, self, "the table follows the enum's order");
        spec
    }
}

fn always(_: Interval, _: Interval) -> bool {
    true
}

/// Undefined stays undefined (f64::min and max would drop a NaN).
fn either_nan(a: f64, b: f64) -> bool {
    a.is_nan() || b.is_nan()
}

/// The rows, in the order of [`BinaryOp`]'s variants.
pub static BINARY: [BinarySpec; 8] = [
    BinarySpec {
        op: BinaryOp::Min,
        name: "min",
        callable: true,
        point: |a, b| if either_nan(a, b) { f64::NAN } else { a.min(b) },
        interval: Interval::min,
        continuous: always,
        derivative: |b, o| branch(b, o, BinaryOp::Min),
        wgsl: |a, b| format!("min({a}, {b})"),
        wgsl_interval: "iv_min",
        undefined: "min is defined everywhere",
    },
    BinarySpec {
        op: BinaryOp::Max,
        name: "max",
        callable: true,
        point: |a, b| if either_nan(a, b) { f64::NAN } else { a.max(b) },
        interval: Interval::max,
        continuous: always,
        derivative: |b, o| branch(b, o, BinaryOp::Max),
        wgsl: |a, b| format!("max({a}, {b})"),
        wgsl_interval: "iv_max",
        undefined: "max is defined everywhere",
    },
    BinarySpec {
        op: BinaryOp::Pow,
        name: "pow",
        callable: true,
        // Real power: a negative base has no real power for a non-integer exponent, and
        // IEEE's pow(1, NaN) = 1 would hide an undefined exponent.
        point: |a, b| {
            if a < 0.0 || (a == 0.0 && b < 0.0) || either_nan(a, b) {
                f64::NAN
            } else {
                a.powf(b)
            }
        },
        interval: Interval::pow,
        // (0^b = 0 for every b > 0: a base that reaches 0 keeps it continuous there.)
        continuous: |a, b| a.lo() > 0.0 || (a.lo() >= 0.0 && b.lo() > 0.0),
        derivative: power,
        wgsl: |a, b| {
            format!(
                "select(select(pow({a}, {b}), 1.0, {b} == 0.0), ff_nan(), {a} < 0.0 || ({a} == 0.0 && {b} < 0.0))"
            )
        },
        wgsl_interval: "iv_pow",
        undefined: "a real power of a negative number, or of 0 to a power ≤ 0, is undefined",
    },
    BinarySpec {
        op: BinaryOp::Atan2,
        name: "atan2",
        callable: true,
        point: f64::atan2,
        interval: Interval::atan2,
        // Off its cut, the negative x half-axis.
        continuous: |y, x| x.lo() > 0.0 || y.lo() > 0.0 || y.hi() < 0.0,
        // atan2(u, v)' = (v u' − u v') / (u² + v²)
        derivative: |b, Operands { u, v, du, dv, .. }| {
            let x = b.mul(v, du);
            let y = b.mul(u, dv);
            let num = b.sub(x, y);
            let u2 = b.powi(u, 2);
            let v2 = b.powi(v, 2);
            let den = b.add(u2, v2);
            b.div(num, den)
        },
        wgsl: |a, b| format!("atan2({a}, {b})"),
        wgsl_interval: "iv_atan2",
        undefined: "atan2 is defined everywhere",
    },
    BinarySpec {
        op: BinaryOp::Add,
        name: "+",
        callable: false,
        point: |a, b| a + b,
        interval: Interval::add,
        continuous: always,
        derivative: |b, o| b.add(o.du, o.dv),
        wgsl: |a, b| format!("{a} + {b}"),
        wgsl_interval: "iv_add",
        undefined: "∞ + (−∞) is undefined",
    },
    BinarySpec {
        op: BinaryOp::Sub,
        name: "-",
        callable: false,
        point: |a, b| a - b,
        interval: Interval::sub,
        continuous: always,
        derivative: |b, o| b.sub(o.du, o.dv),
        wgsl: |a, b| format!("{a} - {b}"),
        wgsl_interval: "iv_sub",
        undefined: "∞ − ∞ is undefined",
    },
    BinarySpec {
        op: BinaryOp::Mul,
        name: "*",
        callable: false,
        point: |a, b| a * b,
        interval: Interval::mul,
        continuous: always,
        derivative: |b, Operands { u, v, du, dv, .. }| {
            let x = b.mul(du, v);
            let y = b.mul(u, dv);
            b.add(x, y)
        },
        wgsl: |a, b| format!("{a} * {b}"),
        wgsl_interval: "iv_mul",
        undefined: "0 · ∞ is undefined",
    },
    BinarySpec {
        op: BinaryOp::Div,
        name: "/",
        callable: false,
        // A pole is undefined, like a square root of a negative number: x/0 is NaN, not ∞,
        // matching the interval rule that [a]/[0, 0] is empty.
        point: |a, b| if b == 0.0 { f64::NAN } else { a / b },
        interval: Interval::div,
        continuous: |_, b| !b.contains_zero(),
        derivative: quotient,
        wgsl: |a, b| format!("select({a} / {b}, ff_nan(), {b} == 0.0)"),
        wgsl_interval: "iv_div",
        undefined: "division by 0 is undefined",
    },
];

/// (u/v)' = u'/v where v is constant, else (u'v − uv') / v².
fn quotient(b: &mut dyn Builder, Operands { u, v, du, dv, .. }: Operands) -> NodeId {
    if b.is_const(dv, 0.0) {
        return b.div(du, v);
    }
    let x = b.mul(du, v);
    let y = b.mul(u, dv);
    let num = b.sub(x, y);
    let den = b.powi(v, 2);
    b.div(num, den)
}

/// (u^v)' = v·u^(v−1)·u' where v is constant, else u^v · (v'·ln u + v·u'/u).
fn power(b: &mut dyn Builder, Operands { u, v, f, du, dv }: Operands) -> NodeId {
    if b.is_const(dv, 0.0) {
        let one = b.constant(1.0);
        let vm1 = b.sub(v, one);
        let p = b.binary(BinaryOp::Pow, u, vm1);
        let vp = b.mul(v, p);
        return b.mul(vp, du);
    }
    if b.is_const(u, 0.0) {
        // 0^v is 0 wherever it is defined (v > 0): its ln u term would be undefined.
        return b.constant(0.0);
    }
    let ln = b.unary(UnaryOp::Ln, u);
    let x = b.mul(dv, ln);
    let vdu = b.mul(v, du);
    let y = b.div(vdu, u);
    let s = b.add(x, y);
    b.mul(f, s)
}

/// The derivative of the branch min or max takes: step(v − u) picks u for min.
fn branch(b: &mut dyn Builder, Operands { u, v, du, dv, .. }: Operands, op: BinaryOp) -> NodeId {
    let diff = if op == BinaryOp::Min {
        b.sub(v, u)
    } else {
        b.sub(u, v)
    };
    let pick_u = b.unary(UnaryOp::Step, diff);
    let one = b.constant(1.0);
    let pick_v = b.sub(one, pick_u);
    let x = b.mul(pick_u, du);
    let y = b.mul(pick_v, dv);
    b.add(x, y)
}
