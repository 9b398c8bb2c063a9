//! Interval evaluation of a [`Tape`] over up to [`LANES`] boxes at once: the 16 children of a
//! 16-tree box in one pass. Each instruction is dispatched once for all of them, and the
//! common arithmetic runs as a loop over lanes with no branch, which the compiler vectorizes.
//! The results are bit for bit those of [`IntervalEvaluator`](super::IntervalEvaluator): both
//! call the same [`Interval`] operations.

use multiversion::multiversion;

use crate::expr::{BinaryOp, UnaryOp};

use super::interval_eval::{Box4, apply, continuous, unary};
use super::tape::{Op, PrefixKey, Tape, prepare_slots};
use crate::interval::Interval;
use crate::interval::trig;

/// Boxes per pass: a 16-tree box's children.
pub const LANES: usize = 16;

/// One slot of the tape for every lane, the bounds apart so that a lane loop reads them
/// densely.
#[derive(Debug, Clone, Copy)]
struct Lanes {
    lo: [f64; LANES],
    hi: [f64; LANES],
}

impl Lanes {
    const fn splat(v: Interval) -> Self {
        Self {
            lo: [v.lo(); LANES],
            hi: [v.hi(); LANES],
        }
    }

    #[inline(always)]
    fn get(&self, lane: usize) -> Interval {
        Interval::from_bounds(self.lo[lane], self.hi[lane])
    }

    #[inline(always)]
    fn set(&mut self, lane: usize, v: Interval) {
        self.lo[lane] = v.lo();
        self.hi[lane] = v.hi();
    }
}

/// `out = f(a)` lane by lane; `f` should have no branch, so that the loop vectorizes.
#[inline(always)]
fn map(out: &mut Lanes, a: &Lanes, f: impl Fn(Interval) -> Interval) {
    for l in 0..LANES {
        out.set(l, f(a.get(l)));
    }
}

/// `out = f(a, b)` lane by lane; as [`map`].
#[inline(always)]
fn zip(out: &mut Lanes, a: &Lanes, b: &Lanes, f: impl Fn(Interval, Interval) -> Interval) {
    for l in 0..LANES {
        out.set(l, f(a.get(l), b.get(l)));
    }
}

/// `out = fast(a, b)` lane by lane with no branch, where `fits(a, b)` says `fast` applies (in
/// the usual case, all lanes); the other lanes are then redone by `full`, which branches.
#[inline(always)]
fn guarded(
    out: &mut Lanes,
    (a, b): (&Lanes, &Lanes),
    fits: impl Fn(Interval, Interval) -> bool,
    fast: impl Fn(Interval, Interval) -> Interval,
    full: impl Fn(Interval, Interval) -> Interval,
) {
    let mut all_fit = true;
    for l in 0..LANES {
        let (x, y) = (a.get(l), b.get(l));
        out.set(l, fast(x, y));
        all_fit &= fits(x, y);
    }
    if !all_fit {
        for l in 0..LANES {
            let (x, y) = (a.get(l), b.get(l));
            if !fits(x, y) {
                out.set(l, full(x, y));
            }
        }
    }
}

/// Reusable interval evaluator over batches of boxes.
#[derive(Debug, Clone, Default)]
pub struct BatchEvaluator {
    slots: Vec<Lanes>,
    prefix: PrefixKey,
    /// Boxes in the last batch (the other lanes repeat its last box).
    len: usize,
}

impl BatchEvaluator {
    pub fn new() -> Self {
        Self::default()
    }

    /// Evaluates every output of `tape` over each of `boxes` (1 to [`LANES`] of them); read
    /// the results with [`Self::output`].
    pub fn eval(&mut self, tape: &Tape, boxes: &[Box4], params: &[f64]) {
        assert!(
            (1..=LANES).contains(&boxes.len()),
            "a batch holds 1 to {LANES} boxes, not {}",
            boxes.len()
        );
        self.len = boxes.len();
        let (slots, start) = prepare_slots(
            &mut self.slots,
            &mut self.prefix,
            tape,
            params,
            Lanes::splat(Interval::EMPTY),
        );
        let ops = tape.ops();
        let uniform = tape.uniform_len();
        // The uniform prefix is the same in every lane: computed once.
        for i in start..uniform {
            let v = apply!(ops[i], boxes[0], params, |k| slots[k as usize].get(0));
            slots[i] = Lanes::splat(v);
        }
        run(ops, slots, uniform, boxes, params);
    }

    /// Output `k` of `tape`, just evaluated, over box `lane` of the batch.
    pub fn output(&self, tape: &Tape, k: usize, lane: usize) -> Interval {
        debug_assert!(lane < self.len);
        self.slots[tape.outputs()[k] as usize].get(lane)
    }

    /// [`IntervalEvaluator::continuous_on_last_box`](super::IntervalEvaluator::continuous_on_last_box)
    /// for box `lane` of the last batch.
    pub fn continuous(&self, tape: &Tape, lane: usize) -> bool {
        debug_assert!(lane < self.len);
        continuous(tape, |i| self.slots[i as usize].get(lane))
    }
}

/// The tape's instructions `ops` past its uniform prefix (`uniform` long) over `boxes` into
/// `slots`, every lane in step. (Also compiled for AVX2: see `eval`.)
#[multiversion(targets("x86_64+avx2"))]
fn run(ops: &[Op], slots: &mut [Lanes], uniform: usize, boxes: &[Box4], params: &[f64]) {
    let last = boxes.len() - 1;
    for i in uniform..ops.len() {
        let (done, rest) = slots.split_at_mut(i);
        let out = &mut rest[0];
        let s = |k: u32| &done[k as usize];
        match ops[i] {
            Op::Add(a, b) => zip(out, s(a), s(b), Interval::add),
            Op::Sub(a, b) => zip(out, s(a), s(b), Interval::sub),
            Op::Mul(a, b) => guarded(
                out,
                (s(a), s(b)),
                Interval::multiplies_finite,
                Interval::mul_finite,
                Interval::mul,
            ),
            Op::Binary(BinaryOp::Div, a, b) => guarded(
                out,
                (s(a), s(b)),
                Interval::divides_finite,
                Interval::div_finite,
                Interval::div,
            ),
            Op::Neg(a) => map(out, s(a), Interval::neg),
            Op::Square(a) => map(out, s(a), Interval::square),
            Op::Unary(UnaryOp::Sqrt, a) => map(out, s(a), Interval::sqrt),
            Op::Unary(op @ (UnaryOp::Sin | UnaryOp::Cos), a) => {
                let shift = i64::from(op == UnaryOp::Cos);
                guarded(
                    out,
                    (s(a), s(a)),
                    |x, _| trig::reducible(x),
                    |x, _| trig::shifted_sin(x, shift),
                    |x, _| unary(op, x),
                )
            }
            Op::Var(axis) => {
                for l in 0..LANES {
                    out.set(l, boxes[l.min(last)][axis as usize & 3]);
                }
            }
            op => {
                for l in 0..LANES {
                    let v = apply!(op, boxes[l.min(last)], params, |k| s(k).get(l));
                    out.set(l, v);
                }
            }
        }
    }
}
