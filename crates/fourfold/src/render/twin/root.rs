//! A root of F on a ray's segment where F changes sign (docs/method.md §5.3): Algorithm 3.1's
//! bisection, with the secant's zero in place of the midpoint wherever that keeps the
//! bracket near bisection's. The twin's own: the shader bisects (its `bisect`), as a SIMD
//! group's lanes wait for the slowest one's root: with these steps lavapipe's plain frame
//! of fig. 3.9 was 9% later, where the CPU's slices are 6–36% sooner (docs/benchmarks.md).
//! Both stop at the same |F|, so their hits agree to the tolerance.

/// How far a root's bracket may lag behind bisection's: after k steps from a width W it is
/// at most 2·FALSI_SLACK·W/2^k wide, 8 times what k bisections leave. With 1 or 2 the peer
/// bench's slices took 2–90% more evaluations a root, with 16 at most 2% fewer.
const FALSI_SLACK: f32 = 4.0;

/// How near (in units of f32's rounding of t) the secant must put the root to the point
/// just tried for one probe to settle it (see [`near_root`]).
const NEAR_ENOUGH: f32 = 2.0;

/// The root of `f` in [lo, hi], where it changes sign from `f_lo` to `f_hi`: at most
/// `iters` steps, stopping once |f| < `approximation` or once f32 cannot split the bracket;
/// the last point tried (the bracket's middle with no steps). Each step is `falsi_step`'s,
/// and an end kept by two steps in a row has its value scaled down by `kept_scale` (the
/// Anderson–Björck rule: so both ends move). f(lo) stays on its side of 0, so its sign is
/// not carried.
///
/// Where F's rounding in f32 is above `approximation` (the chapter's torus graph: |F| at
/// 2^-16 near its roots, against 10^-6), the steps reach that floor in two or three and
/// then crawl: the secant's zero rounds onto the end just found, and the bracket halves
/// from the other side until f32 cannot split it (up to 20 evaluations). So once, where
/// the secant puts the root within [`NEAR_ENOUGH`] units of rounding of the point just
/// tried, one more evaluation a little beyond it (an evaluation more than `iters` steps'
/// at most) most often leaves a bracket of a few units ([`near_root`]).
pub(super) fn refine(
    mut f: impl FnMut(f32) -> f32,
    bracket: (f32, f32),
    ends: (f32, f32),
    iters: u32,
    approximation: f32,
) -> f32 {
    let mut steps = Steps::new(bracket, ends, approximation);
    for _ in 0..iters {
        let Some(tm) = steps.step() else {
            break;
        };
        match steps.at_step(f(tm)) {
            After::Found => break,
            After::Probe(p) => {
                if steps.at_probe(p, f(p)) {
                    break;
                }
            }
            After::Step => {}
        }
    }
    steps.tm
}

/// [`refine`]'s bracket and the state of its steps.
#[derive(Debug, Clone, Copy)]
struct Steps {
    lo: f32,
    hi: f32,
    f_lo: f32,
    f_hi: f32,
    /// F at the ends as evaluated (f_lo and f_hi may be scaled).
    v_lo: f32,
    v_hi: f32,
    neg_lo: bool,
    /// The last point tried: the root once the steps end.
    tm: f32,
    cap: f32,
    /// Which end the last step moved.
    moved_lo: Option<bool>,
    /// Whether the probe was taken.
    probed: bool,
    approximation: f32,
}

/// What follows a step's value (see [`Steps::at_step`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum After {
    Found,
    Probe(f32),
    Step,
}

impl Steps {
    fn new((lo, hi): (f32, f32), (f_lo, f_hi): (f32, f32), approximation: f32) -> Self {
        Self {
            lo,
            hi,
            f_lo,
            f_hi,
            v_lo: f_lo,
            v_hi: f_hi,
            neg_lo: f_lo < 0.0,
            tm: 0.5 * (lo + hi),
            cap: FALSI_SLACK * (hi - lo),
            moved_lo: None,
            probed: false,
            approximation,
        }
    }

    /// The next step's point (`falsi_step`'s); None where f32 cannot split the bracket.
    #[inline(always)]
    fn step(&mut self) -> Option<f32> {
        self.tm = falsi_step((self.lo, self.hi), (self.f_lo, self.f_hi), self.cap);
        self.cap *= 0.5;
        (self.tm != self.lo && self.tm != self.hi).then_some(self.tm)
    }

    /// Takes f's value `fm` at the step's point: the root found (|fm| below the
    /// approximation), or the bracket narrowed, and then a probe to take (see
    /// [`near_root`]) or the next step.
    #[inline(always)]
    fn at_step(&mut self, fm: f32) -> After {
        let tm = self.tm;
        if fm.abs() < self.approximation {
            return After::Found;
        }
        let to_lo = (fm < 0.0) == self.neg_lo;
        if to_lo {
            if self.moved_lo == Some(true) {
                self.f_hi *= kept_scale(fm, self.f_lo);
            }
            (self.lo, self.f_lo, self.v_lo) = (tm, fm, fm);
        } else {
            if self.moved_lo == Some(false) {
                self.f_lo *= kept_scale(fm, self.f_hi);
            }
            (self.hi, self.f_hi, self.v_hi) = (tm, fm, fm);
        }
        self.moved_lo = Some(to_lo);
        let other = if to_lo {
            (self.hi, self.v_hi)
        } else {
            (self.lo, self.v_lo)
        };
        match near_root((tm, fm), other).filter(|_| !self.probed) {
            Some(p) => {
                self.probed = true;
                After::Probe(p)
            }
            None => After::Step,
        }
    }

    /// Takes f's value `fp` at the probe `p`: whether it is the root (|fp| below the
    /// approximation); else p is the end on its side, and with a sign change the bracket is
    /// now (tm, p), a few units of rounding wide.
    #[inline(always)]
    fn at_probe(&mut self, p: f32, fp: f32) -> bool {
        self.tm = p;
        if fp.abs() < self.approximation {
            return true;
        }
        let p_lo = (fp < 0.0) == self.neg_lo;
        if p_lo {
            (self.lo, self.f_lo, self.v_lo) = (p, fp, fp);
        } else {
            (self.hi, self.f_hi, self.v_hi) = (p, fp, fp);
        }
        self.moved_lo = Some(p_lo);
        false
    }
}

/// [`refine`]'s steps, one evaluation of f at a time: [`Self::next`] says where f is wanted
/// (None: the root is found), [`Self::take`] takes its value there. So the roots of many
/// rays can be sought together, their evaluations made side by side.
#[derive(Debug, Clone, Copy)]
pub(super) struct RootSearch {
    steps: Steps,
    steps_left: u32,
    state: Seeking,
}

/// Where a [`RootSearch`] is: about to step, waiting for f at its step's point or at its
/// probe, or done.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Seeking {
    Step,
    AtStep,
    AtProbe(f32),
    Found,
}

impl RootSearch {
    pub(super) fn new(
        bracket: (f32, f32),
        ends: (f32, f32),
        iters: u32,
        approximation: f32,
    ) -> Self {
        Self {
            steps: Steps::new(bracket, ends, approximation),
            steps_left: iters,
            state: Seeking::Step,
        }
    }

    /// Where f is wanted next; None once the root is found.
    pub(super) fn next(&mut self) -> Option<f32> {
        match self.state {
            Seeking::Step => {
                let point = (self.steps_left > 0).then(|| self.steps.step()).flatten();
                self.steps_left = self.steps_left.saturating_sub(1);
                self.state = if point.is_some() {
                    Seeking::AtStep
                } else {
                    Seeking::Found
                };
                point
            }
            Seeking::AtStep => Some(self.steps.tm),
            Seeking::AtProbe(p) => Some(p),
            Seeking::Found => None,
        }
    }

    /// f's value at the point [`Self::next`] gave.
    pub(super) fn take(&mut self, value: f32) {
        self.state = match self.state {
            Seeking::AtStep => match self.steps.at_step(value) {
                After::Found => Seeking::Found,
                After::Probe(p) => Seeking::AtProbe(p),
                After::Step => Seeking::Step,
            },
            Seeking::AtProbe(p) if self.steps.at_probe(p, value) => Seeking::Found,
            Seeking::AtProbe(_) => Seeking::Step,
            state => {
                debug_assert!(false, "a value taken with none asked for");
                state
            }
        };
    }

    /// The root (once [`Self::next`] gives None).
    pub(super) fn root(&self) -> f32 {
        self.steps.tm
    }

    /// The root, the steps left taken with `f`.
    pub(super) fn finish(mut self, mut f: impl FnMut(f32) -> f32) -> f32 {
        while let Some(t) = self.next() {
            self.take(f(t));
        }
        self.root()
    }
}

/// Where the secant through the point just tried, (t, f), and the bracket's other end,
/// (t_o, f_o), as evaluated, puts the root within [`NEAR_ENOUGH`] units of f32's rounding
/// of t: the point twice as far from t towards t_o (at least the next float), if the
/// bracket holds one.
fn near_root((t, f): (f32, f32), (t_o, f_o): (f32, f32)) -> Option<f32> {
    let away = f.abs() * ((t_o - t) / (f_o - f)).abs();
    let unit = t.abs().max(t_o.abs()) * f32::EPSILON;
    if !(away <= NEAR_ENOUGH * unit) {
        return None;
    }
    let toward = (t_o - t).signum();
    let mut p = t + toward * (2.0 * away).max(unit);
    if p == t {
        p = if toward > 0.0 {
            t.next_up()
        } else {
            t.next_down()
        };
    }
    let between = (p - t) * toward > 0.0 && (t_o - p) * toward > 0.0;
    between.then_some(p)
}

/// How much the value at the end a step kept is scaled when the other end moved twice in a
/// row, from `f_old` to `f_new` (Anderson and Björck, 1973): 1 − f_new/f_old, or a half
/// where that is not positive (or not a number).
fn kept_scale(f_new: f32, f_old: f32) -> f32 {
    let m = 1.0 - f_new / f_old;
    if m > 0.0 { m } else { 0.5 }
}

/// One step in the bracket (lo, hi), with f's values at its ends: the secant's zero (regula
/// falsi), moved to within `cap` − width/2 of the midpoint (the projection of the ITP
/// method, Oliveira and Takahashi 2020; `cap` is halved at each step). The midpoint where
/// the secant's zero is not in the bracket (a value not finite) or the result is not
/// strictly inside.
fn falsi_step((lo, hi): (f32, f32), (f_lo, f_hi): (f32, f32), cap: f32) -> f32 {
    let mid = 0.5 * (lo + hi);
    let width = hi - lo;
    let secant = lo + width * (f_lo / (f_lo - f_hi));
    let falsi = if secant >= lo && secant <= hi {
        secant
    } else {
        mid
    };
    let reach = cap - 0.5 * width;
    let t = if (falsi - mid).abs() <= reach {
        falsi
    } else if falsi < mid {
        mid - reach
    } else {
        mid + reach
    };
    if t > lo && t < hi { t } else { mid }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// `refine` on `f` over [lo, hi], with its count of evaluations.
    fn counted(f: impl Fn(f32) -> f32, (lo, hi): (f32, f32), iters: u32, tol: f32) -> (f32, u32) {
        let mut n = 0;
        let t = refine(
            |t| {
                n += 1;
                f(t)
            },
            (lo, hi),
            (f(lo), f(hi)),
            iters,
            tol,
        );
        (t, n)
    }

    /// Bisection as Algorithm 3.1 (and fourfold before the secant steps) runs it.
    fn bisected(
        f: impl Fn(f32) -> f32,
        (mut lo, mut hi): (f32, f32),
        iters: u32,
        tol: f32,
    ) -> (f32, u32) {
        let (neg_lo, mut tm, mut n) = (f(lo) < 0.0, 0.5 * (lo + hi), 0);
        for _ in 0..iters {
            tm = 0.5 * (lo + hi);
            if tm == lo || tm == hi {
                break;
            }
            n += 1;
            let fm = f(tm);
            if fm.abs() < tol {
                break;
            }
            if (fm < 0.0) == neg_lo {
                lo = tm;
            } else {
                hi = tm;
            }
        }
        (tm, n)
    }

    /// A simple root of a smooth F (a sphere's, a sextic's, a quartic's, a cosine's along a
    /// ray) is found within the tolerance in a few evaluations, where bisection takes many.
    #[test]
    fn smooth_roots_take_few_evaluations() {
        let (mut ours, mut bisection, mut cases) = (0, 0, 0);
        for k in 0..=8 {
            let root = 0.4 + 0.05 * k as f32;
            let kinds: [&dyn Fn(f32) -> f32; 4] = [
                &|t| (t * t + 0.3) - (root * root + 0.3),
                &|t| t.powi(6) - root.powi(6),
                &|t| (t * t + 0.2).powi(2) - (root * root + 0.2).powi(2),
                &|t| (8.0 * (t - root)).sin() + 0.1 * (t - root),
            ];
            for f in kinds {
                for below in [0.001, 0.01, 0.05, 0.2] {
                    for above in [0.002, 0.02, 0.07, 0.15] {
                        let bracket = (root - below, root + above);
                        let (t, n) = counted(f, bracket, 24, 1e-6);
                        assert!(t > bracket.0 && t < bracket.1);
                        assert!(
                            f(t).abs() < 1e-6,
                            "root {root}, {bracket:?}: t {t}, F {}",
                            f(t)
                        );
                        ours += n;
                        bisection += bisected(f, bracket, 24, 1e-6).1;
                        cases += 1;
                    }
                }
            }
        }
        let (ours, bisection) = (ours as f32 / cases as f32, bisection as f32 / cases as f32);
        eprintln!("evaluations a root: {ours:.2}, bisection {bisection:.2}");
        assert!(
            ours < 4.5 && bisection > 10.0,
            "{ours} against bisection's {bisection}"
        );
    }

    /// Where F's rounding is above the tolerance (the torus graph's |F| at 2^-16 near its
    /// roots, against 10^-6), a root takes few evaluations more than a smooth one, not the
    /// crawl of the bracket down to f32's last bit, and lies as near as the rounding allows.
    #[test]
    fn roots_in_rounding_noise_do_not_crawl() {
        let noise = 2f32.powi(-16);
        let (mut evaluations, mut cases) = (0, 0);
        for k in 0..=8 {
            let root = 7.8 + 0.15 * k as f32;
            // 13 (t - root) + 3 (t - root)², give or take the rounding, never 0.
            let f = |t: f32| {
                let d = t - root;
                let wobble = if t.to_bits().count_ones().is_multiple_of(2) {
                    noise
                } else {
                    -noise
                };
                13.0 * d + 3.0 * d * d + wobble
            };
            for below in [0.001, 0.01, 0.05] {
                for above in [0.002, 0.02, 0.05] {
                    let bracket = (root - below, root + above);
                    let (t, n) = counted(f, bracket, 24, 1e-6);
                    let off = (t - root).abs();
                    assert!(
                        off < 2.0 * noise / 13.0 + 4.0 * root * f32::EPSILON,
                        "{root}: {t}"
                    );
                    evaluations += n;
                    cases += 1;
                }
            }
        }
        let mean = evaluations as f32 / cases as f32;
        eprintln!("evaluations a root in rounding noise: {mean:.2}");
        assert!(mean < 5.0, "{mean}");
    }

    proptest! {
        /// Where F jumps or kinks at c, the bracket narrows at least as bisection's does, but
        /// for the slack: after k steps the point is within 8·W/2^k of c.
        #[test]
        fn jumps_and_kinks_narrow_as_bisection_does(
            c in 0.1f32..0.9,
            steep in 1.0f32..1000.0,
            kind in 0usize..3,
            iters in 1u32..20,
        ) {
            let f = move |t: f32| match kind {
                0 => if t < c { -1.0 } else { steep },
                1 => if t < c { t - c } else { steep * (t - c) },
                _ => 1.0 / (c - t),
            };
            let (t, _) = counted(f, (0.0, 1.0), iters, 0.0);
            let bound = 8.0 / 2f32.powi(iters as i32) + 1e-6;
            prop_assert!((t - c).abs() <= bound, "t {t}, c {c}, bound {bound}");
        }
    }

    proptest! {
        /// A search driven one value at a time asks for f at the points `refine` evaluates
        /// it at, in order, and ends on its root, bit for bit: on roots smooth, kinked and in
        /// rounding noise, with few steps and many.
        #[test]
        fn a_search_a_value_at_a_time_is_refine_s(
            c in -3.0f32..3.0, slope in 0.01f32..100.0, kind in 0usize..3,
            width in 1e-4f32..2.0, at in 0.01f32..0.99, iters in 0u32..30,
            tol in prop::sample::select(vec![0.0f32, 1e-6, 1e-3]),
        ) {
            let f = move |t: f32| match kind {
                0 => slope * (t - c) + 0.3 * (t - c) * (t - c),
                1 => slope * (t - c).abs().sqrt().copysign(t - c),
                _ => ((slope * (t - c)) * 65536.0).round() / 65536.0,
            };
            let (lo, hi) = (c - at * width, c + (1.0 - at) * width);
            let ends = (f(lo), f(hi));
            prop_assume!(ends.0 < 0.0 && ends.1 > 0.0);
            let mut asked = Vec::new();
            let root = refine(|t| { asked.push(t); f(t) }, (lo, hi), ends, iters, tol);
            let search = RootSearch::new((lo, hi), ends, iters, tol);
            let mut driven = Vec::new();
            let found = search.finish(|t| { driven.push(t); f(t) });
            prop_assert_eq!(driven, asked);
            prop_assert_eq!(found.to_bits(), root.to_bits());
        }
    }

    #[test]
    fn values_that_are_not_finite_bisect() {
        // Infinite or NaN ends make no secant: the step is the midpoint, as bisection's.
        let (t, _) = counted(
            |t| {
                if t < 0.3 {
                    f32::NEG_INFINITY
                } else {
                    f32::INFINITY
                }
            },
            (0.0, 1.0),
            2,
            0.0,
        );
        assert_eq!(t, 0.25);
        let mid = falsi_step((0.0, 1.0), (f32::NAN, 1.0), 4.0);
        assert_eq!(mid, 0.5);
        // No steps: the bracket's middle.
        assert_eq!(counted(|t| t - 0.1, (0.0, 1.0), 0, 1e-6), (0.5, 0));
    }
}
