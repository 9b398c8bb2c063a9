//! Bounds on F over a tree's box as the ray caster uses them: its slope (|∂F/∂x_k|) where F is
//! continuous, its curvature (the second derivatives) where ∇F is too, each padded past the
//! f32 rounding of the shader's boxes and samples; and how a curvature bound reads along a
//! ray or in a plane.

use crate::eval::IntervalEvaluator;
use crate::formula::{CompiledFormula, HESSIAN_PAIRS};
use crate::gpu_layout::Curvature;
use crate::interval::Interval;

impl Curvature {
    /// No bound.
    pub const NONE: Self = Self {
        diag_lo: [f32::NEG_INFINITY; 4],
        diag_hi: [f32::INFINITY; 4],
        off_lo: [f32::NEG_INFINITY; 4],
        off_hi: [f32::INFINITY; 4],
        rest: [
            f32::NEG_INFINITY,
            f32::NEG_INFINITY,
            f32::INFINITY,
            f32::INFINITY,
        ],
    };

    /// Whether every bound is finite (else none is: see [`Curvature::NONE`]).
    pub fn is_bounded(&self) -> bool {
        let (lo, hi) = self.pairs();
        lo.iter().chain(&hi).all(|v| v.is_finite())
    }

    /// From bounds in the order of [`HESSIAN_PAIRS`].
    fn from_pairs(lo: [f32; 10], hi: [f32; 10]) -> Self {
        Self {
            diag_lo: [lo[0], lo[1], lo[2], lo[3]],
            diag_hi: [hi[0], hi[1], hi[2], hi[3]],
            off_lo: [lo[4], lo[5], lo[6], lo[7]],
            off_hi: [hi[4], hi[5], hi[6], hi[7]],
            rest: [lo[8], lo[9], hi[8], hi[9]],
        }
    }

    /// Bounds in the order of [`HESSIAN_PAIRS`].
    pub fn pairs(&self) -> ([f32; 10], [f32; 10]) {
        let [xx, yy, zz, ww] = self.diag_lo;
        let [xy, xz, xw, yz] = self.off_lo;
        let lo = [xx, yy, zz, ww, xy, xz, xw, yz, self.rest[0], self.rest[1]];
        let [xx, yy, zz, ww] = self.diag_hi;
        let [xy, xz, xw, yz] = self.off_hi;
        let hi = [xx, yy, zz, ww, xy, xz, xw, yz, self.rest[2], self.rest[3]];
        (lo, hi)
    }

    /// Bounds [lo, hi] on d²F/dt² = dᵀ H d along a ray o + t d in the box, rounded
    /// outwards past f32's rounding; (−∞, +∞) where unbounded. The CPU reference's rule;
    /// the shader bounds its rays by the observer plane's forms instead
    /// ([`Curvature::in_plane`]).
    pub fn along(&self, d: [f64; 4]) -> (f32, f32) {
        self.form(|i, j| d[i] * d[j])
            .unwrap_or((f32::NEG_INFINITY, f32::INFINITY))
    }

    /// Bounds on the second derivative along any ray in the plane of `n1` and `n2`: for
    /// d = a·n1 + b·n2, dᵀ H d = a²·A + ab·B + b²·C with A = n1ᵀ H n1, B = n1ᵀ H n2 + n2ᵀ H n1
    /// and C = n2ᵀ H n2, and this is [A lo, A hi, B lo, B hi, C lo, C hi], rounded outwards
    /// past f32's rounding; all infinite where unbounded. A view's rays all lie in that
    /// plane, so the shader works A, B and C out once per box and view (a box record, see
    /// `render::tiles`), not a ray's 10 products per ray. No looser than [`Curvature::along`]
    /// where H is exact or n1, n2 are coordinate axes (the glome, the chapter's views);
    /// elsewhere the sum over the three forms can be wider.
    pub fn in_plane(&self, n1: [f64; 4], n2: [f64; 4]) -> [f32; 6] {
        let forms = [
            self.form(|i, j| n1[i] * n1[j]),
            self.form(|i, j| n1[i] * n2[j] + n2[i] * n1[j]),
            self.form(|i, j| n2[i] * n2[j]),
        ];
        match forms {
            [Some(a), Some(b), Some(c)] => [a.0, a.1, b.0, b.1, c.0, c.1],
            _ => {
                let (lo, hi) = (f32::NEG_INFINITY, f32::INFINITY);
                [lo, hi, lo, hi, lo, hi]
            }
        }
    }

    /// Bounds on Σ_ij H_ij·p(i, j) over the box (H symmetric: twice p off the diagonal),
    /// rounded outwards past f32's rounding; None where not finite.
    fn form(&self, p: impl Fn(usize, usize) -> f64) -> Option<(f32, f32)> {
        let (lo, hi) = self.pairs();
        let (mut a, mut b, mut mag) = (0.0f64, 0.0f64, 0.0f64);
        for (k, &(i, j)) in HESSIAN_PAIRS.iter().enumerate() {
            let (i, j) = (usize::from(i), usize::from(j));
            let p = p(i, j) * if i == j { 1.0 } else { 2.0 };
            if p == 0.0 {
                continue;
            }
            let (l, h) = (f64::from(lo[k]), f64::from(hi[k]));
            let (x, y) = if p > 0.0 {
                (l * p, h * p)
            } else {
                (h * p, l * p)
            };
            a += x;
            b += y;
            mag += x.abs().max(y.abs());
        }
        if !(a.is_finite() && b.is_finite()) {
            return None;
        }
        let margin = mag * 1e-6;
        Some(((a - margin) as f32, (b + margin) as f32))
    }
}

/// Largest |F| on a box that gets a slope bound (f32 overflows at 3.4e38).
const F32_SAFE: f64 = 1e30;

/// The box `center ± half`, padded past the f32 rounding of the shader's box and samples.
fn padded_box(center: [f32; 4], half: [f32; 4]) -> [Interval; 4] {
    std::array::from_fn(|k| {
        let (c, h) = (f64::from(center[k]), f64::from(half[k]));
        let e = (c.abs() + h) * 1e-6;
        Interval::new(c - h - e, c + h + e)
    })
}

/// A bound on |∂F/∂x_k| over the box `center ± half` (padded past the f32 rounding of the
/// shader's box and samples) if F is continuous on it and far from f32's overflow, else +∞
/// (see `Hierarchy::slopes`).
pub(super) fn box_slope(
    eval: &mut IntervalEvaluator,
    formula: &CompiledFormula,
    params: &[f64],
    center: [f32; 4],
    half: [f32; 4],
) -> [f32; 4] {
    let unbounded = [f32::INFINITY; 4];
    let bx = padded_box(center, half);
    eval.eval(&formula.tape_f, &bx, params);
    if !eval.continuous_on_last_box(&formula.tape_f) {
        return unbounded;
    }
    let mut out = [Interval::EMPTY; 5];
    eval.eval_into(&formula.tape_all, &bx, params, &mut out);
    // The shader evaluates F in f32: where it may overflow, an infinite |F| would step
    // over the whole span.
    if !(out[0].lo().abs() < F32_SAFE && out[0].hi().abs() < F32_SAFE) {
        return unbounded;
    }
    std::array::from_fn(|k| {
        let g = out[k + 1];
        let m = g.magnitude();
        if g.is_empty() || !m.is_finite() {
            f32::INFINITY
        } else {
            // Rounded up past f32's rounding.
            (m * (1.0 + 1e-6)) as f32
        }
    })
}

/// Bounds on F's second derivatives over the box `center ± half` (padded as `box_slope`'s)
/// if F, ∇F and they are continuous on it and far from f32's overflow, else
/// [`Curvature::NONE`].
pub(super) fn box_curvature(
    eval: &mut IntervalEvaluator,
    formula: &CompiledFormula,
    params: &[f64],
    center: [f32; 4],
    half: [f32; 4],
) -> Curvature {
    let bx = padded_box(center, half);
    let mut out = [Interval::EMPTY; 15];
    eval.eval_into(&formula.tape_second, &bx, params, &mut out);
    // Taylor's bound needs ∇F continuous too: every part of F, ∇F and the second
    // derivatives (abs and min / max put sign and step in ∇F).
    if !eval.continuous_on_last_box(&formula.tape_second) {
        return Curvature::NONE;
    }
    // F (as in box_slope) and the bounds (an f32 would round them to infinity) far from
    // f32's overflow.
    let second = &out[5..];
    if std::iter::once(&out[0])
        .chain(second)
        .any(|h| h.is_empty() || !(h.lo().abs() < F32_SAFE && h.hi().abs() < F32_SAFE))
    {
        return Curvature::NONE;
    }
    // Rounded outwards past f32's rounding.
    let widen = |v: f64| v.abs() * 1e-6 + 1e-30;
    let lo = std::array::from_fn(|k| (second[k].lo() - widen(second[k].lo())) as f32);
    let hi = std::array::from_fn(|k| (second[k].hi() + widen(second[k].hi())) as f32);
    Curvature::from_pairs(lo, hi)
}
