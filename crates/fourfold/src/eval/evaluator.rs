//! The one contract every evaluator of a tape keeps (as fidget's evaluators do), so that one
//! conformance suite (`tests/conformance.rs`) checks them all: the point evaluator, the
//! interval evaluator, the batch evaluator and the GPU's enclosures (`headless::probe`).

use crate::interval::Interval;

use super::batch::{BatchEvaluator, LANES};
use super::interval_eval::{Box4, IntervalEvaluator};
use super::point::PointEvaluator;
use super::tape::Tape;

/// Evaluates every output of a tape over a batch of inputs.
pub trait Evaluator {
    /// What it evaluates at: a point of R⁴, or a box.
    type Input;
    /// What comes out: a number (NaN where undefined), or an enclosure of every value over
    /// the input (empty where undefined everywhere).
    type Output: Copy;

    /// The most inputs one call takes (at least 1).
    fn batch_size(&self) -> usize;

    /// Evaluates every output of `tape` at each of `inputs` (1 to [`batch_size`] of them)
    /// with the parameter values `params`, writing output k of input i to
    /// `out[i * tape.outputs().len() + k]`; Err says why it could not (the GPU failed, or
    /// the evaluator cannot run this tape).
    ///
    /// [`batch_size`]: Evaluator::batch_size
    fn evaluate(
        &mut self,
        tape: &Tape,
        inputs: &[Self::Input],
        params: &[f64],
        out: &mut [Self::Output],
    ) -> Result<(), String>;

    /// For input `i` of the last call: whether the function the tape computes was proved
    /// defined and continuous over it (interval evaluators that track it); None where the
    /// evaluator does not tell.
    fn continuous(&self, _tape: &Tape, _i: usize) -> Option<bool> {
        None
    }
}

/// Checks the common preconditions of [`Evaluator::evaluate`].
pub fn check_call<I, O>(tape: &Tape, inputs: &[I], out: &[O], batch: usize) -> Result<(), String> {
    if inputs.is_empty() || inputs.len() > batch {
        return Err(format!(
            "a call takes 1 to {batch} inputs, not {}",
            inputs.len()
        ));
    }
    let needed = inputs.len() * tape.outputs().len();
    if out.len() < needed {
        return Err(format!(
            "{needed} outputs need room, the buffer holds {}",
            out.len()
        ));
    }
    Ok(())
}

/// A point of R⁴ (x, y, z, w).
pub type Point4 = [f64; 4];

impl Evaluator for PointEvaluator {
    type Input = Point4;
    type Output = f64;

    fn batch_size(&self) -> usize {
        usize::MAX
    }

    fn evaluate(
        &mut self,
        tape: &Tape,
        inputs: &[Point4],
        params: &[f64],
        out: &mut [f64],
    ) -> Result<(), String> {
        check_call(tape, inputs, out, usize::MAX)?;
        let n = tape.outputs().len();
        for (p, values) in inputs.iter().zip(out.chunks_mut(n)) {
            self.eval_into(tape, *p, params, values);
        }
        Ok(())
    }
}

impl Evaluator for IntervalEvaluator {
    type Input = Box4;
    type Output = Interval;

    /// One box: what it tells of continuity is of the last box it evaluated.
    fn batch_size(&self) -> usize {
        1
    }

    fn evaluate(
        &mut self,
        tape: &Tape,
        inputs: &[Box4],
        params: &[f64],
        out: &mut [Interval],
    ) -> Result<(), String> {
        check_call(tape, inputs, out, 1)?;
        self.eval_into(tape, &inputs[0], params, out);
        Ok(())
    }

    fn continuous(&self, tape: &Tape, _i: usize) -> Option<bool> {
        Some(self.continuous_on_last_box(tape))
    }
}

impl Evaluator for BatchEvaluator {
    type Input = Box4;
    type Output = Interval;

    fn batch_size(&self) -> usize {
        LANES
    }

    fn evaluate(
        &mut self,
        tape: &Tape,
        inputs: &[Box4],
        params: &[f64],
        out: &mut [Interval],
    ) -> Result<(), String> {
        check_call(tape, inputs, out, LANES)?;
        self.eval(tape, inputs, params);
        let n = tape.outputs().len();
        for (lane, values) in out.chunks_mut(n).take(inputs.len()).enumerate() {
            for (k, v) in values.iter_mut().enumerate() {
                *v = self.output(tape, k, lane);
            }
        }
        Ok(())
    }

    fn continuous(&self, tape: &Tape, i: usize) -> Option<bool> {
        Some(BatchEvaluator::continuous(self, tape, i))
    }
}
