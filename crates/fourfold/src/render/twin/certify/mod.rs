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

use crate::eval::{BallLanes, BatchEvaluator, Box4, Interval, IntervalEvaluator, LANES};
use crate::formula::CompiledFormula;
use crate::render::verdict::Verdict;
use crate::render::view::{FLAG_CONTINUOUS, FLAG_SLICE, Uniforms};

mod plane;
mod sampled;

use super::forms::{bowl_above_zero, half_second_order};
use super::shading::V4;
use plane::{dot, inside, within};
use sampled::SampledSigns;

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

/// A box the search covers, [lo, hi], with bounds on F's second derivatives along the
/// plane over it ([`crate::tree::Curvature::in_plane`]: along s·n1 + t·n2, d²F within
/// s²·A + st·B + t²·C, as A, B, C's lower and upper bounds; ±∞ where unbounded).
#[derive(Debug, Clone, Copy)]
pub struct SearchBox {
    pub lo: [f32; 4],
    pub hi: [f32; 4],
    pub form: [f32; 6],
}

impl SearchBox {
    /// The form in f64 where all its bounds are finite and below the shader's IV_LARGE (as
    /// the shader's `form_bounded`).
    fn bounded_form(&self) -> Option<[f64; 6]> {
        let bounded = self.form.iter().all(|v| v.abs() < IV_LARGE);
        bounded.then(|| self.form.map(f64::from))
    }
}

/// The CPU's certifier for one frame (one per thread).
pub struct Certifier<'a> {
    formula: &'a CompiledFormula,
    params: &'a [f64],
    u: &'a Uniforms,
    eval: IntervalEvaluator,
    /// F's proved signs at the ends of a tile's brackets, [`LANES`] at a time.
    batch: BatchEvaluator,
    /// F's signs at brackets' ends from the march's samples there, where F's f32 error has
    /// a bound (see `sampled`), and by balls, where F's tape takes them (see [`BallLanes`]).
    sampled: Option<SampledSigns>,
    balls: Option<BallLanes>,
    /// The points of those ends that lie in the domain (their boxes, and where each goes).
    pending: Vec<(Box4, usize)>,
}

/// A pixel's ray's sign change (see [`Certifier::pixel`]): its plane's origin, and the sign
/// change, if a ray found one.
pub type Bracket = ([f32; 4], Option<SignChange>);

/// Two points (s, t) of a pixel's plane F was found on either side of 0 at, and where a
/// march sampled them, each one's point as the march had it in f32 and F's f32 value there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SignChange {
    pub ends: [[f64; 2]; 2],
    pub samples: Option<[(V4, f32); 2]>,
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
            batch: BatchEvaluator::new(),
            sampled: SampledSigns::new(formula, params, u),
            balls: BallLanes::takes(&formula.tape_f).then(BallLanes::new),
            pending: Vec::new(),
        }
    }

    /// F's proved signs (1, −1; 0: none) at the two ends of each of `brackets`, into `out`
    /// in their order: None where a pixel has no bracket or F may not be continuous
    /// between its ends (then it proves nothing). The ends' boxes are those [`Self::pixel`]
    /// would take one by one: from the march's samples where they are far enough from 0
    /// (see `sampled`), else [`LANES`] at a time, by balls where F's tape takes them, by
    /// intervals (bit for bit those one by one) where balls prove nothing.
    pub fn bracket_signs(
        &mut self,
        brackets: impl IntoIterator<Item = Bracket>,
        out: &mut Vec<Option<[i8; 2]>>,
    ) {
        out.clear();
        self.pending.clear();
        let domain = self.domain();
        for (k, (o, bracket)) in brackets.into_iter().enumerate() {
            let tried = bracket.filter(|c| self.continuous_between(o, c.ends[0], c.ends[1]));
            let Some(change) = tried else {
                out.push(None);
                continue;
            };
            let mut signs = [0; 2];
            let sampled = self.sampled.as_ref().zip(change.samples);
            for (end, p) in change.ends.into_iter().enumerate() {
                signs[end] = sampled.map_or(0, |(s, samples)| s.sign((o, p), samples[end]));
                if signs[end] != 0 {
                    continue;
                }
                let x = self.point_box(o, p);
                if inside(&x, &domain) {
                    self.pending.push((x, 2 * k + end));
                }
            }
            out.push(Some(signs));
        }
        let tape = &self.formula.tape_f;
        let mut boxes = [[Interval::EMPTY; 4]; LANES];
        for chunk in self.pending.chunks(LANES) {
            let n = chunk.len();
            for (b, &(x, _)) in boxes.iter_mut().zip(chunk) {
                *b = x;
            }
            let mut proved = [0i8; LANES];
            if let Some(balls) = &mut self.balls {
                balls.signs(tape, &boxes[..n], self.params, &mut proved);
            }
            // (Intervals for all sixteen where balls left any: a batch's cost.)
            if proved[..n].contains(&0) {
                self.batch.eval(tape, &boxes[..n], self.params);
                for (lane, sign) in proved[..n].iter_mut().enumerate() {
                    if *sign == 0 {
                        *sign = proved_sign(self.batch.output(tape, 0, lane));
                    }
                }
            }
            for (&sign, &(_, at)) in proved.iter().zip(chunk) {
                if let Some(signs) = &mut out[at / 2] {
                    signs[at % 2] = sign;
                }
            }
        }
    }

    /// Certifies the pixel whose plane has origin `o` (its observer plane's point on the
    /// (v1, v2) plane through the domain's centre), within the boxes `boxes` gives (boxes
    /// that together hold every point of M in the domain that the plane may meet).
    /// A ray's sign change, `bracket`'s two points (s, t), is tried first, with F's signs
    /// there as [`Self::bracket_signs`] proved them (`signs`): where they prove a hit, the
    /// boxes are not asked for (a pixel's walk of its hierarchy is not free).
    pub fn pixel<'b>(
        &mut self,
        (o, bracket): Bracket,
        signs: Option<[i8; 2]>,
        boxes: impl FnOnce() -> &'b [SearchBox],
    ) -> Outcome {
        let mut search = Search {
            budget: self.u.march.cert_budget,
            undecided: false,
            pos: None,
            neg: None,
        };
        if let (Some(change), Some(signs)) = (bracket, signs) {
            search.note(signs[0], change.ends[0]);
            search.note(signs[1], change.ends[1]);
        }
        if let Some(bracket) = search.hit() {
            return Outcome {
                verdict: Verdict::Hit,
                bracket: Some(bracket),
            };
        }
        let boxes = boxes();
        // As the shader: two passes, each box first held to an eighth of the budget, then
        // what stays undecided searched again, whole (brute force's one box whole at once).
        let (budget, brute_force) = (self.u.march.cert_budget, self.u.brute_force());
        for round in 0..2 {
            let done = search.hit().is_some() || !search.undecided || search.budget == 0;
            if round == 1 && (brute_force || done) {
                break;
            }
            search.undecided = false;
            let cap = if round == 0 && !brute_force {
                (budget / 8).max(1)
            } else {
                search.budget
            };
            for b in boxes {
                if (search.budget == 0 && search.undecided) || search.hit().is_some() {
                    break;
                }
                self.certify_box(&mut search, o, b, cap);
            }
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

    /// Whether F is continuous on the plane's segment from a to b (a ray's two samples): on
    /// the whole domain, or else on the box around the segment, within the domain, as its
    /// enclosure says (the shader's `bracket_continuous`).
    fn continuous_between(&mut self, o: [f32; 4], a: [f64; 2], b: [f64; 2]) -> bool {
        if self.u.control.flags & FLAG_CONTINUOUS != 0 {
            return true;
        }
        let span = |i: usize| Interval::new(a[i].min(b[i]), a[i].max(b[i]));
        let x = self.plane_box(o, span(0), span(1));
        if !inside(&x, &self.domain()) {
            return false;
        }
        let tape = &self.formula.tape_f;
        let f = self.eval.eval(tape, &x, self.params);
        !f.is_empty() && self.eval.continuous_on_last_box(tape)
    }

    /// Certifies the part of the plane within the box [lo, hi] and the domain, spending at
    /// most `cap` cells of the budget (the shader's `certify_box`).
    fn certify_box(&mut self, search: &mut Search, o: [f32; 4], b: &SearchBox, cap: u32) {
        let u = self.u;
        // (A box the slice's line misses costs no cell; only this test, not the search's
        // set-up, which would find nothing there either.)
        if u.control.flags & FLAG_SLICE != 0 && search.budget > 0 && self.line_misses(o, b) {
            return;
        }
        let floor = search.budget.saturating_sub(cap);
        let domain = self.domain();
        let Some((bx, rel, (s, t))) = self.plane_cell(o, b.lo, b.hi) else {
            return;
        };
        let form = b.bounded_form();
        // As the shader: cells are cut down to where the plane may meet the box.
        let reach = s.magnitude().max(t.magnitude());
        let global = u.control.flags & FLAG_CONTINUOUS != 0;
        let mut stack: Vec<Cell> = Vec::with_capacity(CERT_STACK);
        stack.push((s, t));
        let mut first_cell = true;
        while let Some(cell) = stack.pop() {
            let Some((cs, ct)) = self.shrink_cell(cell, &rel, reach) else {
                continue;
            };
            if search.hit().is_some() {
                return;
            }
            if search.budget == floor {
                search.undecided = true;
                return;
            }
            let Some(x) = within(self.plane_box(o, cs, ct), &bx) else {
                continue;
            };
            search.budget -= 1;
            // A box's first cell, F alone first: where the plane passes by M, it excludes
            // most, at a fraction of F and ∇F's tape (the same enclosure of F, operation for
            // operation); the cells split from it lie nearer M, where it seldom does.
            let first = std::mem::replace(&mut first_cell, false);
            if first
                && !self
                    .eval
                    .eval(&self.formula.tape_f, &x, self.params)
                    .contains_zero()
            {
                continue;
            }
            let mut fg = [Interval::EMPTY; 5];
            let tape = &self.formula.tape_all;
            self.eval.eval_into(tape, &x, self.params, &mut fg);
            let smooth = self.eval.continuous_on_last_box(tape);
            if !fg[0].contains_zero() {
                continue;
            }
            let mid = [cs.midpoint(), ct.midpoint()];
            // F's slope along n1 and n2 over the cell, estimated (where bounded), and the
            // most it may be (where unknown, the longer side is split).
            let mut slope = [0.0; 2];
            let mut smear = [1.0; 2];
            // As the shader: the point c0 the forms expand about (in the box where it can be
            // found); where it lies in the box, F's value there and the mean-value form over
            // the cell.
            let c0 = self.cell_point(o, (cs, ct), mid, &bx);
            let cp = self.point_box(o, c0);
            let ds = cs.sub(Interval::point(c0[0]));
            let dt = ct.sub(Interval::point(c0[1]));
            let half_quad = form.map(|form| half_second_order(form, ds, dt));
            // Where Taylor's form may prove the cell: F at c0, half its second-order term and
            // the box's form.
            let mut taylor = None;
            if inside(&cp, &bx) {
                let fc = self.eval.eval(&self.formula.tape_f, &cp, self.params);
                if smooth {
                    let (g1, g2) = (dot(&fg[1..], u.n1), dot(&fg[1..], u.n2));
                    let mv = fc.add(g1.mul(ds).add(g2.mul(dt)));
                    if !meet(fg[0], mv).contains_zero() {
                        continue;
                    }
                    taylor = half_quad
                        .zip(form)
                        .filter(|&(h, _)| !fc.is_empty() && !fc.add(h).contains_zero())
                        .map(|(h, form)| (fc, h, form));
                    slope =
                        [g1.midpoint(), g2.midpoint()].map(|g| if g.is_finite() { g } else { 0.0 });
                    let most = [g1.magnitude(), g2.magnitude()];
                    if most.iter().all(|&m| m < f64::from(IV_LARGE)) && most[0] + most[1] > 0.0 {
                        smear = most;
                    }
                }
                if global && inside(&cp, &domain) {
                    search.note(proved_sign(fc), c0);
                    if let Some(p) = search.guess(fc, c0, slope, (cs, ct)) {
                        let sign = self.sign_at(o, p, &bx);
                        search.note(sign, p);
                    }
                }
            }
            if !global && smooth {
                // F is continuous on this cell's box only: its own samples must differ.
                let mut local = Search::default();
                for p in [c0, [cs.lo(), ct.lo()], [cs.hi(), ct.hi()]] {
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
            if let Some((fc, half_quad, form)) = taylor
                && self.taylor_excludes_zero(&cp, fc, half_quad, (ds, dt), form)
            {
                continue;
            }
            if !split((cs, ct), mid, (slope, smear), search.wanted(), &mut stack) {
                search.undecided = true;
            }
        }
    }

    /// Whether Taylor's form of second order, F(c0) + ∇F(c0)·d + half_quad (the shader's),
    /// excludes 0 over the cell's offsets (ds, dt) from c0 (its box `cp`, where F encloses
    /// to `fc`), or the bowl (or cap) the box's `form` bounds stays clear of 0 everywhere.
    fn taylor_excludes_zero(
        &mut self,
        cp: &Box4,
        fc: Interval,
        half_quad: Interval,
        (ds, dt): (Interval, Interval),
        form: [f64; 6],
    ) -> bool {
        let mut fgc = [Interval::EMPTY; 5];
        self.eval
            .eval_into(&self.formula.tape_all, cp, self.params, &mut fgc);
        let (c1, c2) = (dot(&fgc[1..], self.u.n1), dot(&fgc[1..], self.u.n2));
        let [al, ah, bl, bh, cl, ch] = form;
        let b = Interval::new(bl, bh);
        !fc.add(c1.mul(ds))
            .add(c2.mul(dt))
            .add(half_quad)
            .contains_zero()
            || bowl_above_zero(fc, c1, c2, al, b, cl)
            || bowl_above_zero(fc.neg(), c1.neg(), c2.neg(), -ah, b.neg(), -ch)
    }

    /// F's proved sign at the plane's point p (0: not proved, or p may lie outside `within`).
    fn sign_at(&mut self, o: [f32; 4], p: [f64; 2], within: &Box4) -> i8 {
        let x = self.point_box(o, p);
        if !inside(&x, within) {
            return 0;
        }
        proved_sign(self.eval.eval(&self.formula.tape_f, &x, self.params))
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

    /// The sign still missing: 1, −1, or 0 (both, or neither, missing).
    fn wanted(&self) -> i8 {
        match (self.pos, self.neg) {
            (None, Some(_)) => 1,
            (Some(_), None) => -1,
            _ => 0,
        }
    }

    /// Where in the cell (s, t ranges) F more likely has the sign still missing (or, with
    /// neither found, the sign opposite to F's at the centre): from the centre, with F's
    /// value `fc` there and its estimated slope, twice the Newton step of the linear
    /// model towards 0, kept within the cell.
    fn guess(
        &self,
        fc: Interval,
        mid: [f64; 2],
        slope: [f64; 2],
        (s, t): Cell,
    ) -> Option<[f64; 2]> {
        let f = fc.midpoint();
        let want = match self.wanted() {
            0 if self.pos.is_none() && self.neg.is_none() => -f.signum(),
            w => f64::from(w),
        };
        let norm = slope[0] * slope[0] + slope[1] * slope[1];
        if want * f >= 0.0 || !(norm > 0.0 && norm.is_finite() && f.is_finite()) {
            return None;
        }
        let step = -2.0 * f / norm;
        let p = [
            (mid[0] + step * slope[0]).clamp(s.lo(), s.hi()),
            (mid[1] + step * slope[1]).clamp(t.lo(), t.hi()),
        ];
        Some(p)
    }
}

/// Splits the cell across the side along which F may change the most (`smear`, the most
/// |F|'s slope along n1 and n2 may be, times the side's length), or the other where f32
/// cannot split that one (a slice's cells are segments along n1), onto `stack`: the half
/// where F more likely has the sign still missing (`wanted`, by the estimated `slope`)
/// searched first (pushed last); false where neither side splits or the stack is full
/// (that part stays undecided).
fn split(
    (cs, ct): Cell,
    mid: [f64; 2],
    (slope, smear): ([f64; 2], [f64; 2]),
    wanted: i8,
    stack: &mut Vec<Cell>,
) -> bool {
    let splits = |side: Interval, cut: f64| side.lo() < cut && cut < side.hi();
    let (split_s, split_t) = (splits(cs, mid[0]), splits(ct, mid[1]));
    let along_s = split_s && (!split_t || cs.width() * smear[0] >= ct.width() * smear[1]);
    let (side, cut) = if along_s { (cs, mid[0]) } else { (ct, mid[1]) };
    if !(split_s || split_t) || stack.len() + 2 > CERT_STACK {
        return false;
    }
    let (mut a, mut b) = (Interval::new(side.lo(), cut), Interval::new(cut, side.hi()));
    let g = if along_s { slope[0] } else { slope[1] };
    if f64::from(wanted) * g < 0.0 {
        (a, b) = (b, a);
    }
    if along_s {
        stack.push((a, ct));
        stack.push((b, ct));
    } else {
        stack.push((cs, a));
        stack.push((cs, b));
    }
    true
}

/// The largest finite bound the shader's intervals keep (its IV_LARGE, 2^61).
const IV_LARGE: f32 = 2_305_843_009_213_693_952.0;

/// The sign an enclosure of F proves: 1, −1, or 0 (none).
fn proved_sign(f: Interval) -> i8 {
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

/// The values both enclosures hold.
fn meet(a: Interval, b: Interval) -> Interval {
    a.intersect(b.lo(), b.hi())
}

#[cfg(test)]
mod tests {
    use super::*;
    use bytemuck::Zeroable;
    use proptest::prelude::*;

    proptest! {
        /// A point's box is the plane's box of that point, bit for bit, however the plane is
        /// turned and however far the point lies (f64 overflow included).
        #[test]
        fn a_point_s_box_is_the_plane_box_of_the_point(
            o in prop::array::uniform4(prop_oneof![Just(0.0f32), -3.0f32..3.0]),
            n1 in prop::array::uniform4(prop_oneof![Just(0.0f32), Just(1.0), -1.0f32..1.0]),
            n2 in prop::array::uniform4(prop_oneof![Just(0.0f32), Just(-1.0), -1.0f32..1.0]),
            p in prop::array::uniform2(prop::num::f64::NORMAL | prop::num::f64::ZERO),
        ) {
            let formula = CompiledFormula::compile("x").unwrap();
            let mut u = Uniforms::zeroed();
            (u.n1, u.n2) = (n1, n2);
            let certifier = Certifier::new(&formula, &[], &u);
            let bits = |b: Box4| b.map(|x| [x.lo().to_bits(), x.hi().to_bits()]);
            let plane = certifier.plane_box(o, Interval::point(p[0]), Interval::point(p[1]));
            prop_assert_eq!(bits(certifier.point_box(o, p)), bits(plane));
        }
    }

    /// The side split is the one along which F may change the most (its length times the
    /// slope's bound), not the longer one; with no bound, the longer; where f32 cannot halve
    /// the chosen side, the other.
    #[test]
    fn cells_split_where_f_changes_the_most() {
        let split_of = |cell: Cell, smear: [f64; 2]| {
            let mut stack = Vec::new();
            let mid = [cell.0.midpoint(), cell.1.midpoint()];
            assert!(split(cell, mid, ([0.0; 2], smear), 0, &mut stack));
            stack
        };
        let wide_t = (Interval::new(0.0, 1.0), Interval::new(0.0, 2.0));
        // F changes 100 along s and 1 along t (the chapter's graph seen with n2 = w).
        let halves = split_of(wide_t, [100.0, 1.0]);
        assert_eq!(halves.len(), 2);
        assert!(
            halves
                .iter()
                .all(|&(s, t)| s.width() == 0.5 && t == wide_t.1)
        );
        // Unknown slopes: the longer side.
        let halves = split_of(wide_t, [1.0, 1.0]);
        assert!(
            halves
                .iter()
                .all(|&(s, t)| s == wide_t.0 && t.width() == 1.0)
        );
        // s too narrow for f32 to halve: t, whatever the slopes.
        let thin_s = (
            Interval::new(1.0, 1.0 + f64::EPSILON),
            Interval::new(0.0, 2.0),
        );
        let halves = split_of(thin_s, [100.0, 1.0]);
        assert!(
            halves
                .iter()
                .all(|&(s, t)| s == thin_s.0 && t.width() == 1.0)
        );
    }
}
