//! The formula language's operations, each a row of one table ([`UNARY`], [`BINARY`]): its
//! name, its value at a point, its interval extension and continuity, its derivative rule,
//! and its WGSL. Lowering, folding, differentiation, printing, both evaluators and the
//! shader's code generation all read the rows, so adding a function to the language is
//! adding a row (and its interval rule where it needs one). Beneath the pipeline, beside
//! [`crate::interval`].

mod binary;
mod op;
mod unary;
mod words;

pub use binary::{BINARY, BinarySpec, Operands};
pub use op::{BinaryOp, Builder, NodeId, UnaryOp};
pub use unary::{UNARY, UnarySpec};
pub use words::{CONSTANTS, Function, function, function_names};

/// `v^n` for an integer `n` (the graph's integer powers, which are not a function of the
/// language but what `^` with an integer exponent becomes): undefined at 0 for n < 0.
///
/// By repeated squaring, the products of the runtime's `__powidf2` (what `f64::powi` calls)
/// in its order, so the same value; written out so that it inlines into the evaluators'
/// loops instead of a call per power.
#[inline]
pub fn powi(v: f64, n: i32) -> f64 {
    if v == 0.0 && n < 0 {
        return f64::NAN;
    }
    let (mut base, mut rest, mut product) = (v, n.unsigned_abs(), 1.0);
    loop {
        if rest & 1 != 0 {
            product *= base;
        }
        rest >>= 1;
        if rest == 0 {
            break;
        }
        base *= base;
    }
    if n < 0 { 1.0 / product } else { product }
}

#[cfg(test)]
mod tests {
    use super::powi;

    #[test]
    fn powi_is_the_runtime_s_to_the_bit() {
        let bases = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            -0.7,
            1.3,
            3.0e-8,
            -2.5e7,
            1e300,
            f64::NAN,
        ];
        for v in bases {
            for n in -12..=12 {
                if v == 0.0 && n < 0 {
                    assert!(powi(v, n).is_nan());
                    continue;
                }
                let (ours, theirs) = (powi(v, n), v.powi(n));
                assert!(
                    ours.to_bits() == theirs.to_bits() || (ours.is_nan() && theirs.is_nan()),
                    "{v}^{n}: {ours} against {theirs}"
                );
            }
        }
    }
}
