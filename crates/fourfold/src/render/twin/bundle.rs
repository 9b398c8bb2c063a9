//! The lines of a tile of a slice's pixels, all along n1 within the slice's hyperplane:
//! a box of the hierarchy in which F has no root on any of them is proved so once for the
//! tile, and left out of its walk, for the rays' march and the certified search alike
//! (each pixel had proved it again, box by box: most of an empty pixel's time).

use crate::eval::{Box4, Interval, IntervalEvaluator};
use crate::formula::CompiledFormula;
use crate::render::view::Uniforms;

use super::shading::V4;

/// The tile's lines: each pixel's slice line from its start (the rays' origin) along n1;
/// `base` holds every start, and `slack` the widening of a box that covers the rounding of
/// the points a pixel works out along its line, the march's and the certified search's.
#[derive(Debug, Clone, Copy)]
pub(super) struct Bundle {
    base: [(f64, f64); 4],
    n1: [f64; 4],
    slack: f64,
}

impl Bundle {
    /// The lines of a slice's tile from the starts of its four corner pixels' lines: each
    /// coordinate of a start is worked out from the pixel's column and row by steps that
    /// each keep or reverse order, so the corners' hold all the others'.
    pub(super) fn of(u: &Uniforms, corners: [V4; 4], reach: f32) -> Self {
        let base: [(f64, f64); 4] = std::array::from_fn(|k| {
            corners
                .iter()
                .map(|o| f64::from(o[k]))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                    (l.min(v), h.max(v))
                })
        });
        let far = base
            .iter()
            .map(|&(l, h)| l.abs().max(h.abs()))
            .fold(0.0, f64::max);
        let offset = f64::from(u.root.section_offset).abs();
        Self {
            base,
            n1: u.n1.map(f64::from),
            // A pixel's points, its line's start plus t·n1 or its plane's origin plus
            // s·n1 + offset·n2, are worked out in f32 from starts, origins and distances of
            // at most `far`, twice `reach` and `offset`: far beyond their rounding.
            slack: 1e-5 * (far + 2.0 * f64::from(reach) + offset) + 1e-30,
        }
    }

    /// A box around the lines' points within [lo, hi] (widened by the slack); None where
    /// no line meets it.
    fn within(&self, lo: V4, hi: V4) -> Option<Box4> {
        let widened: [(f64, f64); 4] = std::array::from_fn(|k| {
            let (l, h) = (f64::from(lo[k]), f64::from(hi[k]));
            let m = 1e-5 * (l.abs() + h.abs()) + self.slack;
            (l - m, h + m)
        });
        let (first, last) = span_within(self.base, self.n1, widened)?;
        // (The quotients' rounding: a millionth of the range's ends.)
        let e = 1e-6 * (first.abs() + last.abs()) + 1e-30;
        let along = Interval::new(first - e, last + e);
        let mut x = [Interval::EMPTY; 4];
        for k in 0..4 {
            let ((bl, bh), (l, h)) = (self.base[k], widened[k]);
            x[k] = Interval::new(bl, bh)
                .add(along.mul(Interval::point(self.n1[k])))
                .intersect(l, h);
            if x[k].is_empty() {
                return None;
            }
        }
        Some(x)
    }
}

/// The distances along `n` at which a line from a point of `base` (a range per coordinate)
/// may lie within `sides` on every axis, as (first, last); None where none does.
pub(super) fn span_within(
    base: [(f64, f64); 4],
    n: [f64; 4],
    sides: [(f64, f64); 4],
) -> Option<(f64, f64)> {
    let (mut first, mut last) = (f64::NEG_INFINITY, f64::INFINITY);
    for k in 0..4 {
        let ((bl, bh), (l, h)) = (base[k], sides[k]);
        if n[k] == 0.0 {
            if bh < l || bl > h {
                return None;
            }
            continue;
        }
        let (a, c) = ((l - bh) / n[k], (h - bl) / n[k]);
        first = first.max(a.min(c));
        last = last.min(a.max(c));
    }
    (first <= last).then_some((first, last))
}

/// Proves boxes free of M along a tile's lines: F's enclosure over the lines' part in the
/// box holds no 0 (or F is undefined on all of it).
pub(super) struct RootFree<'a> {
    formula: &'a CompiledFormula,
    params: &'a [f64],
    eval: IntervalEvaluator,
}

impl<'a> RootFree<'a> {
    pub(super) fn new(formula: &'a CompiledFormula, params: &'a [f64]) -> Self {
        Self {
            formula,
            params,
            eval: IntervalEvaluator::new(),
        }
    }

    /// Whether no line of `bundle` meets M (nor a point where F is 0) in [lo, hi].
    pub(super) fn proves(&mut self, bundle: &Bundle, lo: V4, hi: V4) -> bool {
        bundle.within(lo, hi).is_none_or(|x| {
            !self
                .eval
                .eval(&self.formula.tape_f, &x, self.params)
                .contains_zero()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bytemuck::Zeroable;
    use proptest::prelude::*;

    /// Two orthonormal pairs (v1, v2) and (n1, n2) from a rotation by `a` in the x–z plane
    /// and `b` in the y–w plane, as a view's turned axes are.
    fn turned(a: f32, b: f32) -> [V4; 4] {
        let (ca, sa, cb, sb) = (a.cos(), a.sin(), b.cos(), b.sin());
        [
            [ca, 0.0, sa, 0.0],
            [0.0, cb, 0.0, sb],
            [-sa, 0.0, ca, 0.0],
            [0.0, -sb, 0.0, cb],
        ]
    }

    proptest! {
        /// Every point of a tile's lines that lies in a box lies in the bundle's box there,
        /// whichever way the view is turned.
        #[test]
        fn the_bundle_holds_every_line_s_points_in_a_box(
            a in -3.0f32..3.0, b in -3.0f32..3.0, offset in -1.0f32..1.0,
            corner in prop::array::uniform2(-1.0f32..1.0), side in 0.001f32..0.05,
            at in prop::array::uniform2(0.0f32..1.0), s in -3.0f32..3.0,
            half in 0.01f32..0.5, shift in prop::array::uniform4(-1.0f32..1.0),
        ) {
            let [v1, v2, n1, n2] = turned(a, b);
            let mut u = Uniforms::zeroed();
            (u.n1, u.n2) = (n1, n2);
            u.root.section_offset = offset;
            // A pixel's plane origin, and its line's start (as the twin's `origins`).
            let origin = |p: [f32; 2]| -> V4 { std::array::from_fn(|k| p[0] * v1[k] + p[1] * v2[k]) };
            let start = |o: V4| -> V4 { std::array::from_fn(|k| (o[k] + offset * n2[k]) - 2.0 * n1[k]) };
            let corners = [[0.0, 0.0], [side, 0.0], [0.0, side], [side, side]]
                .map(|d| start(origin([corner[0] + d[0], corner[1] + d[1]])));
            let bundle = Bundle::of(&u, corners, 2.0);
            // A point of a pixel's line as the certified search has it, from its plane's
            // origin (the march's, from its start, differ by rounding only).
            let o = origin([corner[0] + at[0] * side, corner[1] + at[1] * side]);
            let p: V4 = std::array::from_fn(|k| o[k] + offset * n2[k] + s * n1[k]);
            // A box around p, p anywhere in it.
            let lo: V4 = std::array::from_fn(|k| p[k] - half * (1.0 + shift[k]));
            let hi: V4 = std::array::from_fn(|k| lo[k] + 2.0 * half);
            let x = bundle.within(lo, hi);
            prop_assert!(x.is_some());
            let x = x.unwrap();
            prop_assert!((0..4).all(|k| x[k].contains(f64::from(p[k]))), "{x:?} {p:?}");
        }
    }

    /// A box the tile's lines pass by, clear of the sphere, is proved free of it; one they
    /// cross the sphere in is not, nor one F is 0 in.
    #[test]
    fn a_box_the_lines_pass_clear_of_m_is_proved_free() {
        let formula = CompiledFormula::compile("x^2 + y^2 + z^2 + w^2 - 1").unwrap();
        let mut free = RootFree::new(&formula, &[]);
        let mut u = Uniforms::zeroed();
        let [_, _, n1, n2] = turned(0.0, 0.0);
        (u.n1, u.n2) = (n1, n2);
        u.root.section_offset = 0.3;
        // Lines along z from z = −2 at x, y in [0.1, 0.12], w = 0.3: they cross the sphere
        // at z ≈ ±0.94.
        let corners =
            [[0.1, 0.1], [0.12, 0.1], [0.1, 0.12], [0.12, 0.12]].map(|[x, y]| [x, y, -2.0, 0.3]);
        let bundle = Bundle::of(&u, corners, 2.0);
        assert!(free.proves(&bundle, [-0.5; 4], [0.5; 4]));
        assert!(!free.proves(&bundle, [-0.5, -0.5, 0.5, -0.5], [0.5, 0.5, 1.5, 0.5]));
        // A box the lines do not reach (x beyond 0.12), though it holds part of M.
        assert!(free.proves(&bundle, [0.5, -1.0, -1.0, -1.0], [1.0, 1.0, 1.0, 1.0]));
    }
}
