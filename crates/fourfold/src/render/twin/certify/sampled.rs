//! F's sign at a bracket's end from the march's own sample there, with no evaluation: where
//! the sample's f32 value is farther from 0 than F at the end can lie from it. That is at
//! most the single-precision evaluators' error over the domain (`eval::rounding`) plus F's
//! slope times the distance from the sample's f32 point to the end (the end is the plane's
//! exact point, the sample the march's rounded one). Most ends of a polynomial's brackets
//! are a march step from M, far beyond both; the rest are left to balls.

use crate::eval::{Interval, IntervalEvaluator, single_precision_error};
use crate::formula::CompiledFormula;
use crate::render::view::Uniforms;

use super::super::shading::V4;
use super::plane::domain_of;

/// What proves signs from samples, for one frame's formula, parameters, domain and plane.
#[derive(Debug, Clone)]
pub(super) struct SampledSigns {
    /// The bound on the f32 value's error anywhere in the domain.
    error: f64,
    /// Bounds on |∂F/∂x_k| over the domain.
    slopes: [f64; 4],
    /// The domain less [`NEAR`] on every side: a sample's point there, and an end within
    /// NEAR of it, lie in the domain.
    lo: [f64; 4],
    hi: [f64; 4],
    n1: [f64; 4],
    n2: [f64; 4],
}

/// How far from its sample an end may be for the sample to prove its sign: far beyond f32's
/// rounding of the points (the twin's distances are a few units), far within any domain.
const NEAR: f64 = 1e-4;

impl SampledSigns {
    /// None where the single-precision error has no bound (a library function), or F's
    /// slopes over the domain none.
    pub(super) fn new(formula: &CompiledFormula, params: &[f64], u: &Uniforms) -> Option<Self> {
        let domain = domain_of(u);
        let error = single_precision_error(&formula.tape_f, 0, &domain, params)?;
        // (F and ∇F: the tape's first five outputs.)
        let mut all = [Interval::EMPTY; 5];
        IntervalEvaluator::new().eval_into(&formula.tape_all, &domain, params, &mut all);
        let slopes: [f64; 4] = std::array::from_fn(|k| all[k + 1].magnitude());
        slopes.iter().all(|g| g.is_finite()).then(|| Self {
            error,
            slopes,
            lo: domain.map(|d| d.lo() + NEAR),
            hi: domain.map(|d| d.hi() - NEAR),
            n1: u.n1.map(f64::from),
            n2: u.n2.map(f64::from),
        })
    }

    /// F's sign (1, −1; 0: not proved) at the point (s, t) = `at` of the plane through `o`,
    /// from F's f32 value `f` at the f32 point `p` (the march's point there): by the mean
    /// value theorem on the segment between them, in the (convex) domain.
    pub(super) fn sign(&self, (o, at): (V4, [f64; 2]), (p, f): (V4, f32)) -> i8 {
        let (mut reach, mut near) = (self.error, true);
        for k in 0..4 {
            let (a, b, c) = (f64::from(o[k]), at[0] * self.n1[k], at[1] * self.n2[k]);
            let pk = f64::from(p[k]);
            // (The end's coordinate in f64 is within 4 roundings of 2^-53 of its terms.)
            let far = (a + b + c - pk).abs() + (a.abs() + b.abs() + c.abs()) * 4.0 * f64::EPSILON;
            near &= far <= NEAR && pk >= self.lo[k] && pk <= self.hi[k];
            reach += self.slopes[k] * far;
        }
        // (A relative margin for this sum's own rounding.)
        let (f, reach) = (f64::from(f), reach * (1.0 + 1e-9));
        match (near, f > reach, f < -reach) {
            (true, true, _) => 1,
            (true, _, true) => -1,
            _ => 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::shading::{add, dot as dot4, scale, sub};
    use super::super::{Certifier, SignChange};
    use super::*;
    use crate::eval::PointEvaluator;
    use crate::render::view::FLAG_CONTINUOUS;
    use bytemuck::Zeroable;
    use proptest::prelude::*;

    /// The samples' signs for `text` over [−1.5, 1.5]⁴, the plane along x and y.
    fn signs(text: &str) -> Option<SampledSigns> {
        let f = CompiledFormula::compile(text).unwrap();
        let mut u = Uniforms::zeroed();
        (u.domain_lo, u.domain_hi) = ([-1.5; 4], [1.5; 4]);
        (u.n1, u.n2) = ([1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]);
        SampledSigns::new(&f, &[], &u)
    }

    /// A sample well away from 0 proves its sign at an end by its point; one near 0, an end
    /// farther from it, or a point outside the domain, not.
    #[test]
    fn a_sample_proves_its_sign_only_far_from_zero_and_near_its_end() {
        let s = signs("x^2 + y^2 + z^2 + w^2 - 1").unwrap();
        let o = [0.0, 0.0, 0.2, 0.0];
        let p = [0.5, 0.0, 0.2, 0.0];
        assert_eq!(s.sign((o, [0.5, 0.0]), (p, -0.71)), -1);
        let q = [1.2, 0.1, 0.2, 0.0];
        assert_eq!(s.sign((o, [1.2, 0.1]), (q, 0.49)), 1);
        assert_eq!(s.sign((o, [1.2, 0.1]), (q, 1e-7)), 0);
        // |∂F/∂x| ≤ 3 over the domain: an end 0.2 away may have the other sign.
        assert_eq!(s.sign((o, [1.0, 0.1]), (q, 0.49)), 0);
        let out = [1.6, 0.0, 0.2, 0.0];
        assert_eq!(s.sign((o, [1.6, 0.0]), (out, 1.6)), 0);
    }

    /// No bound without one on the f32 error.
    #[test]
    fn library_functions_prove_nothing_here() {
        assert!(signs("sin(3x) + y").is_none());
    }

    proptest! {
        /// A bracket end's sign proved from the march's sample is F's sign there, and the
        /// one balls prove where they prove one, however the plane is turned; a sample
        /// clear of 0 proves it.
        #[test]
        fn signs_from_samples_are_the_signs_balls_prove(
            angles in prop::array::uniform2(-3.0f32..3.0),
            o in prop::array::uniform4(-0.7f32..0.7),
            ts in prop::array::uniform2(-1.2f32..1.2),
            offset in -0.4f32..0.4,
        ) {
            let text = "x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1";
            let formula = CompiledFormula::compile(text).unwrap();
            let mut u = Uniforms::zeroed();
            let ([ca, sa], [cb, sb]) = (angles.map(f32::cos), angles.map(f32::sin));
            (u.n1, u.n2) = ([ca, 0.0, sa, 0.0], [0.0, cb, 0.0, sb]);
            (u.domain_lo, u.domain_hi) = ([-1.5; 4], [1.5; 4]);
            u.control.flags = FLAG_CONTINUOUS;
            let mut certifier = Certifier::new(&formula, &[], &u);
            // The ends as a slice's march has them: along n1 from the line's start.
            let start = add(o, scale(u.n2, offset));
            let ends = ts.map(|t| {
                let p = add(start, scale(u.n1, t));
                let f = PointEvaluator::single_precision().eval(&formula.tape_f, p.map(f64::from), &[]);
                let rel = sub(p, o);
                ([f64::from(dot4(rel, u.n1)), f64::from(dot4(rel, u.n2))], (p, f as f32))
            });
            let change = SignChange { ends: ends.map(|e| e.0), samples: Some(ends.map(|e| e.1)) };
            let mut signs = Vec::new();
            certifier.bracket_signs([(o, Some(change))], &mut signs);
            let sampled = signs[0].unwrap();
            certifier.bracket_signs([(o, Some(SignChange { samples: None, ..change }))], &mut signs);
            let by_balls = signs[0].unwrap();
            for end in 0..2 {
                let [s, t] = change.ends[end];
                let x: [f64; 4] = std::array::from_fn(|k| {
                    f64::from(o[k]) + s * f64::from(u.n1[k]) + t * f64::from(u.n2[k])
                });
                let exact = PointEvaluator::new().eval(&formula.tape_f, x, &[]);
                let (proved, f) = (sampled[end], f64::from(ends[end].1.1));
                if proved != 0 {
                    prop_assert_eq!(f64::from(proved), exact.signum(), "{:?}", x);
                    prop_assert!(by_balls[end] == 0 || by_balls[end] == proved);
                }
                let inside = x.iter().all(|v| v.abs() < 1.49);
                prop_assert!(!inside || f.abs() < 1e-3 || proved != 0, "{f} at {x:?} not proved");
            }
        }
    }
}
