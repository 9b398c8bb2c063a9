//! Certified pixels' verdicts (docs/method.md §5.9): how a frame's alpha carries them, how
//! they are counted, and what to say about the undecided ones.

use crate::tree::{Touching, TreeStats};

/// What a certified pixel proved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Verdict {
    /// F ≠ 0 on the pixel's observer plane within the domain: the background is right.
    Empty = 0,
    /// F changes sign on the plane, so M meets it.
    Hit = 1,
    /// The budget of cells ran out first.
    Undecided = 2,
}

impl Verdict {
    /// The pixel's alpha in a certified frame: 255 − 2·verdict (and 1 less where the GPU
    /// driver cut the pixel's work short).
    pub fn alpha(self) -> u8 {
        255 - 2 * self as u8
    }
}

/// How many pixels got each verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct VerdictCounts {
    pub hit: usize,
    pub empty: usize,
    pub undecided: usize,
}

impl VerdictCounts {
    pub fn of(verdicts: &[Verdict]) -> Self {
        let mut c = Self::default();
        for v in verdicts {
            match v {
                Verdict::Hit => c.hit += 1,
                Verdict::Empty => c.empty += 1,
                Verdict::Undecided => c.undecided += 1,
            }
        }
        c
    }

    /// Undecided pixels as a share of those that may show M (hit or undecided), in percent.
    pub fn undecided_share(&self) -> f64 {
        let covered = self.hit + self.undecided;
        if covered == 0 {
            0.0
        } else {
            100.0 * self.undecided as f64 / covered as f64
        }
    }
}

impl std::ops::AddAssign for VerdictCounts {
    fn add_assign(&mut self, other: Self) {
        self.hit += other.hit;
        self.empty += other.empty;
        self.undecided += other.undecided;
    }
}

impl std::fmt::Display for VerdictCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} hit, {} empty, {} undecided ({:.2}% of the pixels that may show M)",
            self.hit,
            self.empty,
            self.undecided,
            self.undecided_share()
        )
    }
}

/// What a user can do about undecided pixels, naming the budget's control (`knob`). Where
/// F may be discontinuous in the domain (`continuous` false: interval evaluation over the
/// domain could not rule out a pole, a jump or an edge of F's definition), a cell holding a
/// pole encloses every value however small it is, so a pixel whose plane crosses one may
/// stay undecided whatever the budget. Where F only touches 0 (`touching`, see
/// [`touching_note`]), the pixels that see M only there are decided by no budget.
pub fn undecided_advice(continuous: bool, touching: Touching, knob: &str) -> String {
    match touching {
        Touching::Everywhere => {
            "no budget decides them: F does not change sign (see the note)".to_string()
        }
        Touching::Partly => format!(
            "those whose plane meets M only where F touches 0 stay undecided whatever the \
             budget (see the note); a larger {knob} decides the others"
        ),
        Touching::Nowhere if continuous => format!("a larger {knob} decides more"),
        Touching::Nowhere => format!(
            "F may have a pole in the domain (a division, a negative power...), and a pixel \
             whose plane crosses one stays undecided whatever the budget unless a root is \
             proved elsewhere on the plane; a larger {knob} decides the others"
        ),
    }
}

/// How each note on where F only touches 0 opens (what the fuzzer looks for).
pub const TOUCHING_OPENING: &str = "F does not change sign";

/// What a user is told where F does not change sign on any box of the tree
/// (`TreeStats::one_signed`): the rays and the certified search look for sign changes.
pub const TOUCHING_NOTE: &str = "F does not change sign where it may be 0 (F ≥ 0 on every \
    box of the tree, or F ≤ 0 on every one): M is where F touches 0, which the search for \
    sign changes can neither find nor prove, so what shows of it is chance; write F so that \
    it changes sign across M (x^2 + y^2 + z^2 + w^2 - 1, not its square; y, not |y|)";

/// The note on where F only touches 0, if it does anywhere: [`TOUCHING_NOTE`], or, for a
/// formula that changes sign across one part of M and only touches 0 on another (`x·y²`
/// along y = 0), the same with the share of the tree's boxes where it touches.
pub fn touching_note(stats: &TreeStats) -> Option<String> {
    match stats.touching() {
        Touching::Nowhere => None,
        Touching::Everywhere => Some(TOUCHING_NOTE.to_string()),
        Touching::Partly => Some(format!(
            "{TOUCHING_OPENING} across part of M, where it only touches 0 ({:.0}% of the \
             tree's boxes): the search for sign changes can neither find nor prove that \
             part, so what shows of it is chance; write F so that it changes sign across \
             each part of M (x·y, not x·y^2; a factor z, not z^2)",
            100.0 * stats.touching_share
        )),
    }
}

/// The marks a frame leaves in its alpha channel, made opaque: the pixels whose work the
/// GPU driver cut short (odd 255 − alpha), and each pixel's verdict ((255 − alpha) / 2; a
/// cut pixel that claims empty is undecided: its search may have stopped early).
pub fn take_marks(rgba: &mut [u8]) -> (Vec<usize>, Vec<Verdict>) {
    let mut cut = Vec::new();
    let mut verdicts = Vec::with_capacity(rgba.len() / 4);
    for (i, p) in rgba.chunks_mut(4).enumerate() {
        let code = 255 - p[3];
        let was_cut = code & 1 == 1;
        if was_cut {
            cut.push(i);
        }
        verdicts.push(match code >> 1 {
            0 if !was_cut => Verdict::Empty,
            1 => Verdict::Hit,
            _ => Verdict::Undecided,
        });
        p[3] = 255;
    }
    (cut, verdicts)
}
