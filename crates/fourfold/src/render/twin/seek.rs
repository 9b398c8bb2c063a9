//! The search between the pencil's rays, as the shader's `seek_in_plane`
//! (templates/raycast/seek.wgsl): a pixel whose rays found nothing searches each of its
//! boxes again, with a few Newton steps on F within its observer plane from the rays'
//! closest samples or a point in the box, for a sign change inside it whose root is a hit.

use crate::render::view::{FLAG_CERTIFIED, FLAG_SLAB, plane_ray};

use super::certify::SignChange;
use super::march::same_side;
use super::pixel::{Marched, Pixel};
use super::shading::{V4, add, dot, scale, sub};

/// Evaluations of F and ∇F (a step's, a valley floor's) from each start, and how much each
/// Newton step is lengthened so that it crosses a root it nears (the shader's SEEK_EVALS
/// and SEEK_REACH).
const SEEK_EVALS: u32 = 8;
const SEEK_REACH: f32 = 1.5;
/// The corners tried of the plane's part in a box: two of its sides, of four axes' eight.
const BOX_CORNERS: usize = 24;

fn dot2(a: [f32; 2], b: [f32; 2]) -> f32 {
    a[0] * b[0] + a[1] * b[1]
}

/// How far outside its box, as a share of the domain's extent along each axis, the search's
/// root may lie and still be kept (the shader's ROOT_MARGIN): about 170 units of f32's
/// rounding of the domain's coordinates, a two-hundredth of a pixel of a 512² picture.
const ROOT_MARGIN: f32 = 1e-5;

/// Whether `p` lies in the box [lo, hi] (the shader's `in_box`).
fn in_box(p: V4, lo: V4, hi: V4) -> bool {
    (0..4).all(|k| p[k] >= lo[k] && p[k] <= hi[k])
}

/// Where a search from one start ended: at a, with F(a) (NaN where F is undefined at the
/// start: the search never moves from there), and the sign change from a to b it found,
/// with F(b).
#[derive(Clone, Copy)]
struct Seek {
    a: [f32; 2],
    fa: f32,
    b: Option<([f32; 2], f32)>,
}

impl Seek {
    fn change(self) -> Option<([f32; 2], f32, [f32; 2], f32)> {
        self.b.map(|(b, fb)| (self.a, self.fa, b, fb))
    }
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

    /// Corner `i` (of 24 tried) of the plane's part in the box [lo, hi] shrunk by a
    /// thousandth, if it is one: where the plane meets two of the box's sides (pair `i / 4`
    /// of two axes, their bounds by `i % 4`) within the others, give or take half that
    /// margin (the shader's `box_corner`).
    fn box_corner(&self, o: V4, lo: V4, hi: V4, i: usize) -> Option<[f32; 2]> {
        const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
        let (n1, n2) = (self.u.n1, self.u.n2);
        let m: V4 = std::array::from_fn(|k| 0.001 * (hi[k] - lo[k]));
        let (l, h) = (add(lo, m), sub(hi, m));
        let (a, b) = PAIRS[i / 4];
        let det = n1[a] * n2[b] - n2[a] * n1[b];
        if det.abs() < 1e-12 {
            return None;
        }
        let ra = if i % 4 >= 2 { h[a] } else { l[a] } - o[a];
        let rb = if i % 2 == 1 { h[b] } else { l[b] } - o[b];
        let st = [
            (ra * n2[b] - n2[a] * rb) / det,
            (n1[a] * rb - ra * n1[b]) / det,
        ];
        let p = self.in_plane(o, st);
        (0..4)
            .all(|k| p[k] >= l[k] - 0.5 * m[k] && p[k] <= h[k] + 0.5 * m[k])
            .then_some(st)
    }

    /// Whether the plane meets the box whose centre lies at `rel` from the plane's origin,
    /// with half extents `half` (give or take rounding): the box's shadow along the plane on
    /// (v1, v2), a zonotope with a side along each axis's (v1_k, v2_k), holds the plane's
    /// point; tested across each side, and along v1 and v2 (the shader's `plane_meets_box`).
    fn plane_meets_box(&self, rel: V4, half: V4) -> bool {
        let (v1, v2) = (self.u.v1, self.u.v2);
        let (a, b) = (dot(rel, v1), dot(rel, v2));
        let along = |w: V4| dot(half, w.map(f32::abs));
        let slack = 1e-5 * (a.abs() + b.abs() + dot(half, half).sqrt());
        (0..4).all(|k| {
            let w = sub(scale(v2, v1[k]), scale(v1, v2[k]));
            (b * v1[k] - a * v2[k]).abs() <= along(w) * 1.0001 + slack
        }) && a.abs() <= along(v1) * 1.0001 + slack
            && b.abs() <= along(v2) * 1.0001 + slack
    }

    /// A point of the plane through `o` inside the box [lo, hi], if the plane meets it (the
    /// shader's `point_in_box`): from the box's centre, alternate projections on its four
    /// slabs shrunk by a thousandth; where four rounds of them end outside (the plane cuts
    /// only a corner of the box: they converge slowly there), the mean of the corners of the
    /// plane's part in the box.
    fn point_in_box(&self, o: V4, lo: V4, hi: V4) -> Option<[f32; 2]> {
        let rel = sub(scale(add(lo, hi), 0.5), o);
        if !self.plane_meets_box(rel, scale(sub(hi, lo), 0.5)) {
            return None;
        }
        let (n1, n2) = (self.u.n1, self.u.n2);
        let mut p = [dot(rel, n1), dot(rel, n2)];
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
        if in_box(self.in_plane(o, p), lo, hi) {
            return Some(p);
        }
        let (mut sum, mut count) = ([0.0f32; 2], 0);
        for st in (0..BOX_CORNERS).filter_map(|i| self.box_corner(o, lo, hi, i)) {
            sum = [sum[0] + st[0], sum[1] + st[1]];
            count += 1;
        }
        (count > 0).then(|| [sum[0] / count as f32, sum[1] / count as f32])
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
    /// through `o` (the shader's `seek_from`).
    fn seek_from(&mut self, o: V4, start: [f32; 2], lo: V4, hi: V4) -> Seek {
        let half = sub(hi, lo);
        let reach = 0.5 * dot(half, half).sqrt();
        let mut a = start;
        let (mut fa, mut ga) = self.f_grad(self.in_plane(o, a));
        // M is farther than the box reaches, by |F| / |∇F| in the plane (or F is undefined
        // there): no search (as the shader).
        let (gs, gt) = (dot(ga, self.u.n1), dot(ga, self.u.n2));
        if !(fa.abs() <= reach * (gs * gs + gt * gt).sqrt()) {
            return Seek { a, fa, b: None };
        }
        let mut found = None;
        // The outward normal of the box's side the search stands on ([0, 0]: none).
        let mut wall = [0.0f32; 2];
        // The normal of the valley's floor the search stands on ([0, 0]: none).
        let mut crease = [0.0f32; 2];
        // How far the next step goes, in Newton's steps.
        let mut gain = SEEK_REACH;
        // (F's evaluations, the steps' and the floors'.)
        let mut evals = 0;
        while evals < SEEK_EVALS {
            evals += 1;
            // (Whether this step goes along a floor found before.)
            let on_floor = crease != [0.0; 2];
            // ∇F in the plane, along the valley's floor if on one, and along the side if the
            // step would leave through it.
            let g = [dot(ga, self.u.n1), dot(ga, self.u.n2)];
            let across = dot2(g, crease);
            let g_floor = [g[0] - across * crease[0], g[1] - across * crease[1]];
            let out = dot2(g_floor, wall);
            let gw = if out * fa < 0.0 {
                [g_floor[0] - out * wall[0], g_floor[1] - out * wall[1]]
            } else {
                g_floor
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
                found = Some((b, fb));
                break;
            }
            // Across a valley's floor: the point where the tangents at a and b meet, too.
            let (taken, fb_step) = ([b[0] - a[0], b[1] - a[1]], fb);
            let gb2 = [dot(gb, self.u.n1), dot(gb, self.u.n2)];
            let sa = dot2(g, taken);
            let sb = dot2(gb2, taken);
            if sa * fa < 0.0 && sb * fa > 0.0 {
                let tau = ((fb - fa - sb) / (sa - sb)).clamp(0.05, 0.95);
                let m = [a[0] + tau * taken[0], a[1] + tau * taken[1]];
                let (fm, gm) = self.f_grad(self.in_plane(o, m));
                evals += 1;
                if !same_side(fa, fm) {
                    found = Some((m, fm));
                    break;
                }
                if fm.abs() < fb.abs() {
                    // On the floor: the next steps go along it (its normal is where the
                    // gradient turned, from a to b), not across it again.
                    let turn = [gb2[0] - g[0], gb2[1] - g[1]];
                    let len = dot2(turn, turn).sqrt();
                    crease = if len > 0.0 {
                        [turn[0] / len, turn[1] / len]
                    } else {
                        [0.0; 2]
                    };
                    (b, fb, gb) = (m, fm, gm);
                }
            }
            if fb.abs() < fa.abs() {
                if share < 1.0 {
                    wall = side;
                }
                (a, fa, ga) = (b, fb, gb);
                gain = SEEK_REACH;
            } else if on_floor {
                // Along the floor took |F| up: the gradient's own step again.
                crease = [0.0; 2];
            } else {
                // Nothing nearer 0, even where the tangents meet: a shorter step (the
                // parabola's point nearest 0, through F at a, its slope and F at b), not
                // along that floor (the same step again would find the same).
                crease = [0.0; 2];
                let bend = fb_step - fa - sa;
                let best = if bend * fa > 0.0 {
                    (-sa / (2.0 * bend)).clamp(0.05, 0.95)
                } else {
                    0.5
                };
                gain = gain * best * dot2(taken, taken).sqrt() / len;
            }
        }
        Seek { a, fa, b: found }
    }

    /// How far from the sample at `st` (in the plane) M may be for the search to start there
    /// when it is not the nearest start: an island the pencil passed beside lies within half
    /// the gap between two rays, |st|·π/n, of one of them (and within half a step of one of
    /// its samples: a margin of a thousandth of the domain's diagonal stands for it); four
    /// times that, as `away` is a first-order guess (the shader's `between_rays`).
    fn between_rays(&self, st: [f32; 2]) -> f32 {
        let gap = std::f32::consts::TAU / self.u.size.rays as f32;
        let extent = sub(self.u.domain_hi, self.u.domain_lo);
        2.0 * (dot2(st, st).sqrt() * gap + 0.002 * dot(extent, extent).sqrt())
    }

    /// Seeks a root of F in the box `b`, within the plane through `o`, and keeps it as a hit.
    pub(super) fn seek_in_plane(&mut self, o: V4, b: &Marched) {
        let (lo, hi) = (b.lo, b.hi);
        let inside = |p: V4| in_box(p, lo, hi);
        // From the rays' closest samples that lie in the box, then from a point amid the
        // plane's part in the box.
        let mut seek = None;
        for (i, (near, away)) in self.starts.into_iter().enumerate() {
            let plausible = away < f32::INFINITY && (i == 0 || away <= self.between_rays(near));
            if plausible && inside(self.in_plane(o, near)) {
                seek = self.seek_from(o, near, lo, hi).change();
                if seek.is_some() {
                    break;
                }
            }
        }
        let amid = || {
            self.point_in_box(o, lo, hi)
                .filter(|&c| inside(self.in_plane(o, c)))
        };
        if let Some(centre) = seek.is_none().then(amid).flatten() {
            let from_centre = self.seek_from(o, centre, lo, hi);
            seek = from_centre.change();
            // Where F is undefined there (ln, sqrt or a pole past the edge of its domain),
            // from each corner, a hundredth of the way in: F's domain within the plane's part
            // in the box is cut off by its edge, and where that is a line, a corner lies on
            // the defined side. (Not in a certified frame, as the shader: it proves what the
            // corners would find, and aims a ray at it.)
            let certified = self.u.control.flags & FLAG_CERTIFIED != 0;
            if from_centre.fa.is_nan() && !certified {
                for i in 0..BOX_CORNERS {
                    let Some(corner) = self.box_corner(o, lo, hi, i) else {
                        continue;
                    };
                    let start = [
                        corner[0] + 0.01 * (centre[0] - corner[0]),
                        corner[1] + 0.01 * (centre[1] - corner[1]),
                    ];
                    if inside(self.in_plane(o, start)) {
                        seek = self.seek_from(o, start, lo, hi).change();
                        if seek.is_some() {
                            break;
                        }
                    }
                }
            }
        }
        let Some((a, fa, b, fb)) = seek else {
            return;
        };
        if self.u.control.flags & FLAG_CERTIFIED != 0
            && self.bracket.is_none()
            && self.in_slab(a)
            && self.in_slab(b)
        {
            // (No samples: the search's points are not the plane's as a march has them.)
            self.bracket = Some(SignChange {
                ends: [a.map(f64::from), b.map(f64::from)],
                samples: None,
            });
        }
        // The root on the segment from a to b, as a ray's.
        let ab = [b[0] - a[0], b[1] - a[1]];
        let d = add(scale(self.u.n1, ab[0]), scale(self.u.n2, ab[1]));
        let tau = self.refine_root(self.in_plane(o, a), d, (0.0, 1.0), (fa, fb));
        let m = [a[0] + tau * ab[0], a[1] + tau * ab[1]];
        let t = dot2(m, m).sqrt();
        // (In the box widened past rounding: a search along the box's side finds roots on
        // it, and the point worked out from m may round to either side.)
        let margin = scale(sub(self.u.domain_hi, self.u.domain_lo), ROOT_MARGIN);
        let near = in_box(self.in_plane(o, m), sub(lo, margin), add(hi, margin));
        if t > 0.0 && near && self.in_slab(m) {
            self.insert(t, plane_ray([m[0] / t, m[1] / t]));
        }
    }
}
