//! The structs the ray caster's buffers hold, byte for byte as `templates/raycast.wgsl`
//! declares them (`#[repr(C)]`, 4-byte scalars, vec4 fields at 16-byte offsets);
//! `tests/layout.rs` holds each one's size and offsets to the shader's, as naga lays them out.
//!
//! This module imports nothing of fourfold's: the tree fills the hierarchy's records
//! ([`SphereNode`], [`LevelInfo`], [`NodeBounds`]), the renderer the per-view and per-frame
//! ones ([`BoxRecord`], [`Uniforms`]); what they compute lives with them.
//!
//! The shader reads the settings as `vec4`s (they travel to the fragment stage as flat
//! vectors); here each `vec4` is a struct whose fields name its components.

use bytemuck::{Pod, Zeroable};

/// One node of the flattened sphere hierarchy (binding 1, 24 bytes): its box's centre, the
/// index of the next node after its subtree, and its level and flags in `meta` (bits 0–7
/// the level, [`LEAF_BIT`], [`MARCH_BIT`]). A box's half extents and its sphere's radius
/// depend only on its level, so they live in [`LevelInfo`], not in every node. WGSL names
/// the centre's components `cx`..`cw` and `meta` `info`: a `vec4` would be aligned to 16
/// bytes and make the node 32.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SphereNode {
    pub center: [f32; 4],
    pub skip: u32,
    pub meta: u32,
}

/// Bit of `SphereNode::meta` that marks a leaf.
pub const LEAF_BIT: u32 = 1 << 8;

/// Bit of `SphereNode::meta` that marks a box the ray caster marches whole (its subtree,
/// if any, is not kept).
pub const MARCH_BIT: u32 = 1 << 9;

impl SphereNode {
    pub fn level(&self) -> u32 {
        self.meta & 0xff
    }
    pub fn is_leaf(&self) -> bool {
        self.meta & LEAF_BIT != 0
    }
    pub fn is_marched(&self) -> bool {
        self.meta & MARCH_BIT != 0
    }
}

/// Half extents of a box at one level, padded outward so the f32 box holds the exact one,
/// and the radius of the sphere around it (32 bytes; `Uniforms::levels`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct LevelInfo {
    pub half: [f32; 4],
    pub radius: f32,
    /// Unused (zero): pads the entry to the shader's 32 bytes.
    pub support: [f32; 3],
}

/// Bounds on F's second derivatives ∂²F/∂x_i∂x_j over a box (five vec4): lower and upper
/// bounds of the diagonal (xx, yy, zz, ww), of xy, xz, xw, yz, and in `rest` yw and zw
/// (lower, lower, upper, upper). ±∞ where unbounded.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Curvature {
    pub diag_lo: [f32; 4],
    pub diag_hi: [f32; 4],
    pub off_lo: [f32; 4],
    pub off_hi: [f32; 4],
    pub rest: [f32; 4],
}

/// A node's bounds over its box (binding 4): on |∂F/∂x|..|∂F/∂w|, and on F's second
/// derivatives.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct NodeBounds {
    pub slope: [f32; 4],
    pub curvature: Curvature,
}

/// Bounds on F's second derivative along the rays of a view's observer plane: a ray
/// a·n1 + b·n2 sees d²F/dt² within a²·A + ab·B + b²·C, with A (lower, upper) and B in `ab`,
/// C in `c` (see `Curvature::in_plane`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct PlaneCurvature {
    pub ab: [f32; 4],
    pub c: [f32; 2],
    /// Pads the struct to the shader's 32 bytes.
    pub unused: [f32; 2],
}

/// One box of a view's tile lists (binding 3, 96 bytes): the parts of its pixel test and of
/// its choice of rays that are the same for every pixel, worked out once per view instead
/// of per pixel (the angles cost a pixel more than the rest of a visit).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct BoxRecord {
    /// The centre minus the domain's centre, projected on v1 and v2 (the pixel whose origin
    /// is at offset (sx, sy) along them sees the centre at (a − sx, b − sy)); |q| − r, the
    /// least distance of a hit in the box (q: the centre projected on n1, n2; r: the
    /// sphere's radius), or for a slice the least distance along its ray.
    pub view: [f32; 3],
    /// The level (bits 0–7) and leaf flag (bit 8), as in `SphereNode`.
    pub level: u32,
    /// The angle of q in the observer plane, and the half angle the sphere spans seen from
    /// any pixel's origin, with a margin (−1 where |q| ≤ r: every ray is tried).
    pub angles: [f32; 2],
    /// The box's index in the hierarchy.
    pub node: u32,
    pub unused: u32,
    /// The box's centre.
    pub center: [f32; 4],
    /// Its slope bounds (`Hierarchy::slope`: a ray d sees F change by at most
    /// Σ slope_k·|d_k| per unit length).
    pub slope: [f32; 4],
    /// Its curvature bounds in the observer plane.
    pub form: PlaneCurvature,
}

/// Flag bits of `Control::flags`.
pub const FLAG_LIGHTING: u32 = 1;
pub const FLAG_SILHOUETTE: u32 = 2;
pub const FLAG_BORDER: u32 = 4;
pub const FLAG_RANDOM: u32 = 8;
/// Brute force: the ray caster picks its brute-force pipeline (see `gpu::Mode`).
pub const FLAG_BRUTE_FORCE: u32 = 16;
/// A slab: rays only where the n2 coordinate is within `Root::section_half` of
/// `Root::section_offset`.
pub const FLAG_SLAB: u32 = 32;
/// A slice: one ray per pixel along n1, at `Root::section_offset` along n2.
pub const FLAG_SLICE: u32 = 64;
/// Colour hits by their coordinate along n2 (the viridis map) instead of the surface colour.
pub const FLAG_HIDDEN: u32 = 128;
/// Mark the hits within `Root::section_half` of `Root::section_offset` along n2 (where a
/// slice cuts), in the projection.
pub const FLAG_MARK: u32 = 256;
/// Certify every pixel (docs/method.md §5.9): the shader's certified pipeline reads
/// `March::cert_budget` and the two flags below.
pub const FLAG_CERTIFIED: u32 = 512;
/// Draw undecided pixels hatched (stripes of the marker colour) rather than filled.
pub const FLAG_HATCH: u32 = 1024;
/// F is continuous on the whole domain (`Hierarchy::continuous`).
pub const FLAG_CONTINUOUS: u32 = 2048;
/// A pass blended into a running mean leaves each pixel where it finds no hit as it is (the
/// shader discards it): the plain passes that smooth a certified picture keep what its
/// certified pass proved (a hit the pencil misses, an undecided mark). Cleared by the ray
/// caster for a pass that overwrites.
pub const FLAG_KEEP_MISSES: u32 = 4096;

/// Entries of the per-level table (levels 0..=15).
pub const LEVEL_SLOTS: usize = 16;

/// The Phong terms (WGSL `shading`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Shading {
    pub ambient: f32,
    pub diffuse: f32,
    pub specular: f32,
    pub shininess: f32,
}

/// The pixel's size and how hits are blended and highlighted (WGSL `misc`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Misc {
    /// World units per pixel.
    pub pixel_size: f32,
    /// Weight of the nearer hit.
    pub alpha: f32,
    pub silhouette_tolerance: f32,
    pub border_tolerance: f32,
}

/// The root finding's settings (WGSL `root`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Root {
    /// The bisection stops once |F| is below this.
    pub approximation: f32,
    /// Padding of every box (a level-l box's half extents are `half0 · 2^-l + pad`).
    pub pad: f32,
    /// With `FLAG_SLAB` or `FLAG_SLICE`: the slab's middle or the slice's place along n2,
    /// from the domain's centre, and the slab's half width.
    pub section_offset: f32,
    pub section_half: f32,
}

/// The picture's size, and the rays and hits per pixel (WGSL `size`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Size {
    pub width: u32,
    pub height: u32,
    pub rays: u32,
    /// Hits kept, K (at most 16).
    pub hits: u32,
}

/// How the march runs (WGSL `control`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Control {
    /// Steps per span of a leaf.
    pub steps: u32,
    pub bisection_iters: u32,
    /// `FLAG_*` bits.
    pub flags: u32,
    pub seed: u32,
}

/// Counts and constants (WGSL `counts`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Counts {
    pub nodes: u32,
    /// Frame counter: new ray offsets for progressive refinement.
    pub frame: u32,
    /// The bits of a NaN, which WGSL cannot write as a constant.
    pub nan_bits: u32,
    /// Steps per ray of the brute-force march.
    pub brute_steps: u32,
}

/// The tile lists the caster has bound (WGSL `tiling`), set by the ray caster from them.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Tiling {
    /// Tile side in pixels.
    pub tile: u32,
    pub tiles_per_row: u32,
    /// 1 when lists are bound, else 0.
    pub bound: u32,
    /// Index in binding 2 where the entries start (after the tiles' offsets).
    pub entries_start: u32,
}

/// The tree's finest level (WGSL `march`): a marched box at level l that is not a leaf takes
/// `march_steps(steps, finest − l)` steps per span, the finest leaves' step length.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct March {
    pub finest: u32,
    /// Certified pixels: the most cells of its observer plane a pixel evaluates F over.
    pub cert_budget: u32,
    /// Bit i (of x, then y): parameter i's value is an f32 (not a subnormal), so the
    /// shader's interval of it is that point rather than widened by f32's rounding (a
    /// widened 0 made pow(x, R) at R = 0 every value at x = 0). Here, not beside `params`,
    /// because these two words were free.
    pub exact_params: [u32; 2],
}

/// With `FLAG_HIDDEN`: the coordinates along n2 (from the domain's centre) that the colour
/// map's ends stand for (WGSL `hidden`): those of the manifold's boxes in this view.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Hidden {
    pub lo: f32,
    pub hi: f32,
    pub unused: [f32; 2],
}

/// The frame's settings (binding 0, a read-only storage buffer: see `render::gpu`; 1120
/// bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Uniforms {
    pub v1: [f32; 4],
    pub v2: [f32; 4],
    pub n1: [f32; 4],
    pub n2: [f32; 4],
    /// The domain's centre, the origin of the picture's plane.
    pub center: [f32; 4],
    pub domain_lo: [f32; 4],
    pub domain_hi: [f32; 4],
    /// The light's direction in R⁴, unit length.
    pub light: [f32; 4],
    pub surface: [f32; 4],
    pub background: [f32; 4],
    pub silhouette_color: [f32; 4],
    pub border_color: [f32; 4],
    pub shading: Shading,
    pub misc: Misc,
    pub root: Root,
    pub size: Size,
    pub control: Control,
    pub counts: Counts,
    pub tiling: Tiling,
    /// Half extents of a level-0 box before padding: the shader computes a level's box from
    /// them (see `Hierarchy::base_half`).
    pub half0: [f32; 4],
    pub march: March,
    pub hidden: Hidden,
    /// The certifying tile lists bound (WGSL `cert_tiling`, as `tiling`; see
    /// `RayCaster::set_cert_tiles`).
    pub cert_tiling: Tiling,
    pub levels: [LevelInfo; LEVEL_SLOTS],
    /// The formula's parameters, four to a vec4 (at most 64).
    pub params: [[f32; 4]; 16],
}
