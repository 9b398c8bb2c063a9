//! The lines of a tile of a slice's pixels, all along n1 within the slice's hyperplane:
//! a box of the hierarchy in which F has no root on any of them is proved so once for the
//! tile, and left out of its walk, for the rays' march and the certified search alike
//! (each pixel had proved it again, box by box: most of an empty pixel's time). In a box
//! that is kept, the stretches of the lines on which F keeps one sign are proved so the
//! same way, and each pixel's march steps over them (where the box's bounds on F' and F''
//! are loose, most of its samples).

use crate::eval::{Box4, Interval, IntervalEvaluator};
use crate::formula::CompiledFormula;
use crate::render::view::Uniforms;

use std::ops::Range;

use super::march::Stretch;
use super::shading::{V4, origins, slice_reach};

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

    /// The lines of a slice's pixels `columns` × `rows`, from their corner pixels' lines.
    pub(super) fn of_pixels(u: &Uniforms, (columns, rows): (Range<u32>, Range<u32>)) -> Self {
        let (first, last) = ((columns.start, rows.start), (columns.end - 1, rows.end - 1));
        let corners = [first, (last.0, first.1), (first.0, last.1), last]
            .map(|(px, py)| origins(u, (px as f32 + 0.5, py as f32 + 0.5)).1);
        Self::of(u, corners, slice_reach(u))
    }

    /// A box around the lines' points within [lo, hi] (widened by the slack); None where
    /// no line meets it.
    fn within(&self, lo: V4, hi: V4) -> Option<Box4> {
        let widened = self.widened(lo, hi);
        let (first, last) = span_within(self.base, self.n1, widened)?;
        self.segment((first, last), widened)
    }

    /// The box [lo, hi] widened by the slack and past its own rounding, per axis.
    fn widened(&self, lo: V4, hi: V4) -> [(f64, f64); 4] {
        std::array::from_fn(|k| {
            let (l, h) = (f64::from(lo[k]), f64::from(hi[k]));
            let m = 1e-5 * (l.abs() + h.abs()) + self.slack;
            (l - m, h + m)
        })
    }

    /// A box around the lines' points from `first` to `last` along n1 that lie within
    /// `sides`; None where there are none.
    fn segment(&self, (first, last): (f64, f64), sides: [(f64, f64); 4]) -> Option<Box4> {
        // (The quotients' rounding: a millionth of the range's ends.)
        let e = 1e-6 * (first.abs() + last.abs()) + 1e-30;
        let (first, last) = (first - e, last + e);
        let mut x = [Interval::EMPTY; 4];
        for k in 0..4 {
            let ((bl, bh), (l, h), n) = (self.base[k], sides[k], self.n1[k]);
            // In f64 rounded to nearest, widened past its three roundings.
            let (a, b) = (first * n, last * n);
            let (lo, hi) = (bl + a.min(b), bh + a.max(b));
            let slack = 1e-15 * (bl.abs().max(bh.abs()) + a.abs().max(b.abs())) + 1e-300;
            let line = if lo.is_finite() && hi.is_finite() {
                Interval::new(lo - slack, hi + slack)
            } else {
                Interval::ENTIRE
            };
            x[k] = line.intersect(l, h);
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

    /// The stretches of the lines of `bundle` within [lo, hi], as distances along n1 from
    /// their starts (ascending, apart), on which F is defined and keeps one sign: halves of
    /// the lines' span in the box, then halves of those that are not proved, to `depth`
    /// halvings. A pixel's march steps over them (its samples there cannot change sign).
    pub(super) fn one_signed(
        &mut self,
        bundle: &Bundle,
        (lo, hi): (V4, V4),
        depth: u32,
        out: &mut Vec<Stretch>,
    ) {
        out.clear();
        let sides = bundle.widened(lo, hi);
        let Some((first, last)) = span_within(bundle.base, bundle.n1, sides) else {
            return;
        };
        // (The whole span is not proved: the tile's walk would have left the box out.)
        let middle = 0.5 * (first + last);
        for half in [(first, middle), (middle, last)] {
            self.split(bundle, sides, half, depth.saturating_sub(1), out);
        }
    }

    fn split(
        &mut self,
        bundle: &Bundle,
        sides: [(f64, f64); 4],
        (first, last): (f64, f64),
        depth: u32,
        out: &mut Vec<Stretch>,
    ) {
        let Some(x) = bundle.segment((first, last), sides) else {
            return;
        };
        let f = self.eval.eval(&self.formula.tape_f, &x, self.params);
        if !f.contains_zero() && self.eval.continuous_on_last_box(&self.formula.tape_f) {
            let (from, to) = (first as f32, last as f32);
            // (F is continuous on the box: its enclosure is finite, and clear of 0.)
            let sign = if f.lo() > 0.0 { 1.0 } else { -1.0 };
            match out.last_mut() {
                // (Only pieces that meet are joined: both enclose F where they meet.)
                Some(prev) if prev.to >= from => {
                    debug_assert_eq!(prev.sign, sign, "pieces that meet, of one sign");
                    prev.to = to;
                }
                _ => out.push(Stretch { from, to, sign }),
            }
        } else if depth > 0 {
            let middle = 0.5 * (first + last);
            self.split(bundle, sides, (first, middle), depth - 1, out);
            self.split(bundle, sides, (middle, last), depth - 1, out);
        }
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

    /// A slice seen turned by `a` and `b` (see [`turned`]), at `offset` along n2, its lines
    /// starting 2 before the slice's place along n1.
    struct TurnedSlice {
        axes: [V4; 4],
        offset: f32,
    }

    impl TurnedSlice {
        fn new(a: f32, b: f32, offset: f32) -> Self {
            Self {
                axes: turned(a, b),
                offset,
            }
        }

        /// A pixel's plane origin at `p` along (v1, v2) (as the twin's `origins`).
        fn origin(&self, p: [f32; 2]) -> V4 {
            let [v1, v2, _, _] = self.axes;
            std::array::from_fn(|k| p[0] * v1[k] + p[1] * v2[k])
        }

        /// The start of the line of the pixel whose plane origin is `o`.
        fn start(&self, o: V4) -> V4 {
            let [_, _, n1, n2] = self.axes;
            std::array::from_fn(|k| (o[k] + self.offset * n2[k]) - 2.0 * n1[k])
        }

        /// The bundle of the lines of the square of pixels from `corner`, `side` wide.
        fn bundle(&self, corner: [f32; 2], side: f32) -> Bundle {
            let mut u = Uniforms::zeroed();
            (u.n1, u.n2) = (self.axes[2], self.axes[3]);
            u.root.section_offset = self.offset;
            let corners = [[0.0, 0.0], [side, 0.0], [0.0, side], [side, side]]
                .map(|d| self.start(self.origin([corner[0] + d[0], corner[1] + d[1]])));
            Bundle::of(&u, corners, 2.0)
        }
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
            let slice = TurnedSlice::new(a, b, offset);
            let [_, _, n1, n2] = slice.axes;
            let bundle = slice.bundle(corner, side);
            // A point of a pixel's line as the certified search has it, from its plane's
            // origin (the march's, from its start, differ by rounding only).
            let o = slice.origin([corner[0] + at[0] * side, corner[1] + at[1] * side]);
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

    proptest! {
        /// F keeps one sign along every line of a tile over each of the stretches found in
        /// a box, whichever way the view is turned.
        #[test]
        fn f_keeps_one_sign_on_every_line_over_each_one_signed_stretch(
            a in -3.0f32..3.0, b in -3.0f32..3.0, offset in -0.8f32..0.8,
            corner in prop::array::uniform2(-0.9f32..0.9), side in 0.001f32..0.05,
            half in 0.2f32..1.0, shift in prop::array::uniform4(-0.5f32..0.5),
        ) {
            let formula = CompiledFormula::compile("x^2 + y^2 + z^2 + w^2 - 1").unwrap();
            let f = |p: [f64; 4]| p.iter().map(|v| v * v).sum::<f64>() - 1.0;
            let mut free = RootFree::new(&formula, &[]);
            let slice = TurnedSlice::new(a, b, offset);
            let n1 = slice.axes[2];
            let bundle = slice.bundle(corner, side);
            // A box around the middle of the lines' part in the ball of radius 1.5.
            let mid = slice.start(slice.origin([corner[0] + 0.5 * side, corner[1] + 0.5 * side]));
            let c: V4 = std::array::from_fn(|k| mid[k] + 2.0 * n1[k] + shift[k]);
            let (lo, hi) = (c.map(|v| v - half), c.map(|v| v + half));
            let mut stretches = Vec::new();
            free.one_signed(&bundle, (lo, hi), 6, &mut stretches);
            prop_assert!(stretches.windows(2).all(|w| w[0].to < w[1].from));
            for &Stretch { from, to, sign } in &stretches {
                prop_assert!(from < to);
                for (i, j) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.3, 0.7)] {
                    let o = slice.start(slice.origin([corner[0] + i * side, corner[1] + j * side]));
                    let signs: Vec<bool> = (0..=64)
                        .map(|k| from + (to - from) * k as f32 / 64.0)
                        .map(|t| std::array::from_fn(|m| f64::from(o[m]) + f64::from(t * n1[m])))
                        .filter(|p: &[f64; 4]| (0..4).all(|m| p[m] >= f64::from(lo[m]) && p[m] <= f64::from(hi[m])))
                        .map(|p| f(p) > 0.0)
                        .collect();
                    prop_assert!(signs.windows(2).all(|w| w[0] == w[1]), "{from}..{to}");
                    prop_assert!(signs.iter().all(|&s| s == (sign > 0.0)), "{from}..{to}: {sign}");
                }
            }
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
        // Through z in [-1.5, 1.5] (t from 0.5 to 3.5), the lines cross the sphere at t of
        // about 1.06 and 2.94: the stretches cover all but the surroundings of those.
        let mut stretches = Vec::new();
        let sides = ([-0.5, -0.5, -1.5, -0.5], [0.5, 0.5, 1.5, 0.5]);
        free.one_signed(&bundle, sides, 8, &mut stretches);
        let covered = |t: f32| stretches.iter().any(|s| s.from <= t && t <= s.to);
        assert!(!covered(1.06) && !covered(2.94), "{stretches:?}");
        for t in [0.51, 0.8, 1.0, 1.12, 2.0, 2.88, 3.0, 3.49] {
            assert!(covered(t), "{t}: {stretches:?}");
        }
    }
}
