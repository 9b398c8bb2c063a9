//! The view: the rotation A of SPEC.md §4 from six angles, the projection and observer
//! planes it defines, and the pixel → R⁴ map of SPEC.md §5.1.

use glam::DMat4;

use crate::scene::{Domain, View};

/// A 4D rotation built from the six angles θ1..θ6.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation4(pub DMat4);

/// A basic rotation in the plane of axes (i, j): identity with [[c, −s], [s, c]] there.
fn plane_rotation(i: usize, j: usize, angle: f64) -> DMat4 {
    let (s, c) = angle.sin_cos();
    let mut m = DMat4::IDENTITY;
    // glam is column-major: element (row r, column k) is m.col_mut(k)[r].
    m.col_mut(i)[i] = c;
    m.col_mut(j)[i] = -s;
    m.col_mut(i)[j] = s;
    m.col_mut(j)[j] = c;
    m
}

impl Rotation4 {
    /// A = Rxy(θ1) Ryz(θ2) Rzw(θ3) Rxy(θ4) Ryz(θ5) Rxy(θ6).
    pub fn from_angles(t: [f64; 6]) -> Self {
        let planes = [(0, 1), (1, 2), (2, 3), (0, 1), (1, 2), (0, 1)];
        let m = planes
            .iter()
            .zip(t)
            .fold(DMat4::IDENTITY, |acc, (&(i, j), angle)| {
                acc * plane_rotation(i, j, angle)
            });
        Self(m)
    }

    /// Row r of A.
    pub fn row(&self, r: usize) -> [f64; 4] {
        self.0.row(r).to_array()
    }
}

/// Everything needed to turn a pixel into its observer plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// v1, v2: the projection plane; n1, n2: the observer plane (rows of A).
    pub v1: [f64; 4],
    pub v2: [f64; 4],
    pub n1: [f64; 4],
    pub n2: [f64; 4],
    /// c_H, the centre of the domain.
    pub center: [f64; 4],
    /// World units per pixel.
    pub pixel_size: f64,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// The camera for `view` of `domain` in a `width`×`height` image. At zoom 1 the disk of
    /// radius |half-diagonal of H| fits the shorter side, so the whole domain is in view.
    pub fn new(domain: &Domain, view: &View, width: u32, height: u32) -> Self {
        let a = Rotation4::from_angles(view.angles);
        let shorter = f64::from(width.min(height).max(1));
        Self {
            v1: a.row(0),
            v2: a.row(1),
            n1: a.row(2),
            n2: a.row(3),
            center: domain.center(),
            pixel_size: 2.0 * domain.half_diagonal() / shorter / view.zoom,
            width,
            height,
        }
    }

    /// The ray origin o of pixel (px, py), counted from the top-left (SPEC.md §5.1).
    pub fn origin(&self, px: f64, py: f64) -> [f64; 4] {
        let sx = self.pixel_size * (px + 0.5 - 0.5 * f64::from(self.width));
        let sy = self.pixel_size * (0.5 * f64::from(self.height) - py - 0.5);
        std::array::from_fn(|i| self.center[i] + sx * self.v1[i] + sy * self.v2[i])
    }
}
