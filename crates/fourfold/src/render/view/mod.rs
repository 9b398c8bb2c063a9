//! One view of a scene, on the CPU: the camera (rotation, planes, pixel → R⁴), turning it by
//! a drag, the framing that fits the manifold, the frame's settings block, the march rules
//! both ray casters state, and the per-tile box lists the GPU reads.

mod camera;
mod frame;
pub mod framing;
mod march;
mod rotate;
pub mod tiles;
mod uniforms;

pub use camera::{Camera, Rotation4, Section};
pub use frame::frame;
pub use march::{PLANE_ROOT, march_steps, plane_ray, plane_ray_dir, slope_along};
pub use rotate::rotate_view;
pub use tiles::TileLists;
pub use uniforms::{
    Control, Counts, FLAG_BORDER, FLAG_BRUTE_FORCE, FLAG_CERTIFIED, FLAG_CONTINUOUS, FLAG_HATCH,
    FLAG_HIDDEN, FLAG_KEEP_MISSES, FLAG_LIGHTING, FLAG_MARK, FLAG_RANDOM, FLAG_SILHOUETTE,
    FLAG_SLAB, FLAG_SLICE, FrameOptions, Hidden, LEVEL_SLOTS, March, Misc, Root, Shading, Size,
    Tiling, Uniforms, hidden_range, scene_hidden_range,
};
