//! A formula's numbers as data: the shader reads each constant of its tapes from a table in
//! binding 7 (`ff_constants`) instead of a WGSL literal, so that two formulas that differ
//! only in their numbers (`x^2 + y^2 - 0.7` and `… - 0.75`) have the same WGSL and one
//! compiled pipeline draws both. Typing a number then compiles nothing, where a compile
//! takes most of a second on a software GPU and about half a second on a GPU's driver.
//!
//! Each entry is four words: the constant in f32 at a point, then its interval's bounds, as
//! the literals they replace computed them in WGSL (`templates/interval.wgsl`'s `iv_around`
//! and bounds), and a word unused.

use std::collections::HashMap;

use crate::eval::{Instr, Tape};

/// The interval library's largest finite bound, and its stand-in for ∞ (IV_LARGE, IV_BIG).
const IV_LARGE: f32 = 2305843009213693952.0;
const IV_BIG: f32 = 4611686018427387904.0;
/// Below it a bound may be a subnormal a device flushes (IV_TINY, 2^-125).
const IV_TINY: f32 = 2.350_988_7e-38;

/// The WGSL that reads the table: binding 7 and a constant's value at a point and as an
/// interval.
pub(super) const DECLARATIONS: &str = "\
// The formula's constants (fourfold's shader/constants.rs): value, interval lo, hi, unused.
@group(0) @binding(7) var<storage, read> ff_constants: array<vec4<u32>>;

fn ff_const(k: u32) -> f32 {
    return bitcast<f32>(ff_constants[k].x);
}

fn ff_const_box(k: u32) -> vec2<f32> {
    return bitcast<vec2<f32>>(ff_constants[k].yz);
}
";

/// The distinct constants of a formula's tapes, in order of first use, and where each is.
#[derive(Debug, Clone, Default)]
pub(super) struct Constants {
    values: Vec<f64>,
    index: HashMap<u64, u32>,
}

impl Constants {
    /// The constants of `tapes`, first to last.
    pub(super) fn of(tapes: &[&Tape]) -> Self {
        let mut constants = Self::default();
        for instr in tapes.iter().flat_map(|t| t.instrs()) {
            if let Instr::Const(v) = *instr {
                let next = constants.values.len() as u32;
                constants.index.entry(v.to_bits()).or_insert_with(|| {
                    constants.values.push(v);
                    next
                });
            }
        }
        constants
    }

    /// Constant `v`'s entry in the table (it is one of the tapes').
    pub(super) fn index(&self, v: f64) -> u32 {
        self.index[&v.to_bits()]
    }

    pub(super) fn values(&self) -> &[f64] {
        &self.values
    }

    /// Binding 7's words.
    pub(super) fn table(&self) -> Vec<[u32; 4]> {
        self.values
            .iter()
            .map(|&v| {
                let (lo, hi) = interval(v);
                [point(v).to_bits(), lo.to_bits(), hi.to_bits(), 0]
            })
            .collect()
    }
}

/// `v` at a point in f32: its nearest f32, ±∞ beyond f32's range, NaN if undefined (as the
/// literal, or the settings' run-time ∞ and NaN, that it replaces).
fn point(v: f64) -> f32 {
    v as f32
}

/// An interval holding the real number `v`: the point where f32 holds it exactly, else its
/// nearest f32 stepped an ulp either way, or a half-line beyond the library's largest bound;
/// empty (lo > hi) if undefined.
fn interval(v: f64) -> (f32, f32) {
    if v.is_nan() {
        (IV_BIG, -IV_BIG)
    } else if v > f64::from(IV_LARGE) {
        (IV_LARGE, IV_BIG)
    } else if v < -f64::from(IV_LARGE) {
        (-IV_BIG, -IV_LARGE)
    } else if f64::from(v as f32) == v && (v == 0.0 || v.abs() >= f64::from(IV_TINY)) {
        // Exact in f32, and no subnormal a device may flush: a point.
        (v as f32, v as f32)
    } else {
        let x = v as f32;
        (down(x), -down(-x))
    }
}

/// `x` an ulp toward −∞, as the library's `iv_down`: within ±2^-125, −2^-125.
fn down(x: f32) -> f32 {
    if x.abs() < IV_TINY {
        return -IV_TINY;
    }
    let b = x.to_bits();
    f32::from_bits(if x > 0.0 { b - 1 } else { b + 1 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_constant_s_interval_holds_it() {
        for v in [
            0.7,
            -0.7,
            0.1,
            1.0 / 3.0,
            1e-40,
            -1e-40,
            3e-39,
            -2.5e18,
            std::f64::consts::PI,
        ] {
            let (lo, hi) = interval(v);
            assert!(f64::from(lo) < v && v < f64::from(hi), "{v}: [{lo}, {hi}]");
        }
        // Exact ones are points; huge ones half-lines (IV_BIG stands for ∞); undefined ones
        // empty.
        assert_eq!(interval(0.75), (0.75, 0.75));
        assert_eq!(interval(0.0), (0.0, 0.0));
        assert_eq!(interval(3e18), (IV_LARGE, IV_BIG));
        assert_eq!(interval(1e30), (IV_LARGE, IV_BIG));
        assert_eq!(interval(-3e18), (-IV_BIG, -IV_LARGE));
        let (lo, hi) = interval(f64::NAN);
        assert!(lo > hi);
        assert!(point(f64::NAN).is_nan() && point(1e300) == f32::INFINITY);
    }

    #[test]
    fn the_table_holds_each_value_once_in_order_of_first_use() {
        let f = crate::formula::CompiledFormula::compile("0.7*x^2 + y^2 + 0.7*z - 0.25").unwrap();
        let c = Constants::of(&[&f.tape_f, &f.tape_grad, &f.tape_all]);
        let mut seen = c.values().to_vec();
        seen.dedup();
        assert_eq!(seen.len(), c.values().len());
        assert!(c.values().contains(&0.7) && c.values().iter().any(|v| v.abs() == 0.25));
        let table = c.table();
        let k = c.index(0.7) as usize;
        assert_eq!(f32::from_bits(table[k][0]), 0.7f32);
        assert!(f32::from_bits(table[k][1]) < 0.7f32 && f32::from_bits(table[k][2]) > 0.7f32);
    }
}
