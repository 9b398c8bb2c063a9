//! Which of a tape's instructions an evaluator runs again for a new point or box: those
//! reading a coordinate that moved since its last (its slots keep the others' values, the
//! same values). Along a line parallel to an axis (a slice's rays seen square on, a tile's
//! lines), that is most of a tape: the point evaluator's samples, the interval evaluator's
//! pieces of a tile's lines.

use super::tape::{Op, PrefixKey, Tape, moved};

/// What an evaluator keeps between calls to run again only what moved: the tape and
/// parameters its slots hold values of, its last point's or box's coordinates, as bits
/// (None: its slots hold no values), and its plans.
#[derive(Debug, Clone, Default)]
pub(crate) struct Moves<B> {
    prefix: PrefixKey,
    last: Option<[B; 4]>,
    pub(crate) plans: Plans,
}

impl<B: PartialEq> Moves<B> {
    /// For `tape` and `params` at `bits`: the coordinates that moved since the last call
    /// (bit k: x_k), and whether all must run (another tape or parameters: the slots hold
    /// nothing of theirs), as `run_tape!` takes them.
    pub(crate) fn since(&mut self, tape: &Tape, params: &[f64], bits: [B; 4]) -> (u8, bool) {
        let stale = self.prefix.stale(tape, params);
        if stale {
            self.plans.clear();
        }
        let moved = moved(self.last.take().filter(|_| !stale), &bits);
        self.last = Some(bits);
        (moved, stale)
    }
}

/// For one tape and parameters, by the set of coordinates that moved (a bit each), the
/// instructions reading any of them (made when first needed).
#[derive(Debug, Clone, Default)]
pub(crate) struct Plans([Option<Run>; 16]);

/// What a set of moved coordinates runs.
#[derive(Debug, Clone)]
enum Run {
    Whole,
    Only(Vec<(u32, Op)>),
}

impl Plans {
    /// Forgets every plan (another tape or parameters).
    fn clear(&mut self) {
        self.0.iter_mut().for_each(|r| *r = None);
    }

    /// The instructions of `tape` that read a coordinate in `moved`, in order, with their
    /// indices; None where they are most of those past the uniform prefix, which then run
    /// straight through (a list costs more a step).
    pub(crate) fn only(&mut self, tape: &Tape, moved: u8) -> Option<&[(u32, Op)]> {
        let run = self.0[usize::from(moved)].get_or_insert_with(|| {
            let reads = tape.reads().iter().zip(tape.ops()).enumerate();
            let list: Vec<(u32, Op)> = reads
                .filter(|&(_, (&r, _))| r & moved != 0)
                .map(|(i, (_, &op))| (i as u32, op))
                .collect();
            let rest = tape.len() - tape.uniform_len();
            if moved != 0 && 5 * list.len() > 4 * rest {
                Run::Whole
            } else {
                Run::Only(list)
            }
        });
        match run {
            Run::Whole => None,
            Run::Only(list) => Some(list),
        }
    }
}

/// Runs the instructions of `$tape` that `($moved, $all)` ask for into `$slots`, each by
/// `$value(op, slots, args…)`: all where `$all` (the slots hold nothing of this tape and
/// parameters), else those reading a moved coordinate, listed by `$runs` ([`Plans`]) or,
/// where they are most of the tape, straight through. A macro, not a function taking a
/// closure, which made frames 5–20% slower.
macro_rules! run_tape {
    ($slots:expr, $runs:expr, $tape:expr, ($moved:expr, $all:expr), $value:ident($($arg:expr),*)) => {{
        let only = (!$all && $moved != 0xf)
            .then(|| $runs.only($tape, $moved))
            .flatten();
        if let Some(list) = only {
            for &(i, op) in list {
                $slots[i as usize] = $value(op, $slots, $($arg),*);
            }
        } else {
            let start = if $all { 0 } else { $tape.uniform_len() };
            for (i, &op) in $tape.ops().iter().enumerate().skip(start) {
                $slots[i] = $value(op, $slots, $($arg),*);
            }
        }
    }};
}
pub(crate) use run_tape;
