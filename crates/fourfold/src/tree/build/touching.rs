//! How much of M lies where F only touches 0 (reaches it from one side, never crossing):
//! measured once on the finished tree, for the note the front ends give.

use crate::eval::{Interval, IntervalEvaluator};
use crate::formula::CompiledFormula;

use super::tree::Tree16;

/// A sixty-fourth of a leaf's width on each side: the sliver a one-sided leaf is widened by.
const SLIVER: f64 = 1.0 / 64.0;

/// The one-sided leaves widened at most, spread evenly over them: the share only says
/// whether a note is due and how large the part is, and a sample keeps it off the build's
/// time (widening every kept one-sided box took a square's build 24 → 40 ms).
const SAMPLE: usize = 256;

impl Tree16 {
    /// Sets `TreeStats::touching_share`: of the leaves over which F□ reaches 0 from one side
    /// only, the share over which it still does over the leaf widened by a sliver. A zero
    /// on a leaf's face across which F changes sign (x = 0 on a grid of boxes through it,
    /// whose boxes are [0, h] and [−h, 0]) reaches both sides there; a zero where F touches
    /// 0 (y² along y = 0) does not.
    pub(super) fn measure_touching(&mut self, formula: &CompiledFormula, params: &[f64]) {
        let one_sided: Vec<_> = self
            .leaves()
            .filter(|(_, b)| !(b.below && b.above))
            .collect();
        let k = one_sided.len().min(SAMPLE);
        let mut eval = IntervalEvaluator::new();
        let still = (0..k)
            .filter(|&i| {
                let (level, leaf) = one_sided[i * one_sided.len() / k];
                let widened = self.box_of(level, leaf).map(|a| {
                    let w = SLIVER * a.width();
                    Interval::new(a.lo() - w, a.hi() + w)
                });
                let f = eval.eval(&formula.tape_f, &widened, params);
                !(f.lo() < 0.0 && f.hi() > 0.0)
            })
            .count();
        let share = if k == 0 {
            0.0
        } else {
            still as f64 / k as f64 * one_sided.len() as f64 / self.stats.leaves as f64
        };
        self.stats.touching_share = share;
        self.stats.interval_evaluations += k as u64;
    }
}
