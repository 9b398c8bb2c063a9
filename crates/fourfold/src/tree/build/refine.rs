//! One level's refinement step: a box's 16 children evaluated in one batch (F, then F and ∇F
//! for the survivors, then F at the centres where the mean-value form applies), and which
//! of them may hold M.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::eval::{BatchEvaluator, Box4, Interval, LANES};
use crate::formula::CompiledFormula;

use super::region::Region;
use super::tree::{BuildError, Geometry, TreeBox};

/// The component criterion: F□(B) may contain 0 (an empty F□ means F is undefined on B).
pub(super) fn contains_manifold(f: Interval) -> bool {
    f.contains_zero()
}

/// The mean-value form of F□ on `bx`, where F is continuous (and piecewise differentiable)
/// on it: F(B) ⊆ F□(c) + Σ ∂F/∂x_k□(B)·(B_k − c_k), c the box's centre and `gradient`
/// the enclosures of F's partials over B. False when that proves 0 ∉ F(B). Intersected with
/// the natural extension it is still an interval extension of F (docs/method.md §1), and far
/// tighter on small boxes where terms of F cancel: the chapter's scene keeps 23 912 leaves
/// at level 4 instead of 30 376, and refined uniformly to level 6, 814 304 instead of
/// 2 556 768 (the other example scenes' natural extensions are tight already).
fn mean_value_may_vanish(f_at_centre: Interval, bx: &Box4, gradient: &[Interval]) -> bool {
    let c = centre(bx);
    let mut mv = f_at_centre;
    for k in 0..4 {
        mv = mv.add(gradient[k].mul(bx[k].sub(c[k])));
    }
    // (An empty enclosure, F undefined somewhere, proves nothing.)
    mv.is_empty() || mv.contains_zero()
}

/// The point box at the centre of `bx`, where `mean_value_may_vanish` expands F.
fn centre(bx: &Box4) -> Box4 {
    bx.map(|a| Interval::point(a.midpoint()))
}

/// A child whose F□ holds 0, while `Refinement::children` decides on it.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    /// Its index among its parent's children.
    child: usize,
    bx: Box4,
    /// F is continuous on it, and the mean-value form is to be tried.
    continuous: bool,
    /// ∂F/∂x_k□ over it, when the gradient is evaluated.
    gradient: [Interval; 4],
    critical: bool,
    /// F□ over it (holding 0) reached below 0, and above.
    below: bool,
    above: bool,
    /// The mean-value form proved 0 ∉ F(B).
    discarded: bool,
}

impl Default for Candidate {
    fn default() -> Self {
        Self {
            child: 0,
            bx: [Interval::EMPTY; 4],
            continuous: false,
            gradient: [Interval::ENTIRE; 4],
            critical: false,
            below: false,
            above: false,
            discarded: false,
        }
    }
}

/// What `Refinement::children` made.
pub(super) struct Refined {
    /// The kept children, grouped by parent in parent order.
    pub(super) kept: Vec<TreeBox>,
    /// Interval evaluations made.
    pub(super) evaluations: u64,
    /// Children the natural extension kept and the mean-value form discarded.
    pub(super) pruned: u64,
}

/// The refinement of one level: its boxes (`parents`) and what evaluating their children
/// needs.
pub(super) struct Refinement<'a> {
    pub(super) formula: &'a CompiledFormula,
    pub(super) params: &'a [f64],
    pub(super) geometry: &'a Geometry,
    pub(super) level: u32,
    pub(super) parents: &'a [TreeBox],
    /// Where the tree is built within, if not the whole domain: children that miss it are
    /// left out unevaluated.
    pub(super) region: Option<&'a Region>,
    pub(super) cancel: &'a AtomicBool,
}

/// Parents of a level's sample for `Refinement::mean_value_discards`.
const MEAN_VALUE_SAMPLE: usize = 64;

impl Refinement<'_> {
    /// Evaluates the 16 children of each box in `refine` (indices in `parents`), as one
    /// batch per evaluation: F over all 16, then F and ∇F over those kept, then F at the
    /// centres of those the mean-value form is tried on. A child is kept if F□ holds 0 (docs/method.md §2): the natural interval extension, and with
    /// `mean_value` (which needs `gradient`), where F is continuous on the box, the
    /// mean-value form too (see `mean_value_may_vanish`). With `gradient` the topological
    /// criterion is set on the kept ones.
    pub(super) fn children(
        &self,
        refine: &[u32],
        gradient: bool,
        mean_value: bool,
    ) -> Result<Refined, BuildError> {
        let (formula, params) = (self.formula, self.params);
        let groups: Vec<Refined> = refine
            .par_chunks(64)
            .map_init(BatchEvaluator::new, |eval, parents| {
                if self.cancel.load(Ordering::Relaxed) {
                    return Err(BuildError::Cancelled);
                }
                let (mut evaluations, mut pruned) = (0u64, 0u64);
                let mut kept = Vec::with_capacity(parents.len() * 4);
                for &p in parents {
                    let c = self.parents[p as usize].coords;
                    let coords: [[u16; 4]; LANES] = std::array::from_fn(|k| {
                        std::array::from_fn(|i| 2 * c[i] + ((k as u16 >> i) & 1))
                    });
                    // The children within the region (all of them without one), `m` of
                    // them: `child[j]` is the index of the j-th.
                    let (mut child, mut boxes) = ([0; LANES], [[Interval::EMPTY; 4]; LANES]);
                    let mut m = 0;
                    for (k, &at) in coords.iter().enumerate() {
                        let bx = self.geometry.box_at(self.level + 1, at);
                        if self.region.is_none_or(|r| r.meets(&bx)) {
                            (child[m], boxes[m]) = (k, bx);
                            m += 1;
                        }
                    }
                    if m == 0 {
                        continue;
                    }
                    eval.eval(&formula.tape_f, &boxes[..m], params);
                    evaluations += m as u64;
                    // The children whose F□ holds 0, in order (`n` of them), and whether F is
                    // continuous on each (read now: the next evaluation replaces F's).
                    let mut candidates = [Candidate::default(); LANES];
                    let mut n = 0;
                    for (j, bx) in boxes[..m].iter().enumerate() {
                        let f = eval.output(&formula.tape_f, 0, j);
                        if contains_manifold(f) {
                            candidates[n] = Candidate {
                                child: child[j],
                                bx: *bx,
                                continuous: mean_value && eval.continuous(&formula.tape_f, j),
                                below: f.lo() < 0.0,
                                above: f.hi() > 0.0,
                                ..Candidate::default()
                            };
                            n += 1;
                        }
                    }
                    let candidates = &mut candidates[..n];
                    if candidates.is_empty() {
                        continue;
                    }
                    if gradient {
                        let bxs: [Box4; LANES] =
                            std::array::from_fn(|j| candidates[j.min(n - 1)].bx);
                        eval.eval(&formula.tape_all, &bxs[..n], params);
                        evaluations += n as u64;
                        for (lane, c) in candidates.iter_mut().enumerate() {
                            c.gradient = std::array::from_fn(|k| {
                                eval.output(&formula.tape_all, k + 1, lane)
                            });
                            c.critical = c.gradient.iter().all(|g| g.contains_zero());
                        }
                    }
                    if candidates.iter().any(|c| c.continuous) {
                        let centres: [Box4; LANES] =
                            std::array::from_fn(|j| centre(&candidates[j.min(n - 1)].bx));
                        eval.eval(&formula.tape_f, &centres[..n], params);
                        for (lane, c) in candidates.iter_mut().enumerate() {
                            if c.continuous {
                                evaluations += 1;
                                let f_at_centre = eval.output(&formula.tape_f, 0, lane);
                                if !mean_value_may_vanish(f_at_centre, &c.bx, &c.gradient) {
                                    pruned += 1;
                                    c.discarded = true;
                                }
                            }
                        }
                    }
                    kept.extend(candidates.iter().filter(|c| !c.discarded).map(|c| TreeBox {
                        coords: coords[c.child],
                        parent: p,
                        first_child: 0,
                        child_count: 0,
                        critical: c.critical,
                        below: c.below,
                        above: c.above,
                    }));
                }
                Ok(Refined {
                    kept,
                    evaluations,
                    pruned,
                })
            })
            .collect::<Result<_, _>>()?;
        Ok(Refined {
            evaluations: groups.iter().map(|g| g.evaluations).sum(),
            pruned: groups.iter().map(|g| g.pruned).sum(),
            kept: groups.into_iter().flat_map(|g| g.kept).collect(),
        })
    }

    /// Whether the mean-value form discards any child of a sample of `refine` (up to
    /// MEAN_VALUE_SAMPLE boxes spread over it) that the natural extension keeps (where F's
    /// natural extension is exact or nearly, as for the glome's sum of squares, it never
    /// does), and the interval evaluations that took.
    pub(super) fn mean_value_discards(&self, refine: &[u32]) -> Result<(bool, u64), BuildError> {
        let n = refine.len().min(MEAN_VALUE_SAMPLE);
        let sample: Vec<u32> = (0..n).map(|i| refine[i * refine.len() / n]).collect();
        let probe = self.children(&sample, true, true)?;
        Ok((probe.pruned > 0, probe.evaluations))
    }
}
