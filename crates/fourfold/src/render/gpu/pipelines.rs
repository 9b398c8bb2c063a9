//! The ray caster's pipelines: one per variant of the shader's pipeline constants, so that a
//! pixel runs only its own mode's code (a SIMD rasterizer runs every branch of an `if`), and
//! the colour target they write, overwriting or blending passes into a running mean.

use super::device::TARGET_FORMAT;
use crate::render::view::{FLAG_CERTIFIED, FLAG_RANDOM, FLAG_SLAB, FLAG_SLICE, Uniforms};

/// The colour target a [`RayCaster`](super::RayCaster) draws into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Target {
    pub format: wgpu::TextureFormat,
    /// Blend each pass into the target with a constant weight c: target = c·new + (1−c)·old.
    /// With c = 1/(k+1) on pass k the target holds the running mean of the passes (the
    /// viewer's accumulation); c = 1 overwrites.
    pub accumulate: bool,
}

impl Target {
    /// What `render_rgba` and the CLI use: RGBA8, overwrite.
    pub const OFFSCREEN: Target = Target {
        format: TARGET_FORMAT,
        accumulate: false,
    };
}

/// Where and how one pass draws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pass {
    /// x, y, width, height of the pixels to draw; the rest of the target is kept.
    pub region: Option<[u32; 4]>,
    /// The weight c of this pass when the target accumulates (ignored otherwise).
    pub weight: f64,
}

impl Default for Pass {
    fn default() -> Self {
        Self {
            region: None,
            weight: 1.0,
        }
    }
}

/// Where a pixel's leaves come from: the shader's pipeline constant MODE. Each is its own
/// pipeline, so a pixel runs only its mode's code (a SIMD rasterizer runs every branch).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The brute-force baseline: no hierarchy, the domain as one box.
    BruteForce = 0,
    /// The boxes of the pixel's tile list (the default).
    Tiles = 1,
    /// A walk of the whole sphere hierarchy (when no tile lists are bound).
    Walk = 2,
}

impl Mode {
    /// The shader's entry point for a pixel in this mode, plain or certified: one each, so
    /// that a pipeline's compile meets no other mode's code (a driver inlines every call
    /// before it drops the branches a pipeline constant rules out).
    pub fn entry_point(self, certified: bool) -> &'static str {
        match (self, certified) {
            (Mode::BruteForce, false) => "fs_brute_force",
            (Mode::BruteForce, true) => "fs_brute_force_certified",
            (Mode::Tiles, false) => "fs_tiles",
            (Mode::Tiles, true) => "fs_tiles_certified",
            (Mode::Walk, false) => "fs_walk",
            (Mode::Walk, true) => "fs_walk_certified",
        }
    }
}

/// target = c·new + (1−c)·old, c the blend constant.
pub(super) const ACCUMULATE: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Constant,
        dst_factor: wgpu::BlendFactor::OneMinusConstant,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Constant,
        dst_factor: wgpu::BlendFactor::OneMinusConstant,
        operation: wgpu::BlendOperation::Add,
    },
};

/// The shader's pipeline constant SLOTS, the hit slots it keeps: one pipeline per value.
/// Fewer slots cost less per hit (K = 4 by default).
pub(super) const SLOT_TIERS: [u32; 3] = [4, 8, 16];

/// The index in SLOT_TIERS of the fewest slots that hold `hits` (K).
pub(super) fn slot_tier(hits: u32) -> usize {
    SLOT_TIERS
        .iter()
        .position(|&s| hits <= s)
        .unwrap_or(SLOT_TIERS.len() - 1)
}

/// What a ray-caster pipeline is specialised for, by the shader's pipeline constants and
/// its entry point: each is its own pipeline, so that a pixel runs only its own code (a
/// SIMD rasterizer runs every branch). (Public for the fuzzer, which makes what wgpu makes
/// of the shader for a variant without a GPU.)
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Variant {
    /// MODE: where a pixel's boxes come from.
    mode: Mode,
    /// The index in SLOT_TIERS of SLOTS, the hit slots kept.
    slots: usize,
    /// SAMPLING: the chapter's random rays (1) or stratified ones (0): chosen at run time by
    /// the shader's flag, the random rays' code slowed a stratified frame.
    random: bool,
    /// SECTION: the whole observer plane (0), a slab of it (1) or a slice (2), so that a
    /// whole plane's frame runs no slab or slice code.
    section: u8,
    /// CERTIFY: classify every pixel rigorously (docs/method.md §5.9).
    certified: bool,
}

impl Variant {
    pub(super) const COUNT: usize = 3 * SLOT_TIERS.len() * 2 * 3 * 2;

    /// The variant a caster builds at once: tile lists, with the default settings' hit slots
    /// and sampling, the whole plane, plain.
    pub fn first() -> Self {
        let settings = crate::scene::RenderSettings::default();
        Self {
            mode: Mode::Tiles,
            slots: slot_tier(settings.hits),
            random: settings.sampling == crate::scene::Sampling::Random,
            section: 0,
            certified: false,
        }
    }

    /// The variant in `mode` keeping `hits` hits (SLOTS: the fewest of SLOT_TIERS that hold
    /// them), with random rays or stratified ones, on the whole plane (`section` 0), a slab
    /// (1) or a slice (2), plain or certified.
    pub fn new(mode: Mode, hits: u32, random: bool, section: u8, certified: bool) -> Self {
        Self {
            mode,
            slots: slot_tier(hits),
            random,
            section: section.min(2),
            certified,
        }
    }

    /// The variant that frames of `scene` over `hierarchy` draw with, binned into tile
    /// lists as every picture is (brute force reads none).
    pub(super) fn of_scene(
        scene: &crate::scene::Scene,
        hierarchy: &crate::tree::Hierarchy,
    ) -> Self {
        let options = crate::render::view::FrameOptions::default();
        let (_, uniforms) = crate::render::view::frame(scene, hierarchy, &[], [1, 1], options);
        let mode = if uniforms.brute_force() {
            Mode::BruteForce
        } else {
            Mode::Tiles
        };
        Self::of(mode, &uniforms)
    }

    /// The variant that draws with `uniforms` in `mode`.
    pub(super) fn of(mode: Mode, uniforms: &Uniforms) -> Self {
        Self {
            mode,
            slots: slot_tier(uniforms.size.hits),
            random: uniforms.control.flags & FLAG_RANDOM != 0,
            section: if uniforms.control.flags & FLAG_SLICE != 0 {
                2
            } else {
                u8::from(uniforms.control.flags & FLAG_SLAB != 0)
            },
            certified: uniforms.control.flags & FLAG_CERTIFIED != 0,
        }
    }

    /// The shader's pipeline constants for this variant, by name.
    pub fn constants(self) -> [(&'static str, f64); 5] {
        [
            ("MODE", f64::from(self.mode as u32)),
            ("SLOTS", f64::from(SLOT_TIERS[self.slots])),
            ("SAMPLING", f64::from(u32::from(self.random))),
            ("SECTION", f64::from(self.section)),
            ("CERTIFY", f64::from(u32::from(self.certified))),
        ]
    }

    /// The shader's entry point for this variant's pixels.
    pub fn entry_point(self) -> &'static str {
        self.mode.entry_point(self.certified)
    }

    pub(super) fn index(self) -> usize {
        let sampled = (self.mode as usize * SLOT_TIERS.len() + self.slots) * 2;
        let sectioned = (sampled + usize::from(self.random)) * 3 + usize::from(self.section);
        sectioned * 2 + usize::from(self.certified)
    }
}

/// The ray-caster pipeline of `variant` (through `cache`, where there is one).
pub(super) fn build_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    target: Target,
    variant: Variant,
    cache: Option<&wgpu::PipelineCache>,
) -> wgpu::RenderPipeline {
    fullscreen_pipeline(
        device,
        Fullscreen {
            label: "fourfold ray caster",
            module,
            layout,
            target: color_target(target),
            fragment: variant.entry_point(),
            cache,
        },
        &variant.constants(),
    )
}

/// How a ray caster's pipelines write `target`.
pub(super) fn color_target(target: Target) -> wgpu::ColorTargetState {
    wgpu::ColorTargetState {
        format: target.format,
        blend: target.accumulate.then_some(ACCUMULATE),
        write_mask: wgpu::ColorWrites::ALL,
    }
}

/// A pipeline drawing one triangle over the viewport with `vs_main` (no vertex buffers) and
/// shading it with the entry point `fragment` of `module`.
pub struct Fullscreen<'a> {
    pub label: &'a str,
    pub module: &'a wgpu::ShaderModule,
    pub layout: &'a wgpu::PipelineLayout,
    pub target: wgpu::ColorTargetState,
    pub fragment: &'a str,
    /// Where compiled pipelines are kept between runs, if anywhere.
    pub cache: Option<&'a wgpu::PipelineCache>,
}

/// Builds `pipeline`, given pipeline constants for its fragment stage.
pub fn fullscreen_pipeline(
    device: &wgpu::Device,
    pipeline: Fullscreen<'_>,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    let Fullscreen {
        label,
        module,
        layout,
        target,
        fragment,
        cache,
    } = pipeline;
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..Default::default()
            },
            targets: &[Some(target)],
        }),
        multiview_mask: None,
        cache,
    })
}

/// Binding `binding` of the ray caster: a read-only storage buffer (all of them are), read
/// by the fragment stage, and the settings (binding 0) by the vertex stage too (which hands
/// the most read of them to the fragment stage as flat values).
pub(super) fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    let visibility = if binding == 0 {
        wgpu::ShaderStages::VERTEX_FRAGMENT
    } else {
        wgpu::ShaderStages::FRAGMENT
    };
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}
