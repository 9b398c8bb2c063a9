//! The cut: which boxes the ray caster marches whole. Leaves and the boxes at the march level,
//! and coarser boxes where the slope bounds of the box and its descendants allow, or it has
//! curvature bounds (a large box then costs little more than its descendants would).

use rayon::prelude::*;

use crate::eval::IntervalEvaluator;
use crate::gpu_layout::Curvature;
use crate::tree::build::Tree16;

use super::data::COARSEN_LOOSENESS;

/// The boxes of `tree`'s first `depth` levels that are marched whole whatever their bounds:
/// leaves, and the boxes at level `depth - 1` (the march level).
pub(super) fn always_marched(tree: &Tree16, depth: usize) -> Vec<Vec<bool>> {
    tree.levels[..depth]
        .iter()
        .enumerate()
        .map(|(l, boxes)| {
            boxes
                .iter()
                .map(|b| b.child_count == 0 || l + 1 == depth)
                .collect()
        })
        .collect()
}

/// Which boxes of `tree`'s first `depth` levels are marched whole: leaves, the boxes at
/// level `depth - 1` (the march level), and, where `slopes` are given (per level), every
/// box whose bound (the sum of its four) and its descendants' at the march level or leaves
/// are finite, and that either has a slope bound at most [`COARSEN_LOOSENESS`] times the
/// largest of its descendants' or curvature bounds (`curvature(evaluator, level, index)`).
/// Also the curvature it worked out, per level and box (None where it did not need it).
#[allow(clippy::type_complexity)]
pub(super) fn cut(
    tree: &Tree16,
    depth: usize,
    slopes: &[Vec<[f32; 4]>],
    curvature: impl Fn(&mut IntervalEvaluator, usize, usize) -> Curvature + Sync,
) -> (Vec<Vec<bool>>, Vec<Vec<Option<Curvature>>>) {
    let total = |s: &[f32; 4]| s.iter().sum::<f32>();
    let mut marched = always_marched(tree, depth);
    let mut known: Vec<Vec<Option<Curvature>>> =
        marched.iter().map(|m| vec![None; m.len()]).collect();
    if slopes.is_empty() {
        return (marched, known);
    }
    // The largest descendant bound, bottom-up (a box marched anyway: its own).
    let mut below: Vec<Vec<f32>> = marched.iter().map(|m| vec![0.0; m.len()]).collect();
    for l in (0..depth).rev() {
        for (i, b) in tree.levels[l].iter().enumerate() {
            below[l][i] = if marched[l][i] {
                total(&slopes[l][i])
            } else {
                let children =
                    b.first_child as usize..b.first_child as usize + b.child_count as usize;
                below[l + 1][children].iter().copied().fold(0.0, f32::max)
            };
        }
    }
    // Top-down: a box inside one marched whole needs no decision (nor its curvature).
    let mut inside: Vec<Vec<bool>> = marched.iter().map(|m| vec![false; m.len()]).collect();
    for l in 0..depth {
        let decided: Vec<(bool, Option<Curvature>)> = (0..marched[l].len())
            .into_par_iter()
            .map_init(IntervalEvaluator::new, |eval, i| {
                let own = total(&slopes[l][i]);
                if inside[l][i] || !(own.is_finite() && below[l][i].is_finite()) {
                    (false, None)
                } else if own <= COARSEN_LOOSENESS * below[l][i] {
                    (true, None)
                } else {
                    let c = curvature(eval, l, i);
                    (c.is_bounded(), Some(c))
                }
            })
            .collect();
        for (i, b) in tree.levels[l].iter().enumerate() {
            marched[l][i] |= decided[i].0;
            known[l][i] = decided[i].1;
            if (marched[l][i] || inside[l][i]) && l + 1 < depth {
                let children =
                    b.first_child as usize..b.first_child as usize + b.child_count as usize;
                inside[l + 1][children].fill(true);
            }
        }
    }
    (marched, known)
}
