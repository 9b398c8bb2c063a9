//! How a scene, a view and a hierarchy fill the block of per-frame settings the ray caster
//! reads (binding 0; its layout is [`crate::gpu_layout::Uniforms`]).

use bytemuck::Zeroable;

pub use crate::gpu_layout::{
    Control, Counts, FLAG_BORDER, FLAG_BRUTE_FORCE, FLAG_CERTIFIED, FLAG_CONTINUOUS, FLAG_HATCH,
    FLAG_HIDDEN, FLAG_KEEP_MISSES, FLAG_LIGHTING, FLAG_MARK, FLAG_RANDOM, FLAG_SILHOUETTE,
    FLAG_SLAB, FLAG_SLICE, Hidden, LEVEL_SLOTS, March, Misc, Root, Shading, Size, Tiling, Uniforms,
};
use crate::scene::{ColorBy, RenderSettings, Sampling, Undecided};
use crate::tree::{Hierarchy, LevelInfo};

use super::camera::{Camera, Rotation4, Section};
use super::march::march_steps;

/// The coordinates along n2 (from the domain's centre) that the hidden-direction colour map
/// spans: those the manifold's boxes reach in this view, or the domain's half diagonal
/// either way where there are none. Never an empty range.
pub fn hidden_range(
    hierarchy: &Hierarchy,
    domain: &crate::scene::Domain,
    camera: &Camera,
) -> [f64; 2] {
    let reach = domain.half_diagonal();
    let [lo, hi] =
        super::framing::extent_along(hierarchy, domain, camera.n2).unwrap_or([-reach, reach]);
    if hi - lo > 1e-9 * reach {
        [lo, hi]
    } else {
        [lo - 1e-3 * reach, hi + 1e-3 * reach]
    }
}

/// [`hidden_range`] in `scene`'s own view: what a picture's legend for `colour_by =
/// "hidden"` says.
pub fn scene_hidden_range(hierarchy: &Hierarchy, scene: &crate::scene::Scene) -> [f64; 2] {
    let camera = Camera::new(&scene.domain, &scene.view, 1, 1);
    hidden_range(hierarchy, &scene.domain, &camera)
}

/// How close along n2 (in the domain's half diagonals) a hit must be to a slice's place to be
/// marked.
const MARK_WIDTH: f64 = 0.003;

fn v4(a: [f64; 4]) -> [f32; 4] {
    a.map(|v| v as f32)
}

fn rgb(c: [f32; 3]) -> [f32; 4] {
    [c[0], c[1], c[2], 1.0]
}

/// How one frame is drawn beyond the scene's settings.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameOptions {
    /// Frame counter: new ray offsets for progressive refinement.
    pub frame: u32,
    /// March every ray across the whole domain (the benchmark's baseline), with the step
    /// count per unit length that the leaves of `brute_force_level` would use. (With
    /// `RenderSettings::brute_force`, the hierarchy's finest level.)
    pub brute_force_level: Option<u32>,
    /// The view's rotation instead of the one its angles give (an animation's turn).
    pub rotation: Option<Rotation4>,
    /// Rays per pixel instead of the scene's (the viewer's quick passes).
    pub rays: Option<u32>,
    /// Leave the pixels where this pass finds no hit as the target holds them
    /// (`FLAG_KEEP_MISSES`; only a pass blended into a running mean heeds it).
    pub keep_misses: bool,
}

impl Uniforms {
    /// Whether the frame marches every ray across the domain (no tree leaves read).
    pub fn brute_force(&self) -> bool {
        self.control.flags & FLAG_BRUTE_FORCE != 0
    }

    /// Whether the frame certifies every pixel (docs/method.md §5.9).
    pub fn certified(&self) -> bool {
        self.control.flags & FLAG_CERTIFIED != 0
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
        let mut flags = setting_flags(render, hierarchy);
        if options.keep_misses {
            flags |= FLAG_KEEP_MISSES;
        }
        let mut hidden = Hidden::zeroed();
        if render.color_by == ColorBy::Hidden {
            flags |= FLAG_HIDDEN;
            let [lo, hi] = hidden_range(hierarchy, domain, camera);
            (hidden.lo, hidden.hi) = (lo as f32, hi as f32);
        }
        let [section_offset, section_half] = section_fields(camera, domain, &mut flags);
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
        let mut uniforms = Self {
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
            shading: Shading {
                ambient: render.lighting.ambient as f32,
                diffuse: render.lighting.diffuse as f32,
                specular: render.lighting.specular as f32,
                shininess: render.lighting.shininess as f32,
            },
            misc: Misc {
                pixel_size: camera.pixel_size as f32,
                alpha: render.alpha as f32,
                silhouette_tolerance: render.silhouette.tolerance as f32,
                border_tolerance: render.border.tolerance as f32,
            },
            root: Root {
                approximation: render.approximation as f32,
                pad: hierarchy.pad,
                section_offset,
                section_half,
            },
            size: Size {
                width: camera.width,
                height: camera.height,
                rays: render.rays,
                hits: render.hits.min(16),
            },
            control: Control {
                steps: render.steps,
                bisection_iters: render.bisection_iters,
                flags,
                seed: render.seed,
            },
            counts: Counts {
                nodes: hierarchy.nodes.len() as u32,
                frame: options.frame,
                nan_bits: f32::NAN.to_bits(),
                brute_steps,
            },
            tiling: Tiling::zeroed(),
            half0: hierarchy.base_half,
            march: March {
                finest,
                cert_budget: render.cert_budget,
                exact_params: [0; 2],
            },
            hidden,
            cert_tiling: Tiling::zeroed(),
            levels,
            params: [[0.0; 4]; 16],
        };
        uniforms.set_params(params);
        uniforms
    }

    /// The formula's parameter values (at most 64), four to a vec4, and which of them the
    /// shader may take as exact: bit i of `march.exact_params` where parameter i is an f32
    /// that is 0 or normal (a subnormal may be flushed to 0 by a device's arithmetic, so
    /// its interval stays widened).
    pub fn set_params(&mut self, params: &[f64]) {
        self.params = [[0.0; 4]; 16];
        self.march.exact_params = [0; 2];
        for (i, &p) in params.iter().take(64).enumerate() {
            let f = p as f32;
            self.params[i / 4][i % 4] = f;
            if f64::from(f) == p && (f == 0.0 || f.is_normal()) {
                self.march.exact_params[i / 32] |= 1 << (i % 32);
            }
        }
    }
}

/// The flags the render settings and the hierarchy set (the view's are added after).
fn setting_flags(render: &RenderSettings, hierarchy: &Hierarchy) -> u32 {
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
    if render.certified {
        flags |= FLAG_CERTIFIED;
    }
    if render.undecided == Undecided::Hatch {
        flags |= FLAG_HATCH;
    }
    if hierarchy.continuous {
        flags |= FLAG_CONTINUOUS;
    }
    flags
}

/// The section's place and half width along n2 (a slab, a slice, or the mark a projection
/// beside a slice shows), with its flag.
fn section_fields(camera: &Camera, domain: &crate::scene::Domain, flags: &mut u32) -> [f32; 2] {
    match camera.section {
        Section::Plane => match camera.mark {
            Some(c) => {
                *flags |= FLAG_MARK;
                [c as f32, (MARK_WIDTH * domain.half_diagonal()) as f32]
            }
            None => [0.0; 2],
        },
        Section::Slab { center, half } => {
            *flags |= FLAG_SLAB;
            [center as f32, half as f32]
        }
        Section::Slice { offset } => {
            *flags |= FLAG_SLICE;
            [offset as f32, 0.0]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f32 values that are 0 or normal are exact; others, and the 65th on, are not.
    #[test]
    fn a_parameter_is_exact_where_its_value_is_a_normal_f32() {
        let mut params = vec![0.0, -0.0, 1.0, -0.5, 0.1, 1e-40, 1e300, 3.0e38];
        params.resize(40, 0.1);
        params[37] = 2.5;
        let mut uniforms = Uniforms::zeroed();
        uniforms.set_params(&params);
        assert_eq!(uniforms.march.exact_params, [0b1111, 1 << 5]);
        assert_eq!(uniforms.params[9], [0.1, 2.5, 0.1, 0.1]);
        uniforms.set_params(&[1.0; 70]);
        assert_eq!(uniforms.march.exact_params, [u32::MAX; 2]);
        assert_eq!(uniforms.params[15], [1.0; 4]);
    }
}
