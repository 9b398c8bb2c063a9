//! The slice's own frame: the hyperplane at c along n2 from the domain's centre, with the
//! view's orthonormal axes v1, v2, n1 as its x, y, z, so that lengths and volumes measured
//! in it are those of R⁴. The domain enters as a function too, `outside`: ≤ 0 exactly on
//! the domain's box, with flat faces, so that the cut can be capped by them.

use crate::eval::Box4;
use crate::interval::Interval;
use crate::render::view::Rotation4;
use crate::scene::{Domain, View};

/// A box of the slice's frame, one interval per axis.
pub type Box3 = [Interval; 3];

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliceFrame {
    /// The frame's origin in R⁴: the domain's centre moved by c along n2.
    origin: [f64; 4],
    /// v1, v2, n1: the frame's axes in R⁴.
    axes: [[f64; 4]; 3],
    /// n2: the hyperplane's normal.
    normal: [f64; 4],
    offset: f64,
    center: [f64; 4],
    half: [f64; 4],
}

impl SliceFrame {
    /// The slice at `offset` along the view's n2.
    pub fn new(domain: &Domain, view: &View, offset: f64) -> Self {
        let a = Rotation4::from_angles(view.angles);
        let center = domain.center();
        let normal = a.row(3);
        Self {
            origin: std::array::from_fn(|i| center[i] + offset * normal[i]),
            axes: [a.row(0), a.row(1), a.row(2)],
            normal,
            offset,
            center,
            half: domain.axes().map(|r| 0.5 * (r.hi - r.lo)),
        }
    }

    /// The point of R⁴ at `u` in the frame.
    pub fn point(&self, u: [f64; 3]) -> [f64; 4] {
        std::array::from_fn(|i| {
            self.origin[i]
                + u[0] * self.axes[0][i]
                + u[1] * self.axes[1][i]
                + u[2] * self.axes[2][i]
        })
    }

    /// A box of R⁴ holding every point of the frame's box `b` (outward rounded, then widened
    /// by a few ulps so that the points [`Self::point`] computes in floating point lie in
    /// it too).
    pub fn enclose(&self, b: &Box3) -> Box4 {
        std::array::from_fn(|i| {
            let v = (0..3).fold(Interval::point(self.origin[i]), |acc, j| {
                acc.add(Interval::point(self.axes[j][i]).mul(b[j]))
            });
            let slack = 1e-14 * v.magnitude() + f64::MIN_POSITIVE;
            Interval::new(v.lo() - slack, v.hi() + slack)
        })
    }

    /// A 4D vector (F's gradient) as seen in the frame: its components along v1, v2, n1.
    pub fn project(&self, g: [f64; 4]) -> [f64; 3] {
        self.axes
            .map(|axis| (0..4).map(|i| axis[i] * g[i]).sum::<f64>())
    }

    /// How far outside the domain `p` is, by its farthest axis (≤ 0 inside, 0 on a face),
    /// and that function's gradient in R⁴.
    pub fn outside(&self, p: [f64; 4]) -> (f64, [f64; 4]) {
        let (mut value, mut axis) = (f64::NEG_INFINITY, 0);
        for i in 0..4 {
            let d = (p[i] - self.center[i]).abs() - self.half[i];
            if d > value {
                (value, axis) = (d, i);
            }
        }
        let mut gradient = [0.0; 4];
        gradient[axis] = if p[axis] >= self.center[axis] {
            1.0
        } else {
            -1.0
        };
        (value, gradient)
    }

    /// An enclosure of [`Self::outside`] over a box of R⁴.
    pub fn outside_over(&self, b: &Box4) -> Interval {
        (0..4)
            .map(|i| {
                b[i].sub(Interval::point(self.center[i]))
                    .abs()
                    .sub(Interval::point(self.half[i]))
            })
            .reduce(Interval::max)
            .expect("four axes")
    }

    /// How far from the domain's centre, along n2, the domain reaches: the slices within it
    /// meet the domain.
    pub fn reach(&self) -> f64 {
        (0..4).map(|i| self.normal[i].abs() * self.half[i]).sum()
    }

    /// Half the extent, along each of the frame's axes, of a box holding the slice of the
    /// domain; None where the hyperplane misses the domain.
    pub fn extent(&self) -> Option<[f64; 3]> {
        if self.offset.abs() > self.reach() {
            return None;
        }
        let reach = |v: &[f64; 4]| (0..4).map(|i| v[i].abs() * self.half[i]).sum::<f64>();
        // Within the domain's sphere too: |u|² + c² ≤ (half-diagonal)².
        let radius = (self.half.iter().map(|h| h * h).sum::<f64>() - self.offset.powi(2))
            .max(0.0)
            .sqrt();
        Some(self.axes.map(|axis| reach(&axis).min(radius)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_the_view_s_and_the_box_encloses_its_points() {
        let domain = Domain::default();
        let view = View {
            angles: [0.3, -0.7, 1.1, 0.2, 0.5, -0.4],
            ..View::default()
        };
        let frame = SliceFrame::new(&domain, &view, 0.6);
        let u = [0.25, -1.5, 0.75];
        let p = frame.point(u);
        let n2 = Rotation4::from_angles(view.angles).row(3);
        let along: f64 = (0..4).map(|i| p[i] * n2[i]).sum();
        assert!((along - 0.6).abs() < 1e-12, "{along}");
        let b = u.map(|x| Interval::new(x - 0.1, x + 0.1));
        let enclosed = frame.enclose(&b);
        for corner in 0..8 {
            let c: [f64; 3] = std::array::from_fn(|j| {
                if corner >> j & 1 == 1 {
                    b[j].hi()
                } else {
                    b[j].lo()
                }
            });
            let q = frame.point(c);
            assert!(
                (0..4).all(|i| enclosed[i].contains(q[i])),
                "{q:?} {enclosed:?}"
            );
        }
        assert_eq!(
            frame.project(n2).map(|x| (x.abs() < 1e-12) as u8),
            [1, 1, 1]
        );
    }

    #[test]
    fn a_hyperplane_past_the_domain_misses_it() {
        let domain = Domain::default(); // [-2, 2]⁴
        let straight = SliceFrame::new(&domain, &View::default(), 1.5);
        assert_eq!(straight.extent(), Some([2.0, 2.0, 2.0]));
        assert_eq!(
            SliceFrame::new(&domain, &View::default(), 2.5).extent(),
            None
        );
        let (inside, _) = straight.outside(straight.point([0.0, 0.0, 0.0]));
        assert_eq!(inside, -0.5);
    }
}
