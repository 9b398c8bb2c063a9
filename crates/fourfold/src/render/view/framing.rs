//! Framing: the zoom and pan that show the manifold, not the domain, at a view's angles.
//! The tree's boxes enclose M, so the rectangle their projections cover on the screen
//! encloses M's picture; fitting it (with a margin) makes M fill the picture.

use crate::scene::limits::ZOOM;
use crate::scene::{Domain, Scene, View};
use crate::tree::Hierarchy;

use super::camera::Rotation4;

/// The share of the picture's width or height the fitted manifold fills.
const FILL: f64 = 0.9;

/// The rectangle (along v1, then v2, from the domain's centre, world units) that the
/// projections of the hierarchy's finest boxes (its cover) fill through the rotation `a`;
/// None for an empty hierarchy.
pub fn projected_extent(
    hierarchy: &Hierarchy,
    domain: &Domain,
    a: &Rotation4,
) -> Option<[[f64; 2]; 2]> {
    Some([
        extent_along(hierarchy, domain, a.row(0))?,
        extent_along(hierarchy, domain, a.row(1))?,
    ])
}

/// The range of coordinates along the unit vector `v` (from the domain's centre) that the
/// hierarchy's finest boxes reach; None for an empty hierarchy.
pub fn extent_along(hierarchy: &Hierarchy, domain: &Domain, v: [f64; 4]) -> Option<[f64; 2]> {
    let boxes = hierarchy.cover.first().filter(|c| !c.is_empty())?;
    let c = domain.center();
    let mut range = [f64::INFINITY, f64::NEG_INFINITY];
    for b in boxes {
        let half = hierarchy.levels[b.level as usize].half;
        let mid: f64 = (0..4).map(|k| (f64::from(b.center[k]) - c[k]) * v[k]).sum();
        let reach: f64 = (0..4).map(|k| f64::from(half[k]) * v[k].abs()).sum();
        range = [range[0].min(mid - reach), range[1].max(mid + reach)];
    }
    Some(range)
}

/// `view` with the zoom and pan that frame the hierarchy's boxes in a `width`×`height`
/// picture, centred, filling [`FILL`] of the tighter side; the angles are kept. None where
/// there is nothing to frame.
pub fn fit(
    hierarchy: &Hierarchy,
    domain: &Domain,
    view: &View,
    width: u32,
    height: u32,
) -> Option<View> {
    let a = Rotation4::from_angles(view.angles);
    fit_through(hierarchy, domain, view, &[a], width, height)
}

/// Frames the manifold of `hierarchy` in `scene`'s view for a `width`×`height` picture (the
/// view stays as it is where there is nothing to frame).
pub fn fit_scene(scene: &mut Scene, hierarchy: &Hierarchy, width: u32, height: u32) {
    if let Some(view) = fit(hierarchy, &scene.domain, &scene.view, width, height) {
        scene.view = view;
    }
}

/// As [`fit`], for a manifold seen through each of the `rotations` in turn (the frames of
/// an animation): one zoom and pan that frame it in all of them.
pub fn fit_through(
    hierarchy: &Hierarchy,
    domain: &Domain,
    view: &View,
    rotations: &[Rotation4],
    width: u32,
    height: u32,
) -> Option<View> {
    let [[x0, x1], [y0, y1]] = rotations
        .iter()
        .filter_map(|a| projected_extent(hierarchy, domain, a))
        .reduce(|[[a0, a1], [b0, b1]], [[c0, c1], [d0, d1]]| {
            [[a0.min(c0), a1.max(c1)], [b0.min(d0), b1.max(d1)]]
        })?;
    let (w, h) = (f64::from(width.max(1)), f64::from(height.max(1)));
    // World units per pixel that fit the rectangle; at zoom 1 a pixel is
    // 2·half_diagonal / shorter side (see Camera::new).
    let pixel = ((x1 - x0) / w).max((y1 - y0) / h) / FILL;
    let zoom = if pixel > 0.0 {
        2.0 * domain.half_diagonal() / w.min(h) / pixel
    } else {
        *ZOOM.end()
    };
    Some(View {
        zoom: zoom.clamp(*ZOOM.start(), *ZOOM.end()),
        pan: [0.5 * (x0 + x1), 0.5 * (y0 + y1)],
        ..*view
    })
}
