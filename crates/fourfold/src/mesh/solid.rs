//! The solid the mesh bounds, as a function of the slice's frame: S(u) = max(F, outside) at
//! the point of R⁴ that u names, ≤ 0 inside. Its boundary is the cut of M by the hyperplane,
//! capped by the domain's faces where M leaves the domain. Where F is undefined S is too,
//! and such points count as outside.

use crate::eval::PointEvaluator;
use crate::formula::CompiledFormula;

use super::frame::SliceFrame;

/// S at a point, with its gradient in the frame and which function gave it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub value: f64,
    pub gradient: [f64; 3],
    /// The domain's face, not F, is the larger there: a point of a cap.
    pub on_cap: bool,
}

impl Sample {
    /// |S| / |∇S|: to first order, how far the point is from the boundary (∞ where the
    /// gradient vanishes or is unknown).
    pub fn distance(&self) -> f64 {
        let g = self.gradient.iter().map(|x| x * x).sum::<f64>().sqrt();
        let d = self.value.abs() / g;
        if d.is_nan() { f64::INFINITY } else { d }
    }
}

pub struct Solid<'a> {
    pub formula: &'a CompiledFormula,
    pub params: &'a [f64],
    pub frame: &'a SliceFrame,
}

impl Solid<'_> {
    /// Whether `u` is inside (S < 0; undefined is outside).
    pub fn inside(&self, eval: &mut PointEvaluator, u: [f64; 3]) -> bool {
        let p = self.frame.point(u);
        let f = eval.eval(&self.formula.tape_f, p, self.params);
        f < 0.0 && self.frame.outside(p).0 < 0.0
    }

    /// S, its gradient and its active part at `u`.
    pub fn sample(&self, eval: &mut PointEvaluator, u: [f64; 3]) -> Sample {
        let p = self.frame.point(u);
        let mut all = [0.0; 5];
        eval.eval_into(&self.formula.tape_all, p, self.params, &mut all);
        let (outside, towards) = self.frame.outside(p);
        if all[0].is_nan() || outside > all[0] {
            return Sample {
                value: if all[0].is_nan() { f64::NAN } else { outside },
                gradient: self.frame.project(towards),
                on_cap: true,
            };
        }
        Sample {
            value: all[0],
            gradient: self.frame.project([all[1], all[2], all[3], all[4]]),
            on_cap: false,
        }
    }

    /// Where S changes sign on the segment from `a` (inside) to `b` (outside): bisection to
    /// the last bit that matters.
    pub fn crossing(&self, eval: &mut PointEvaluator, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        let (mut lo, mut hi) = (0.0, 1.0);
        let at = |t: f64| std::array::from_fn(|k| a[k] + t * (b[k] - a[k]));
        for _ in 0..48 {
            let mid = 0.5 * (lo + hi);
            if self.inside(eval, at(mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        at(0.5 * (lo + hi))
    }
}
