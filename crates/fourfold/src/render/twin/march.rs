//! A ray's march over its span in a box (docs/method.md §5.3), as the shader's `march_ray`
//! takes it, held as a state that asks for one sample at a time: so that a pixel can take
//! its samples one by one, and a tile's slice pixels theirs side by side (see `abreast`).

use super::shading::V4;

/// What lets a march step over samples that cannot change sign: its box's steps, the bounds
/// on |dF/dt| and on d²F/dt² there (+∞ and (−∞, +∞): none), and the range of the pixel's
/// stretches of its line (ascending distances from its start) on which F keeps one sign.
#[derive(Clone, Copy)]
pub(super) struct Skips {
    pub(super) steps: u32,
    pub(super) slope: f32,
    pub(super) bend: (f32, f32),
    pub(super) one_signed: (u32, u32),
}

/// A box's bounds on |dF/dt| and on d²F/dt² along a slice's rays, o + t n1 (the same for
/// all of them: worked out once per tile, not once per pixel).
#[derive(Debug, Clone, Copy)]
pub(super) struct Along {
    pub(super) slope: f32,
    pub(super) bend: (f32, f32),
}

/// A stretch of a slice's tile's lines, [from, to] as distances along n1 from their
/// starts, on which F keeps one sign: `sign` (1 or −1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Stretch {
    pub(super) from: f32,
    pub(super) to: f32,
    pub(super) sign: f32,
}

/// The march of o + t d over [t0, t1] in `steps` equal steps, stepping over the samples
/// that cannot change sign (the same sign changes as taking every sample). Ask
/// [`Self::next`] where the next sample is, hand F and dF/dt there to [`Self::take`].
#[derive(Clone, Copy)]
pub(super) struct March {
    pub(super) o: V4,
    pub(super) d: V4,
    pub(super) ray: u32,
    /// Whether the samples need dF/dt (only the curvature bound reads it).
    pub(super) bent: bool,
    t0: f32,
    dt: f32,
    steps: u32,
    /// Samples per unit of t, and per unit of |F|, sure to keep F's sign.
    per_t: f32,
    reach: f32,
    bend: (f32, f32),
    one_signed: (u32, u32),
    /// The next sample's index, and the one-signed stretch that does not end before ta.
    s: u32,
    next: u32,
    /// The last sample: its t, F (after a skip, F's sign there, from an earlier sample)
    /// and dF/dt, and whether `fa` is F at ta.
    ta: f32,
    fa: f32,
    ga: f32,
    fresh: bool,
    /// Whether the sample at t0 is taken.
    started: bool,
}

/// A sign change between two samples: F at tb, and at ta where `fresh` (else F's sign
/// there, kept from an earlier sample across a skip).
#[derive(Clone, Copy)]
pub(super) struct Crossing {
    pub(super) ta: f32,
    pub(super) tb: f32,
    pub(super) fa: f32,
    pub(super) fb: f32,
    pub(super) fresh: bool,
}

impl March {
    pub(super) fn new(o: V4, d: V4, (t0, t1): (f32, f32), skips: Skips, ray: u32) -> Self {
        let Skips {
            steps,
            slope,
            bend,
            one_signed,
        } = skips;
        let dt = (t1 - t0) / steps as f32;
        // (0.999: a margin for rounding.)
        let per_t = 0.999 / dt;
        Self {
            o,
            d,
            ray,
            bent: bend.0.is_finite() && bend.1.is_finite(),
            t0,
            dt,
            steps,
            per_t,
            reach: per_t / slope,
            bend,
            one_signed,
            s: 1,
            next: one_signed.0,
            ta: t0,
            fa: 0.0,
            ga: 0.0,
            fresh: true,
            started: false,
        }
    }

    /// Where the next sample is (its t), or None where the march is over: past its span,
    /// or at `stop` (the farthest hit where the hits are full, else +∞). `one_signed`
    /// holds the pixel's stretches that [`Skips::one_signed`] ranges over.
    pub(super) fn next(&mut self, stop: f32, one_signed: &[Stretch]) -> Option<f32> {
        let end = self.one_signed.1;
        while self.next < end && one_signed[self.next as usize].to < self.ta {
            self.next += 1;
        }
        let stretch = (self.next < end)
            .then(|| one_signed[self.next as usize])
            .filter(|s| s.from <= self.ta);
        let mut m = 0.0;
        if self.started {
            m = (self.fa.abs() * self.reach)
                .max(zero_ahead(self.fa, self.ga, self.bend) * self.per_t);
        } else {
            // A march that starts in a one-signed stretch knows F's sign there: its first
            // sample is the one after the stretch (a skip, as from a sample at t0; F there
            // is not known, only its sign, held by a tiny F of that sign).
            let Some(s) = stretch else {
                return Some(self.t0);
            };
            (self.started, self.fa, self.ga, self.fresh) =
                (true, s.sign * f32::MIN_POSITIVE, 0.0, false);
        }
        if let Some(s) = stretch {
            m = m.max((s.to - self.ta) * self.per_t);
        }
        if m >= 1.0 {
            self.s += m.min(self.steps as f32) as u32;
            self.ta = self.t0 + (self.s - 1) as f32 * self.dt;
            self.fresh = false;
        }
        if self.s > self.steps || self.ta >= stop {
            return None;
        }
        Some(self.t0 + self.s as f32 * self.dt)
    }

    /// Takes F and dF/dt (0 unless `bent`) at `t`, the sample [`Self::next`] asked for:
    /// the sign change from the last sample, if F changed sign.
    pub(super) fn take(&mut self, t: f32, [fb, gb]: [f32; 2]) -> Option<Crossing> {
        if !std::mem::replace(&mut self.started, true) {
            (self.fa, self.ga) = (fb, gb);
            return None;
        }
        let crossing = (!same_side(self.fa, fb)).then_some(Crossing {
            ta: self.ta,
            tb: t,
            fa: self.fa,
            fb,
            fresh: self.fresh,
        });
        (self.ta, self.fa, self.ga, self.fresh) = (t, fb, gb, true);
        self.s += 1;
        crossing
    }
}

/// How far from a sample with value `f` and slope `g` (dF/dt) F surely keeps its sign when
/// d²F/dt² lies in `bend`: the first zero of the parabola that bounds |F| from below
/// (+∞: none; 0 where F, its slope or the bound is not finite). The shader's rule (`march_ray`).
fn zero_ahead(f: f32, g: f32, (lo, hi): (f32, f32)) -> f32 {
    // |F|, its slope, and how fast it can bend towards 0.
    let (g, c) = if f > 0.0 { (g, -lo) } else { (-g, hi) };
    let f = f.abs();
    if !(f.is_finite() && g.is_finite() && c.is_finite()) {
        return 0.0;
    }
    let disc = g * g + 2.0 * c * f;
    let root = disc.max(0.0).sqrt();
    if disc >= 0.0 && root > g {
        2.0 * f / (root - g)
    } else {
        f32::INFINITY
    }
}

/// Whether F keeps its sign from `fa` to `fb`: signs compared as the shader's `same_side`
/// compares them (a product of tiny values underflows to 0).
pub(super) fn same_side(fa: f32, fb: f32) -> bool {
    !(((fa <= 0.0 && fb >= 0.0) || (fa >= 0.0 && fb <= 0.0)) && !(fa == 0.0 && fb == 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The samples a march asks for over [0, 1] in 100 steps of F(t) = t − 0.555 (no slope
    /// or curvature bound), and the sign changes it finds.
    fn marched(one_signed: &[Stretch]) -> (Vec<f32>, Vec<(f32, f32)>) {
        let skips = Skips {
            steps: 100,
            slope: f32::INFINITY,
            bend: (f32::NEG_INFINITY, f32::INFINITY),
            one_signed: (0, one_signed.len() as u32),
        };
        let mut march = March::new([0.0; 4], [1.0, 0.0, 0.0, 0.0], (0.0, 1.0), skips, 0);
        let (mut asked, mut crossings) = (Vec::new(), Vec::new());
        while let Some(t) = march.next(f32::INFINITY, one_signed) {
            asked.push(t);
            if let Some(c) = march.take(t, [t - 0.555, 1.0]) {
                crossings.push((c.ta, c.tb));
            }
        }
        (asked, crossings)
    }

    /// A march that starts in a one-signed stretch takes no sample before its end and finds
    /// the same sign change; one that starts before it, its first at its start.
    #[test]
    fn a_march_starting_in_a_one_signed_stretch_skips_it() {
        let (every, crossing) = marched(&[]);
        assert_eq!(every.len(), 101);
        assert_eq!(crossing.len(), 1);
        let stretch = |sign| Stretch {
            from: 0.0,
            to: 0.305,
            sign,
        };
        let (asked, found) = marched(&[stretch(-1.0)]);
        assert!(asked[0] > 0.3 && asked[0] < 0.32, "{asked:?}");
        assert_eq!(found, crossing);
        // (From the first sample in it, at 0.11, to its end.)
        let later = Stretch {
            from: 0.105,
            to: 0.305,
            sign: -1.0,
        };
        let (asked, found) = marched(&[later]);
        assert_eq!(asked[0], 0.0);
        assert!(
            asked.iter().all(|t| !(0.115..=0.3).contains(t)),
            "{asked:?}"
        );
        assert!(asked.len() + 15 < every.len(), "{asked:?}");
        assert_eq!(found, crossing);
    }
}
