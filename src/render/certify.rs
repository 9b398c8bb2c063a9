//! Certified pixels (docs/method.md §5.9): each pixel's verdict, and the CPU twin of the
//! shader's `certify`, in f64 with the rigorous interval evaluator.
//!
//! A pixel's observer plane is the set of points o + s·n1 + t·n2 (its origin and the
//! observer directions as the frame's f32 values, taken as exact reals). Within each of the
//! pixel's boxes, cells (ranges of s and t) are enclosed: F□ over a cell's box without 0
//! proves it holds no root; otherwise its centre's sign is proved if it can be, and the cell
//! is split in two, depth first. Two points of opposite proved sign, joined by a segment on
//! which F is continuous, prove a root: the pixel is a hit. Every cell excluded: empty.
//! Otherwise undecided.

use crate::eval::{Box4, Interval, IntervalEvaluator};
use crate::formula::CompiledFormula;

use super::uniforms::{FLAG_CONTINUOUS, FLAG_SLAB, FLAG_SLICE, Uniforms};

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

/// Cells a pixel may have waiting (the shader's CERT_STACK); a cell that would go deeper
/// stays undecided.
pub const CERT_STACK: usize = 24;

/// The outcome for one pixel: its verdict and, for a hit, two points (s, t) of its plane
/// with F > 0 at the first and F < 0 at the second, F continuous on the segment between.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    pub verdict: Verdict,
    pub bracket: Option<([f64; 2], [f64; 2])>,
}

/// The CPU's certifier for one frame (one per thread).
pub struct Certifier<'a> {
    formula: &'a CompiledFormula,
    params: &'a [f64],
    u: &'a Uniforms,
    eval: IntervalEvaluator,
}

/// A cell: ranges of s and t.
type Cell = (Interval, Interval);

impl<'a> Certifier<'a> {
    pub fn new(formula: &'a CompiledFormula, params: &'a [f64], u: &'a Uniforms) -> Self {
        Self {
            formula,
            params,
            u,
            eval: IntervalEvaluator::new(),
        }
    }

    /// Certifies the pixel whose plane has origin `o` (its observer plane's point on the
    /// (v1, v2) plane through the domain's centre), within `boxes` ([lo, hi] each: boxes
    /// that together hold every point of M in the domain that the plane may meet).
    pub fn pixel(&mut self, o: [f32; 4], boxes: &[([f32; 4], [f32; 4])]) -> Outcome {
        let mut search = Search {
            budget: self.u.march.cert_budget,
            undecided: false,
            pos: None,
            neg: None,
        };
        for &(lo, hi) in boxes {
            if search.budget == 0 || search.hit().is_some() {
                break;
            }
            self.certify_box(&mut search, o, lo, hi);
        }
        if let Some(bracket) = search.hit() {
            return Outcome {
                verdict: Verdict::Hit,
                bracket: Some(bracket),
            };
        }
        Outcome {
            verdict: if search.undecided {
                Verdict::Undecided
            } else {
                Verdict::Empty
            },
            bracket: None,
        }
    }

    fn certify_box(&mut self, search: &mut Search, o: [f32; 4], lo: [f32; 4], hi: [f32; 4]) {
        let u = self.u;
        let bx: Box4 = std::array::from_fn(|i| Interval::new(f64::from(lo[i]), f64::from(hi[i])));
        let range = |n: [f32; 4]| {
            (0..4).fold(Interval::ZERO, |acc, i| {
                let rel = bx[i].sub(Interval::point(f64::from(o[i])));
                acc.add(rel.mul(Interval::point(f64::from(n[i]))))
            })
        };
        let (s, t) = (range(u.n1), range(u.n2));
        // n1 and n2 are orthonormal only to f32's rounding (as the shader, generously).
        let m = 1e-5 * (magnitude(s) + magnitude(t)) + 1e-30;
        let widen = |a: Interval| a.add(Interval::new(-m, m));
        let (s, mut t) = (widen(s), widen(t));
        let (offset, half) = (
            f64::from(u.root.section_offset),
            f64::from(u.root.section_half),
        );
        if u.control.flags & FLAG_SLICE != 0 {
            if !t.contains(offset) {
                return;
            }
            t = Interval::point(offset);
        } else if u.control.flags & FLAG_SLAB != 0 {
            t = t.intersect(offset - half, offset + half);
            if t.is_empty() {
                return;
            }
        }
        let global = u.control.flags & FLAG_CONTINUOUS != 0;
        let domain: Box4 = std::array::from_fn(|i| {
            Interval::new(f64::from(u.domain_lo[i]), f64::from(u.domain_hi[i]))
        });
        let mut stack: Vec<Cell> = Vec::with_capacity(CERT_STACK);
        stack.push((s, t));
        while let Some((cs, ct)) = stack.pop() {
            if search.hit().is_some() {
                return;
            }
            if search.budget == 0 {
                search.undecided = true;
                return;
            }
            let Some(x) = within(self.plane_box(o, cs, ct), &bx) else {
                continue;
            };
            search.budget -= 1;
            let f = self.eval.eval(&self.formula.tape_f, &x, self.params);
            if !f.contains_zero() {
                continue;
            }
            let mid = [cs.midpoint(), ct.midpoint()];
            if global {
                let sign = self.sign_at(o, mid, &domain);
                search.note(sign, mid);
            } else if self.eval.continuous_on_last_box(&self.formula.tape_f) {
                // F is continuous on this cell's box only: its own samples must differ.
                let mut local = Search::default();
                for p in [mid, [cs.lo(), ct.lo()], [cs.hi(), ct.hi()]] {
                    let sign = self.sign_at(o, p, &x);
                    local.note(sign, p);
                }
                if local.hit().is_some() {
                    (search.pos, search.neg) = (local.pos, local.neg);
                }
            }
            if search.hit().is_some() {
                return;
            }
            // Split the longer side (a slice's cells are segments along n1).
            let along_s = cs.width() >= ct.width();
            let (side, cut) = if along_s { (cs, mid[0]) } else { (ct, mid[1]) };
            if !(side.lo() < cut && cut < side.hi()) || stack.len() + 2 > CERT_STACK {
                search.undecided = true;
                continue;
            }
            let (a, b) = (
                Interval::new(side.lo(), cut),
                Interval::new(cut, side.hi()),
            );
            if along_s {
                stack.push((a, ct));
                stack.push((b, ct));
            } else {
                stack.push((cs, a));
                stack.push((cs, b));
            }
        }
    }

    /// The box around the plane's points o + s·n1 + t·n2, s in `s`, t in `t`.
    fn plane_box(&self, o: [f32; 4], s: Interval, t: Interval) -> Box4 {
        let (n1, n2) = (self.u.n1, self.u.n2);
        std::array::from_fn(|i| {
            Interval::point(f64::from(o[i]))
                .add(s.mul(Interval::point(f64::from(n1[i]))))
                .add(t.mul(Interval::point(f64::from(n2[i]))))
        })
    }

    /// F's proved sign at the plane's point p (0: not proved, or p may lie outside `inside`).
    fn sign_at(&mut self, o: [f32; 4], p: [f64; 2], inside: &Box4) -> i8 {
        let x = self.plane_box(o, Interval::point(p[0]), Interval::point(p[1]));
        if (0..4).any(|i| x[i].lo() < inside[i].lo() || x[i].hi() > inside[i].hi()) {
            return 0;
        }
        let f = self.eval.eval(&self.formula.tape_f, &x, self.params);
        if f.is_empty() {
            0
        } else if f.lo() > 0.0 {
            1
        } else if f.hi() < 0.0 {
            -1
        } else {
            0
        }
    }
}

/// The search of one pixel: cells left to spend, whether any part stayed undecided, and
/// the first points of each proved sign.
#[derive(Debug, Default)]
struct Search {
    budget: u32,
    undecided: bool,
    pos: Option<[f64; 2]>,
    neg: Option<[f64; 2]>,
}

impl Search {
    fn note(&mut self, sign: i8, p: [f64; 2]) {
        if sign > 0 && self.pos.is_none() {
            self.pos = Some(p);
        }
        if sign < 0 && self.neg.is_none() {
            self.neg = Some(p);
        }
    }

    fn hit(&self) -> Option<([f64; 2], [f64; 2])> {
        self.pos.zip(self.neg)
    }
}

fn magnitude(a: Interval) -> f64 {
    a.lo().abs().max(a.hi().abs())
}

/// The part of box `x` within box `b`, if any.
fn within(x: Box4, b: &Box4) -> Option<Box4> {
    let mut out = x;
    for i in 0..4 {
        out[i] = x[i].intersect(b[i].lo(), b[i].hi());
        if out[i].is_empty() {
            return None;
        }
    }
    Some(out)
}
