//! Every range a user can set, in one place: the scene file's check, the command line's
//! flags, the share links and the viewer's sliders all read these.

use std::ops::RangeInclusive;

/// Levels of the 16-tree (each level multiplies the boxes by up to 16).
pub const TREE_LEVELS: RangeInclusive<u32> = 0..=crate::tree::MAX_LEVEL;
/// Nodes the tree may keep: at least the root's children, at most what a machine's memory
/// holds comfortably (a node costs tens of bytes, in the tree and the hierarchy).
pub const NODE_BUDGET: RangeInclusive<u32> = 16..=100_000_000;
/// Rays per pixel.
pub const RAYS: RangeInclusive<u32> = 1..=1024;
/// Nearest hits kept and blended per pixel.
pub const HITS: RangeInclusive<u32> = 1..=16;
/// March steps per span, and bisection iterations per root.
pub const STEPS: RangeInclusive<u32> = 1..=256;
/// Certified pixels' cells per pixel: within llvmpipe's 65 535 loop iterations per pixel,
/// with the rays'.
pub const CERT_BUDGET: RangeInclusive<u32> = 1..=8192;
/// Certified pixels' default budget of cells per pixel.
pub const DEFAULT_CERT_BUDGET: u32 = 2048;
/// A share between 0 and 1: the nearer hit's weight α, the light's ambient, diffuse and
/// specular parts.
pub const UNIT: RangeInclusive<f64> = 0.0..=1.0;
/// A highlight's tolerance (the silhouette's, or the border's in domain units): any size
/// from 0.
pub const TOLERANCE: RangeInclusive<f64> = 0.0..=f64::MAX;
/// Magnification: 1 shows the whole domain.
pub const ZOOM: RangeInclusive<f64> = 0.01..=100.0;
/// The sides of a picture, in pixels (within the device's own limit too).
pub const PICTURE_SIDE: RangeInclusive<u32> = 1..=8192;
/// The largest picture side.
pub const MAX_PICTURE_SIDE: u32 = *PICTURE_SIDE.end();
/// Levels of a slice's mesh octree: 2^level finest cells along the slice's extent.
pub const MESH_LEVELS: RangeInclusive<u32> = 1..=10;
/// The level a mesh takes unless told: cells about a hundredth of the slice's width.
pub const DEFAULT_MESH_LEVEL: u32 = 7;
/// Cells a mesh's octree may keep at one level (a few hundred bytes each, in all the
/// mesher's tables).
pub const MESH_CELL_BUDGET: usize = 4_000_000;
/// Levels of the critical-value search: its finest boxes are the domain / 2^level.
pub const CRITICAL_LEVELS: RangeInclusive<u32> = 2..=14;
pub const DEFAULT_CRITICAL_LEVEL: u32 = 7;
/// Boxes the critical-value search may look at (a few microseconds each).
pub const CRITICAL_BOX_BUDGET: usize = 1_000_000;
/// Keys a share link may set: far more than a scene has (its settings and a formula's
/// parameters), few enough that checking them one by one stays instant.
pub const LINK_KEYS: usize = 256;
/// Frames of an animation.
pub const FRAMES: RangeInclusive<u32> = 1..=10_000;
/// The most frames per second of an animation's file (any rate above 0 up to it).
pub const MAX_FPS: f64 = 100.0;
/// Full turns of an animation's turn, either way.
pub const TURNS: RangeInclusive<f64> = -100.0..=100.0;
/// A domain bound's magnitude: beyond it f32 positions on the GPU lose the picture.
pub const DOMAIN_BOUND: f64 = 1e6;
/// A parameter's magnitude: f32's largest. F is computed in f32 (on the GPU, and by the CPU
/// twin as the GPU does), where a larger value is ±∞, and WGSL lets a compiler assume no
/// infinity: lavapipe makes 0·a zero where IEEE makes it NaN.
pub const PARAM_BOUND: f64 = f32::MAX as f64;

/// Whether `fps` is a frame rate an animation's file can have: above 0, at most
/// [`MAX_FPS`].
pub fn fps_allowed(fps: f64) -> bool {
    fps > 0.0 && fps <= MAX_FPS
}
