//! The block of per-frame settings the ray caster reads (binding 0, a read-only storage
//! buffer: see `gpu`), laid out exactly as `Uniforms` in `templates/raycast.wgsl` (1088
//! bytes), and how a scene fills it.

use bytemuck::{Pod, Zeroable};

use crate::scene::{RenderSettings, Sampling};
use crate::tree::{Hierarchy, LevelInfo, hierarchy::march_steps};

use super::camera::Camera;

/// Flag bits of `control[2]`.
pub const FLAG_LIGHTING: u32 = 1;
pub const FLAG_SILHOUETTE: u32 = 2;
pub const FLAG_BORDER: u32 = 4;
pub const FLAG_RANDOM: u32 = 8;
/// Brute force: the ray caster picks its brute-force pipeline (see `gpu::Mode`).
pub const FLAG_BRUTE_FORCE: u32 = 16;

/// Entries of the per-level table (levels 0..=15).
pub const LEVEL_SLOTS: usize = 16;

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct Uniforms {
    pub v1: [f32; 4],
    pub v2: [f32; 4],
    pub n1: [f32; 4],
    pub n2: [f32; 4],
    pub center: [f32; 4],
    pub domain_lo: [f32; 4],
    pub domain_hi: [f32; 4],
    pub light: [f32; 4],
    pub surface: [f32; 4],
    pub background: [f32; 4],
    pub silhouette_color: [f32; 4],
    pub border_color: [f32; 4],
    /// ambient, diffuse, specular, shininess
    pub shading: [f32; 4],
    /// pixel size, alpha, silhouette tolerance, border tolerance
    pub misc: [f32; 4],
    /// bisection approximation, box padding
    pub root: [f32; 4],
    /// width, height, rays, hits kept
    pub size: [u32; 4],
    /// steps per span, bisection iterations, flags, seed
    pub control: [u32; 4],
    /// node count, frame, NaN bit pattern, brute-force steps
    pub counts: [u32; 4],
    /// tile side, tiles per row, tile lists bound (0/1), index where the leaf entries start;
    /// set by the ray caster from its tile lists (see `tiles.rs`).
    pub tiling: [u32; 4],
    /// Half extents of a level-0 box before padding (`root[1]` is the padding): the shader
    /// computes a level's box from them (see `Hierarchy::base_half`).
    pub half0: [f32; 4],
    /// The finest level of the tree (a marched box at level l that is not a leaf takes
    /// `march_steps(steps, finest - l)` steps per span: the finest leaves' step length),
    /// unused x3.
    pub march: [u32; 4],
    pub levels: [LevelInfo; LEVEL_SLOTS],
    pub params: [[f32; 4]; 16],
}

fn v4(a: [f64; 4]) -> [f32; 4] {
    a.map(|v| v as f32)
}

fn rgb(c: [f32; 3]) -> [f32; 4] {
    [c[0], c[1], c[2], 1.0]
}

/// How one frame is drawn beyond the scene's settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrameOptions {
    /// Frame counter: new ray offsets for progressive refinement.
    pub frame: u32,
    /// March every ray across the whole domain (the benchmark's baseline), with the step
    /// count per unit length that the leaves of `brute_force_level` would use. (With
    /// `RenderSettings::brute_force`, the hierarchy's finest level.)
    pub brute_force_level: Option<u32>,
}

impl Uniforms {
    /// Whether the frame marches every ray across the domain (no tree leaves read).
    pub fn brute_force(&self) -> bool {
        self.control[2] & FLAG_BRUTE_FORCE != 0
    }

    pub fn new(
        camera: &Camera,
        render: &RenderSettings,
        domain: &crate::scene::Domain,
        hierarchy: &Hierarchy,
        params: &[f64],
        options: FrameOptions,
    ) -> Self {
        let axes = domain.axes();
        let l = render.lighting.direction;
        let light: [f64; 4] = std::array::from_fn(|i| {
            l[0] * camera.v1[i] + l[1] * camera.v2[i] + l[2] * camera.n1[i] + l[3] * camera.n2[i]
        });
        let norm = light.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-12);
        let mut flags = 0;
        if render.lighting.enabled {
            flags |= FLAG_LIGHTING;
        }
        if render.silhouette.enabled {
            flags |= FLAG_SILHOUETTE;
        }
        if render.border.enabled {
            flags |= FLAG_BORDER;
        }
        if render.sampling == Sampling::Random {
            flags |= FLAG_RANDOM;
        }
        let mut brute_steps = 0;
        let finest = hierarchy.finest_level();
        let brute_level = options
            .brute_force_level
            .or(render.brute_force.then_some(finest));
        if let Some(level) = brute_level {
            flags |= FLAG_BRUTE_FORCE;
            // (At most 2^16 steps per ray, so that a fine tree cannot make one frame endless.)
            brute_steps = march_steps(render.steps, level);
        }
        let mut levels = [LevelInfo::zeroed(); LEVEL_SLOTS];
        // (The CPU reference reads this table; the shader computes a level's box from
        // `half0` instead, see templates/raycast.wgsl.)
        for (slot, info) in levels.iter_mut().zip(&hierarchy.levels) {
            *slot = *info;
        }
        let mut packed = [[0f32; 4]; 16];
        for (i, p) in params.iter().take(64).enumerate() {
            packed[i / 4][i % 4] = *p as f32;
        }
        Self {
            v1: v4(camera.v1),
            v2: v4(camera.v2),
            n1: v4(camera.n1),
            n2: v4(camera.n2),
            center: v4(camera.center),
            domain_lo: v4(axes.map(|a| a.lo)),
            domain_hi: v4(axes.map(|a| a.hi)),
            light: v4(light.map(|v| v / norm)),
            surface: rgb(render.lighting.color.to_f32()),
            background: rgb(render.background.to_f32()),
            silhouette_color: rgb(render.silhouette.color.to_f32()),
            border_color: rgb(render.border.color.to_f32()),
            shading: [
                render.lighting.ambient as f32,
                render.lighting.diffuse as f32,
                render.lighting.specular as f32,
                render.lighting.shininess as f32,
            ],
            misc: [
                camera.pixel_size as f32,
                render.alpha as f32,
                render.silhouette.tolerance as f32,
                render.border.tolerance as f32,
            ],
            root: [render.approximation as f32, hierarchy.pad, 0.0, 0.0],
            size: [
                camera.width,
                camera.height,
                render.rays,
                render.hits.min(16),
            ],
            control: [render.steps, render.bisection_iters, flags, render.seed],
            counts: [
                hierarchy.nodes.len() as u32,
                options.frame,
                f32::NAN.to_bits(),
                brute_steps,
            ],
            tiling: [0; 4],
            half0: hierarchy.base_half,
            march: [finest, 0, 0, 0],
            levels,
            params: packed,
        }
    }
}
