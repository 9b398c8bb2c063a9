//! The one place where a frame's camera and settings are made from a scene: the command
//! line, the exports, animations and the viewer's progressive passes all call [`frame`].

use crate::scene::Scene;
use crate::tree::Hierarchy;

use super::camera::{Camera, Rotation4};
use super::uniforms::{FrameOptions, Uniforms};

/// The camera of `scene`'s view (turned as `options.rotation` says, if it does) in a
/// `width`×`height` picture, and the settings of a frame drawn through it over `hierarchy`
/// with the formula's parameter values `params`.
pub fn frame(
    scene: &Scene,
    hierarchy: &Hierarchy,
    params: &[f64],
    [width, height]: [u32; 2],
    options: FrameOptions,
) -> (Camera, Uniforms) {
    let rotation = options
        .rotation
        .unwrap_or_else(|| Rotation4::from_angles(scene.view.angles));
    let camera = Camera::with_rotation(&scene.domain, &scene.view, rotation, width, height);
    let mut render = scene.render;
    if let Some(rays) = options.rays {
        render.rays = rays;
    }
    let uniforms = Uniforms::new(&camera, &render, &scene.domain, hierarchy, params, options);
    (camera, uniforms)
}
