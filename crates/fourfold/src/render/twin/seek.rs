//! The search between the pencil's rays, as the shader's `seek_in_plane`
//! (templates/raycast/seek.wgsl): a pixel whose rays found nothing searches each of its
//! boxes again, with a few Newton steps on F within its observer plane from the rays'
//! closest sample or a point in the box, for a sign change inside it whose root is a hit.

use crate::render::view::{FLAG_CERTIFIED, FLAG_SLAB, plane_ray};

use super::pixel::{Marched, Pixel, same_side};
use super::shading::{V4, add, dot, scale, sub};

/// Evaluations of F and ∇F (a step's, a valley floor's) from each start, and how much each
/// Newton step is lengthened so that it crosses a root it nears (the shader's SEEK_EVALS
/// and SEEK_REACH).
const SEEK_EVALS: u32 = 8;
const SEEK_REACH: f32 = 1.5;

fn dot2(a: [f32; 2], b: [f32; 2]) -> f32 {
    a[0] * b[0] + a[1] * b[1]
}

impl Pixel<'_, '_> {
    fn in_plane(&self, o: V4, st: [f32; 2]) -> V4 {
        add(o, add(scale(self.u.n1, st[0]), scale(self.u.n2, st[1])))
    }

    fn in_slab(&self, st: [f32; 2]) -> bool {
        let r = &self.u.root;
        self.u.control.flags & FLAG_SLAB == 0
            || (st[1] >= r.section_offset - r.section_half
                && st[1] <= r.section_offset + r.section_half)
    }

    /// A point of the plane through `o` inside the box (or near it, if the plane misses it)
    /// from `st`: alternate projections on its four slabs shrunk by a thousandth (the
    /// shader's `point_in_box`).
    fn point_in_box(&self, o: V4, st: [f32; 2], lo: V4, hi: V4) -> [f32; 2] {
        let (n1, n2) = (self.u.n1, self.u.n2);
        let mut p = st;
        for _ in 0..4 {
            for k in 0..4 {
                let m = 0.001 * (hi[k] - lo[k]);
                let a = [n1[k], n2[k]];
                let aa = a[0] * a[0] + a[1] * a[1];
                let v = o[k] + a[0] * p[0] + a[1] * p[1];
                let to = v.max(lo[k] + m).min(hi[k] - m);
                if aa > 1e-12 {
                    let c = (to - v) / aa;
                    p = [p[0] + c * a[0], p[1] + c * a[1]];
                }
            }
        }
        p
    }

    /// The share of `step` from `st` (inside the box) that stays in it, and the outward
    /// normal in the plane of the side where it would leave (0 where it stays): the
    /// shader's `within_box`.
    fn within_box(&self, o: V4, st: [f32; 2], step: [f32; 2], lo: V4, hi: V4) -> (f32, [f32; 2]) {
        let (n1, n2) = (self.u.n1, self.u.n2);
        let p = self.in_plane(o, st);
        let d = add(scale(n1, step[0]), scale(n2, step[1]));
        let (mut k, mut r) = (0, f32::INFINITY);
        for i in 0..4 {
            // (A step along a side of the box never reaches it.)
            let room = if d[i].abs() < 1e-30 {
                f32::INFINITY
            } else {
                (if d[i] > 0.0 {
                    hi[i] - p[i]
                } else {
                    lo[i] - p[i]
                }) / d[i]
            };
            if i == 0 || room < r {
                (k, r) = (i, room);
            }
        }
        let sign = if d[k] > 0.0 {
            1.0
        } else if d[k] < 0.0 {
            -1.0
        } else {
            0.0
        };
        let a = [n1[k] * sign, n2[k] * sign];
        let len = (a[0] * a[0] + a[1] * a[1]).sqrt();
        let wall = if len > 1e-6 && r < 1.0 {
            [a[0] / len, a[1] / len]
        } else {
            [0.0; 2]
        };
        (r.clamp(0.0, 1.0), wall)
    }

    /// Newton's steps from `start` (in the box [lo, hi]) towards a root of F in the plane
    /// through `o`: a sign change between a and b, and F(a) (the shader's `seek_from`).
    fn seek_from(
        &mut self,
        o: V4,
        start: [f32; 2],
        lo: V4,
        hi: V4,
    ) -> Option<([f32; 2], f32, [f32; 2])> {
        let half = sub(hi, lo);
        let reach = 0.5 * dot(half, half).sqrt();
        let mut a = start;
        let (mut fa, mut ga) = self.f_grad(self.in_plane(o, a));
        // M is farther than the box reaches, by |F| / |∇F| in the plane (or F is undefined
        // there): no search (as the shader).
        let (gs, gt) = (dot(ga, self.u.n1), dot(ga, self.u.n2));
        if !(fa.abs() <= reach * (gs * gs + gt * gt).sqrt()) {
            return None;
        }
        let mut found = None;
        // The outward normal of the box's side the search stands on ([0, 0]: none).
        let mut wall = [0.0f32; 2];
        // How far the next step goes, in Newton's steps.
        let mut gain = SEEK_REACH;
        // (F's evaluations, the steps' and the floors'.)
        let mut evals = 0;
        while evals < SEEK_EVALS {
            evals += 1;
            // ∇F in the plane, and along the side if the step would leave through it.
            let g = [dot(ga, self.u.n1), dot(ga, self.u.n2)];
            let out = dot2(g, wall);
            let gw = if out * fa < 0.0 {
                [g[0] - out * wall[0], g[1] - out * wall[1]]
            } else {
                g
            };
            let k = -gain * fa / dot2(gw, gw);
            let mut step = [k * gw[0], k * gw[1]];
            let len = dot2(step, step).sqrt();
            if !(len < f32::INFINITY) {
                break;
            }
            if len > reach {
                step = step.map(|s| s * (reach / len));
            }
            let (share, side) = self.within_box(o, a, step, lo, hi);
            if share < 1e-3 {
                if wall != [0.0; 2] || side == [0.0; 2] {
                    break;
                }
                wall = side;
                continue;
            }
            // (Short of the side by a thousandth: a point on it may round to outside.)
            let reached = if share < 1.0 { share * 0.999 } else { share };
            let b = [a[0] + reached * step[0], a[1] + reached * step[1]];
            let (mut b, (mut fb, mut gb)) = (b, self.f_grad(self.in_plane(o, b)));
            if !same_side(fa, fb) {
                found = Some(b);
                break;
            }
            // Across a valley's floor: the point where the tangents at a and b meet, too.
            let taken = [b[0] - a[0], b[1] - a[1]];
            let sa = dot2(g, taken);
            let sb = dot2([dot(gb, self.u.n1), dot(gb, self.u.n2)], taken);
            if sa * fa < 0.0 && sb * fa > 0.0 {
                let tau = ((fb - fa - sb) / (sa - sb)).clamp(0.05, 0.95);
                let m = [a[0] + tau * taken[0], a[1] + tau * taken[1]];
                let (fm, gm) = self.f_grad(self.in_plane(o, m));
                evals += 1;
                if !same_side(fa, fm) {
                    found = Some(m);
                    break;
                }
                if fm.abs() < fb.abs() {
                    (b, fb, gb) = (m, fm, gm);
                }
            }
            if fb.abs() < fa.abs() {
                if share < 1.0 {
                    wall = side;
                }
                (a, fa, ga) = (b, fb, gb);
                gain = SEEK_REACH;
            } else {
                // Nothing nearer 0: a shorter step (the parabola's point nearest 0).
                let bend = fb - fa - sa;
                let best = if bend * fa > 0.0 {
                    (-sa / (2.0 * bend)).clamp(0.05, 0.95)
                } else {
                    0.5
                };
                gain = gain * best * dot2(taken, taken).sqrt() / len;
            }
        }
        found.map(|b| (a, fa, b))
    }

    /// Seeks a root of F in the box `b`, within the plane through `o`, and keeps it as a hit.
    pub(super) fn seek_in_plane(&mut self, o: V4, b: &Marched) {
        let (lo, hi) = (b.lo, b.hi);
        let inside = |p: V4| (0..4).all(|k| p[k] >= lo[k] && p[k] <= hi[k]);
        // From the rays' closest sample if it lies in the box, then from a point near the
        // box's centre.
        let (near, near_f) = self.closest;
        let mut seek = None;
        if near_f < f32::INFINITY && inside(self.in_plane(o, near)) {
            seek = self.seek_from(o, near, lo, hi);
        }
        if seek.is_none() {
            let rel = sub(scale(add(lo, hi), 0.5), o);
            let centre = self.point_in_box(o, [dot(rel, self.u.n1), dot(rel, self.u.n2)], lo, hi);
            if inside(self.in_plane(o, centre)) {
                seek = self.seek_from(o, centre, lo, hi);
            }
        }
        let Some((a, fa, b)) = seek else {
            return;
        };
        if self.u.control.flags & FLAG_CERTIFIED != 0
            && self.bracket.is_none()
            && self.in_slab(a)
            && self.in_slab(b)
        {
            self.bracket = Some((a.map(f64::from), b.map(f64::from)));
        }
        // The root on the segment from a to b, as a ray's.
        let ab = [b[0] - a[0], b[1] - a[1]];
        let d = add(scale(self.u.n1, ab[0]), scale(self.u.n2, ab[1]));
        let tau = self.bisect(self.in_plane(o, a), d, (0.0, 1.0), fa < 0.0);
        let m = [a[0] + tau * ab[0], a[1] + tau * ab[1]];
        let t = dot2(m, m).sqrt();
        if t > 0.0 && inside(self.in_plane(o, m)) && self.in_slab(m) {
            self.insert(t, plane_ray([m[0] / t, m[1] / t]));
        }
    }
}
