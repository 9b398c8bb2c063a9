//! The view: the rotation A of docs/method.md §4 from six angles, the projection and observer
//! planes it defines, and the pixel → R⁴ map of docs/method.md §5.1.

use glam::DMat4;

use crate::scene::{Domain, View};

/// A 4D rotation built from the six angles θ1..θ6.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation4(pub DMat4);

/// A basic rotation in the plane of axes (i, j): identity with [[c, −s], [s, c]] there.
pub(super) fn plane_rotation(i: usize, j: usize, angle: f64) -> DMat4 {
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

    /// A turned by `angle` in the plane of the coordinate axes i and j: the manifold turns
    /// in that plane before it is seen through A.
    pub fn turned(&self, i: usize, j: usize, angle: f64) -> Self {
        Self(self.0 * plane_rotation(i, j, angle))
    }
}

/// What part of a pixel's observer plane the ray caster searches (docs/method.md §5.8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Section {
    /// The whole plane: the projection.
    Plane,
    /// The band within `half` of `center` along n2, from the domain's centre.
    Slab { center: f64, half: f64 },
    /// The line at `offset` along n2, seen along n1: the cut of M by a hyperplane.
    Slice { offset: f64 },
}

impl Section {
    pub fn of(view: &View) -> Self {
        match (view.slice, view.slab) {
            (Some(offset), _) => Section::Slice { offset },
            (None, Some([center, half])) => Section::Slab { center, half },
            (None, None) => Section::Plane,
        }
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
    /// The picture's centre in R⁴: c_H, the centre of the domain, moved by the view's pan
    /// along v1 and v2.
    pub center: [f64; 4],
    /// World units per pixel.
    pub pixel_size: f64,
    /// What part of each pixel's observer plane is searched.
    pub section: Section,
    /// How far behind the observer plane's origin along n1 a slice's ray starts: the
    /// domain's half-diagonal, so that it starts outside the domain (as the shader's).
    pub slice_start: f64,
    /// In a projection, the place along n2 whose hits are marked.
    pub mark: Option<f64>,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// The camera for `view` of `domain` in a `width`×`height` image. At zoom 1 the disk of
    /// radius |half-diagonal of H| fits the shorter side, so the whole domain is in view.
    pub fn new(domain: &Domain, view: &View, width: u32, height: u32) -> Self {
        Self::with_rotation(
            domain,
            view,
            Rotation4::from_angles(view.angles),
            width,
            height,
        )
    }

    /// As [`Camera::new`] with the rotation `a` instead of the view's angles (zoom and pan
    /// are the view's).
    pub fn with_rotation(
        domain: &Domain,
        view: &View,
        a: Rotation4,
        width: u32,
        height: u32,
    ) -> Self {
        let shorter = f64::from(width.min(height).max(1));
        let (v1, v2) = (a.row(0), a.row(1));
        let c = domain.center();
        let [px, py] = view.pan;
        Self {
            v1,
            v2,
            n1: a.row(2),
            n2: a.row(3),
            center: std::array::from_fn(|i| c[i] + px * v1[i] + py * v2[i]),
            pixel_size: 2.0 * domain.half_diagonal() / shorter / view.zoom,
            section: Section::of(view),
            slice_start: domain.half_diagonal(),
            mark: view.mark.filter(|_| Section::of(view) == Section::Plane),
            width,
            height,
        }
    }

    /// The ray origin o of pixel (px, py), counted from the top-left (docs/method.md §5.1).
    pub fn origin(&self, px: f64, py: f64) -> [f64; 4] {
        let sx = self.pixel_size * (px + 0.5 - 0.5 * f64::from(self.width));
        let sy = self.pixel_size * (0.5 * f64::from(self.height) - py - 0.5);
        std::array::from_fn(|i| self.center[i] + sx * self.v1[i] + sy * self.v2[i])
    }
}
