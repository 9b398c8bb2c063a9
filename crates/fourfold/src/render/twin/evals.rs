//! The point evaluators of a worker's pixels: one per tape, each keeping its tape's values
//! from point to point; a square-on slice's tape of F and one partial; and F, or F and ∇F,
//! at up to sixteen points at once, for a tile's roots and hits.

use crate::eval::{LANES, PointEvaluator, PointLanes, Tape};
use crate::formula::CompiledFormula;

use super::root::RootSearch;
use super::shading::{V4, add, scale, slope};

/// The point evaluators of a row of pixels, one per tape so that each keeps its tape's
/// uniform prefix from pixel to pixel, and F and ∇F's at up to [`LANES`] points at once.
pub(super) struct Evaluators {
    pub(super) f: PointEvaluator,
    pub(super) all: PointEvaluator,
    pub(super) along: Option<(AxisSlope, PointEvaluator)>,
    lanes: PointLanes,
    /// The roots of [`Self::find_roots`] still seeking, by index.
    seeking: Vec<usize>,
    /// Whether F's tape, and ∇F's, are arithmetic alone (no library function past their
    /// uniform prefix): where lanes of them pay (see [`Self::gradients`]).
    arithmetic: [bool; 2],
}

/// A root a slice's ray found a sign change for, its steps left for later (see
/// `Pixel::deferred`): the search, the ray's origin and direction, and its index.
#[derive(Debug, Clone, Copy)]
pub(super) struct Deferred {
    pub(super) search: RootSearch,
    pub(super) o: V4,
    pub(super) d: V4,
    pub(super) ray: u32,
}

impl Evaluators {
    /// With `along`, a slice's march takes its samples' slopes from that tape.
    pub(super) fn new(formula: &CompiledFormula, along: Option<&AxisSlope>) -> Self {
        Self {
            f: PointEvaluator::single_precision(),
            all: PointEvaluator::single_precision(),
            along: along.map(|a| (a.clone(), PointEvaluator::single_precision())),
            lanes: PointLanes::new(),
            seeking: Vec::new(),
            arithmetic: [
                !formula.tape_f.calls_library(),
                !formula.tape_grad.calls_library(),
            ],
        }
    }

    /// Whether a slice's roots are better sought together (see `Pixel::deferred`):
    /// where F's tape is arithmetic alone.
    pub(super) fn defers_roots(&self) -> bool {
        self.arithmetic[0]
    }

    /// F and dF/dt along `d` at each of `points` (1 to [`LANES`]) into `out`, bit for bit
    /// as `Pixel::f_slope` has them where the sample needs dF/dt.
    pub(super) fn samples(
        &mut self,
        formula: &CompiledFormula,
        params: &[f64],
        (points, d): (&[V4], V4),
        out: &mut [[f32; 2]],
    ) {
        let lanes = &mut self.lanes;
        match &self.along {
            Some((along, _)) => {
                lanes.eval(&along.tape, points, params);
                for (l, out) in out[..points.len()].iter_mut().enumerate() {
                    let partial = f64::from(lanes.output(&along.tape, 1, l));
                    *out = [lanes.output(&along.tape, 0, l), along.slope(partial, d)];
                }
            }
            None => {
                let tape = &formula.tape_all;
                lanes.eval(tape, points, params);
                for (l, out) in out[..points.len()].iter_mut().enumerate() {
                    let g: V4 = std::array::from_fn(|k| lanes.output(tape, k + 1, l));
                    *out = [lanes.output(tape, 0, l), slope(g, d)];
                }
            }
        }
    }

    /// Finds each of `roots`, their evaluations [`LANES`] at a time (the same values
    /// as one by one: see [`PointLanes`]).
    pub(super) fn find_roots(
        &mut self,
        formula: &CompiledFormula,
        params: &[f64],
        roots: &mut [Deferred],
    ) {
        let tape = &formula.tape_f;
        let mut active = std::mem::take(&mut self.seeking);
        active.clear();
        active.extend(0..roots.len());
        let mut batch = [[0.0f32; 4]; LANES];
        let mut which = [0usize; LANES];
        while !active.is_empty() {
            for chunk in active.chunks(LANES) {
                let mut n = 0;
                for &k in chunk {
                    let r = &mut roots[k];
                    if let Some(t) = r.search.next() {
                        (batch[n], which[n]) = (add(r.o, scale(r.d, t)), k);
                        n += 1;
                    }
                }
                if n == 0 {
                    continue;
                }
                self.lanes.eval(tape, &batch[..n], params);
                for (lane, &k) in which[..n].iter().enumerate() {
                    roots[k].search.take(self.lanes.output(tape, 0, lane));
                }
            }
            active.retain(|&k| roots[k].search.next().is_some());
        }
        self.seeking = active;
    }

    /// ∇F at each of `points` into `out`, in f32 as `Pixel::f_grad` has it: [`LANES`] at
    /// a time by ∇F's own tape where it is arithmetic alone (lanes of it vectorize; the same
    /// values, from the same instructions, without F's), else point by point (a library
    /// function runs lane by lane anyway, and the point evaluator does not run again what
    /// reads only coordinates that did not move, most of it along a slice's rays).
    pub(super) fn gradients(
        &mut self,
        formula: &CompiledFormula,
        params: &[f64],
        points: impl ExactSizeIterator<Item = V4>,
        out: &mut Vec<V4>,
    ) {
        out.clear();
        let tape = &formula.tape_all;
        if !self.arithmetic[1] {
            out.extend(points.map(|p| {
                let mut fg = [0.0; 5];
                self.all.eval_into(tape, p.map(f64::from), params, &mut fg);
                std::array::from_fn(|k| fg[k + 1] as f32)
            }));
            return;
        }
        let mut batch = [[0.0f32; 4]; LANES];
        let mut n = 0;
        for p in points {
            batch[n] = p;
            n += 1;
            if n == LANES {
                self.lanes_into(formula, params, n, &batch, out);
                n = 0;
            }
        }
        if n > 0 {
            self.lanes_into(formula, params, n, &batch, out);
        }
    }

    fn lanes_into(
        &mut self,
        formula: &CompiledFormula,
        params: &[f64],
        n: usize,
        batch: &[V4; LANES],
        out: &mut Vec<V4>,
    ) {
        let tape = &formula.tape_grad;
        self.lanes.eval(tape, &batch[..n], params);
        let lanes = &self.lanes;
        out.extend((0..n).map(|l| std::array::from_fn(|k| lanes.output(tape, k, l))));
    }
}

/// Where a slice's rays run along an axis (n1 = ±e_k: a slice seen square on), the tape of
/// F and ∂F/∂x_k alone, so that a sample's slope along the ray costs no other partial
/// (the sextic's three others are a third of F and ∇F's instructions that move along z).
/// The slope is the same value as from the whole gradient wherever the others are finite:
/// x·0 is 0 and the sum's other terms vanish.
#[derive(Clone)]
pub(super) struct AxisSlope {
    pub(super) axis: usize,
    pub(super) tape: Tape,
}

impl AxisSlope {
    /// dF/dt along `d` (±e_k) from ∂F/∂x_k.
    pub(super) fn slope(&self, partial: f64, d: V4) -> f32 {
        (partial * f64::from(d[self.axis])) as f32
    }

    /// The tape for the rays along `n1`, if n1 is an axis.
    pub(super) fn of(formula: &CompiledFormula, n1: V4) -> Option<Self> {
        let axis = (0..4).find(|&k| n1[k].abs() == 1.0)?;
        let others_zero = (0..4).all(|j| j == axis || n1[j] == 0.0);
        others_zero.then(|| Self {
            axis,
            tape: Tape::new(&formula.graph, &[formula.f, formula.gradient[axis]]),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Only an axis (either way) makes an [`AxisSlope`]; a turned direction does not.
    #[test]
    fn only_rays_along_an_axis_take_one_partial() {
        let f = CompiledFormula::compile("x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1").unwrap();
        assert_eq!(
            AxisSlope::of(&f, [0.0, 0.0, 1.0, 0.0]).map(|a| a.axis),
            Some(2)
        );
        assert_eq!(
            AxisSlope::of(&f, [-1.0, 0.0, 0.0, 0.0]).map(|a| a.axis),
            Some(0)
        );
        assert!(AxisSlope::of(&f, [0.0, 0.6, 0.8, 0.0]).is_none());
        assert!(AxisSlope::of(&f, [1e-8, 0.0, 1.0, 0.0]).is_none());
    }

    proptest! {
        /// F and the slope along the axis from the one partial's tape are, bit for bit, F
        /// and `slope` of the whole gradient, as the GPU's f32 evaluation gives them.
        #[test]
        fn the_axis_slope_is_the_whole_gradient_s(
            p in prop::array::uniform4(-2.0f32..2.0),
            axis in 0usize..4,
            reverse in prop::bool::ANY,
        ) {
            let sources = [
                "x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1",
                "(x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4R^2(x^2 + y^2) - w",
                "cos(3x) + cos(3y) + cos(3z) + cos(3w)",
                "sqrt(x^2 + y^2) * exp(z) - w/(1 + y^2)",
            ];
            let mut d = [0.0f32; 4];
            d[axis] = if reverse { -1.0 } else { 1.0 };
            for src in sources {
                let f = CompiledFormula::compile(src).unwrap();
                let params = [2.0, 1.0];
                let along = AxisSlope::of(&f, d).unwrap();
                let mut one = [0.0; 2];
                PointEvaluator::single_precision().eval_into(&along.tape, p.map(f64::from), &params, &mut one);
                let mut all = [0.0; 5];
                PointEvaluator::single_precision().eval_into(&f.tape_all, p.map(f64::from), &params, &mut all);
                let g: V4 = std::array::from_fn(|k| all[k + 1] as f32);
                prop_assume!(g.iter().all(|v| v.is_finite()));
                prop_assert_eq!((one[0] as f32).to_bits(), (all[0] as f32).to_bits(), "{}", src);
                let mine = along.slope(one[1], d);
                prop_assert_eq!(mine, slope(g, d), "{} at {:?}", src, p);
            }
        }
    }
}
