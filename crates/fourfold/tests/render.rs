//! Code generation and the ray caster: every example's shader validates, GPU and CPU agree,
//! and the glome's picture is the disk an independent computation predicts.
//!
//! GPU tests need an adapter (Mesa's lavapipe in CI). Without one they fail with the
//! adapter error: a missing GPU must not pass silently.

mod common;

use common::{agreement, coverage, example_scenes, example_scenes_named};
use fourfold::CompiledFormula;
use fourfold::headless::render_scene;
use fourfold::render::Device;
use fourfold::render::gpu::Mode;
use fourfold::render::shader;
use fourfold::render::{Camera, Gpu, Rotation4};
use fourfold::scene::{Domain, Scene};

#[test]
fn every_example_scene_generates_valid_wgsl() {
    for (name, scene) in example_scenes() {
        let f = CompiledFormula::compile(&scene.formula).unwrap();
        let shader = shader::generate(&f).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(shader.source.contains("fn ff_f(p: vec4<f32>) -> f32"));
    }
    // Every operation of the language, in one formula.
    let all = "sin(x)+cos(y)+tan(z)+asin(w/9)+acos(x/9)+atan(y)+sinh(z)+cosh(w)+tanh(x)+exp(y)\
               +ln(z)+sqrt(w)+cbrt(x)+|y|+sign(z)+step(w)+min(x,y)+max(z,w)+pow(x,y)+atan2(z,w)\
               +x^7+y^-3+x/y+a";
    shader::generate(&CompiledFormula::compile(all).unwrap()).unwrap();
}

/// Browsers' WGSL compilers reject a constant expression whose value is infinite or NaN
/// ("value inf cannot be represented as 'f32'", Chromium); naga accepts it. So no shader
/// fourfold generates (or exports for users' own WebGPU code) spells one: its infinity and
/// NaN come from the settings buffer at run time. (A proxy for compiling in a browser: no
/// float bit pattern of an infinity or NaN, and no float literal beyond f32's range.)
#[test]
fn generated_shaders_spell_no_infinite_or_nan_constant() {
    // Huge, infinite (exp(1e9), 1e39 in f32) and undefined parts (y/0, sqrt(-1) and ln(0)
    // alone fold to an undefined F, which is refused: here they are undefined in places).
    let all = "exp(x)^9 + 1e30 x - 3.4e38 + exp(1e9) w + 1e39 y + y/(x - 1) + sqrt(-1 - z^2) \
               + ln(0 * w + w^2)";
    let mut formulas: Vec<String> = example_scenes()
        .into_iter()
        .map(|(_, s)| s.formula)
        .collect();
    formulas.push(all.to_string());
    for formula in formulas {
        let f = CompiledFormula::compile(&formula).unwrap();
        let source = shader::generate(&f).unwrap().source.to_lowercase();
        // +inf, -inf and the NaNs have all exponent bits set: 0x7f8…, 0xff8… and above.
        for pattern in ["bitcast<f32>(0x7f", "bitcast<f32>(0xff"] {
            assert!(
                !source.contains(pattern),
                "{formula}: a constant {pattern}… in the shader"
            );
        }
        for literal in
            source.split(|c: char| !(c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '+'))
        {
            if let Ok(v) = literal.trim_end_matches('f').parse::<f64>()
                && literal.chars().next().is_some_and(|c| c.is_ascii_digit())
            {
                assert!(
                    v.abs() <= f64::from(f32::MAX),
                    "{formula}: the literal {literal} is beyond f32"
                );
            }
        }
    }
}

/// Mesa's lavapipe bakes the uniform-buffer values that steer a shader's loops into the
/// shader, and rebuilt the ray caster at every pass (4-5 ms a pass, see src/render/gpu.rs):
/// the frame's settings must stay in a storage buffer, with binding 0 as the header says.
#[test]
fn the_ray_caster_reads_no_uniform_buffer() {
    // A formula's own shader reads bindings 0-6 and its constants (7); the interpreting
    // one its program (7).
    let f = CompiledFormula::compile("x^2 + y^2 + z^2 + w^2 = 1").unwrap();
    let all = fourfold::render::gpu::STORAGE_BUFFERS;
    for (shader, count) in [
        (shader::generate(&f).unwrap(), all),
        (shader::interpreter().unwrap(), all),
    ] {
        let mut bindings = Vec::new();
        for (_, var) in shader.module.global_variables.iter() {
            assert_ne!(
                var.space,
                naga::AddressSpace::Uniform,
                "{:?} is a uniform buffer",
                var.name
            );
            if let Some(b) = &var.binding {
                assert!(
                    matches!(var.space, naga::AddressSpace::Storage { .. }),
                    "{:?}",
                    var.name
                );
                bindings.push(b.binding);
            }
        }
        bindings.sort_unstable();
        assert_eq!(bindings, (0..count).collect::<Vec<_>>());
        assert!(
            shader.source.contains("binding 0: storage  Uniforms"),
            "the header documents binding 0"
        );
    }
}

/// llvmpipe loads a storage buffer word per pixel in a fragment shader, so the ray caster
/// reads its settings (binding 0) once, into a private copy (start_pixel, which every
/// pixel's entry point calls first), and its functions read that.
#[test]
fn the_ray_caster_reads_its_settings_once() {
    let f = CompiledFormula::compile("x^2 + y^2 + z^2 + w^2 - R^2").unwrap();
    let shader = shader::generate(&f).unwrap();
    let module = &shader.module;
    let (settings, _) = module
        .global_variables
        .iter()
        .find(|(_, v)| v.binding.as_ref().is_some_and(|b| b.binding == 0))
        .expect("binding 0");
    let reads = |fun: &naga::Function| {
        fun.expressions
            .iter()
            .filter(|(_, e)| matches!(e, naga::Expression::GlobalVariable(g) if *g == settings))
            .count()
    };
    for (_, fun) in module.functions.iter() {
        let once = fun.name.as_deref() == Some("start_pixel");
        assert_eq!(
            reads(fun),
            usize::from(once),
            "{:?} reads binding 0",
            fun.name
        );
    }
    let modes = [Mode::BruteForce, Mode::Tiles, Mode::Walk];
    for name in modes
        .iter()
        .flat_map(|m| [m.entry_point(false), m.entry_point(true)])
    {
        let main = module.entry_points.iter().find(|e| e.name == name).unwrap();
        assert_eq!(
            reads(&main.function),
            0,
            "{name} leaves binding 0 to start_pixel"
        );
    }
}

#[test]
fn wgsl_snapshots_of_small_formulas() {
    for text in ["x^2 + y^2 + z^2 + w^2 = 1", "sqrt(x) - R y^5"] {
        let f = CompiledFormula::compile(text).unwrap();
        let shader = shader::generate(&f).unwrap();
        // The point functions, then (after the interval library) the interval ones.
        insta::assert_snapshot!(point_functions(&shader.source).trim().to_string());
        let boxed = shader.source.find("fn ff_f_box").unwrap();
        let end = shader.source.find("fn pcg").unwrap();
        insta::assert_snapshot!(shader.source[boxed..end].trim().to_string());
    }
}

/// The shader's point functions of F and ∇F: from `ff_f` to the interval library.
fn point_functions(source: &str) -> &str {
    let start = source.find("fn ff_f").unwrap();
    let library = source.find("// fourfold's rigorous interval").unwrap();
    &source[start..library]
}

/// The undefined flags of F's point functions join with `|`: `||` short-circuits, a branch
/// in naga's and the browsers' output for every flag of every copy of F, and SwiftShader's
/// compile time grows superlinearly with branches (docs/benchmarks.md).
#[test]
fn undefined_flags_join_without_branches() {
    let f = CompiledFormula::compile("sqrt(x) / ln(y) + sqrt(z - w) - 1").unwrap();
    let shader = shader::generate(&f).unwrap();
    let point = point_functions(&shader.source);
    assert!(point.contains(" | ff_undefined("), "{point}");
    assert!(!point.contains("||"), "{point}");
}

#[test]
fn rotation_rows_are_orthonormal_and_identity_at_zero() {
    let a = Rotation4::from_angles([0.0; 6]);
    assert_eq!(a.row(0), [1.0, 0.0, 0.0, 0.0]);
    let a = Rotation4::from_angles([0.3, 1.1, -0.7, 2.0, 0.5, -1.3]);
    for i in 0..4 {
        for j in 0..4 {
            let d: f64 = (0..4).map(|k| a.row(i)[k] * a.row(j)[k]).sum();
            assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
        }
    }
}

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"))
}

fn small(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    s.tree.max_level = s.tree.max_level.min(5);
    s.tree.min_level = s.tree.min_level.min(4);
    s.render.rays = s.render.rays.min(12);
    // These tests are of the ray pencil (certified pixels: tests/certified.rs).
    s.render.certified = false;
    s
}

#[test]
fn gpu_and_cpu_renders_agree() {
    let gpu = gpu();
    let names = ["glome", "fig-3-9-left", "tiger", "hyperplane"];
    for (name, scene) in example_scenes_named(&names) {
        let scene = small(&scene);
        let g = render_scene(&scene, 48, 48, Device::Gpu(&gpu), Default::default()).unwrap();
        let c = render_scene(&scene, 48, 48, Device::Cpu, Default::default()).unwrap();
        let (fraction, same_cover) = agreement(&g.rgba, &c.rgba, scene.render.background.0, 12);
        eprintln!("{name}: colour {fraction:.3}, coverage {same_cover:.3}");
        // Which pixels show M must agree; colours may differ where F's f32 (GPU) and f64
        // (CPU) values put a root on different sides of another ray's, so a different set
        // of K hits is blended.
        assert!(
            same_cover >= 0.99,
            "{name}: coverage agrees on {:.1}%",
            same_cover * 100.0
        );
        assert!(
            fraction >= 0.90,
            "{name}: only {:.1}% of colours agree",
            fraction * 100.0
        );
    }
}

#[test]
fn every_hit_slot_pipeline_agrees_with_the_cpu() {
    // The GPU keeps 4, 8 or 16 hit slots (the pipeline constant SLOTS, the fewest that hold
    // K): K across the tiers, against the CPU reference, which keeps K in a list.
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["fig-3-9-left", "tiger"]) {
        let mut scene = small(&scene);
        scene.render.rays = 16;
        // Far hits weigh more with a lower alpha: K shows in the picture.
        scene.render.alpha = 0.3;
        let differ = |a: &[u8], b: &[u8]| {
            let (close, _) = agreement(a, b, scene.render.background.0, 12);
            ((1.0 - close) * 1600.0).round() as usize
        };
        let mut four = Vec::new();
        for hits in [1, 4, 6, 8, 11, 16] {
            scene.render.hits = hits;
            let g = render_scene(&scene, 40, 40, Device::Gpu(&gpu), Default::default()).unwrap();
            let c = render_scene(&scene, 40, 40, Device::Cpu, Default::default()).unwrap();
            let (close, cover) = agreement(&g.rgba, &c.rgba, scene.render.background.0, 12);
            eprintln!("{name}, K = {hits}: colour {close:.3}, coverage {cover:.3}");
            assert!(
                cover >= 0.99 && close >= 0.90,
                "{name}, K = {hits}: colour {close}, coverage {cover}"
            );
            if hits == 4 {
                four = c.rgba;
            } else if hits > 4 {
                // A GPU that kept only 4 hits would differ from the CPU where K = 4 does.
                let (gpu_off, k_shows) = (differ(&g.rgba, &c.rgba), differ(&four, &c.rgba));
                eprintln!("{name}, K = {hits}: {gpu_off} pixels off, K = 4 changes {k_shows}");
                assert!(k_shows > 0 && gpu_off * 2 < k_shows, "{name}, K = {hits}");
            }
        }
    }
}

#[test]
fn both_samplings_agree_with_the_cpu() {
    // Each sampling has its own pipeline (the constant SAMPLING): the GPU's picture with
    // each must be the CPU's with the same sampling, and the two must differ, so that a
    // pipeline drawing the other sampling's rays fails. Roots are refined until f32 cannot
    // split their brackets: the shader bisects and the twin takes secant steps, so at the
    // default tolerance their roots differ within it, and the glome's hits, many of which
    // lie that close together, come in another order.
    use fourfold::scene::Sampling;
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["fig-3-9-left", "glome"]) {
        let mut scene = small(&scene);
        scene.render.rays = 6;
        scene.render.approximation = 0.0;
        scene.render.bisection_iters = 64;
        let mut cpu = Vec::new();
        for sampling in [Sampling::Stratified, Sampling::Random] {
            scene.render.sampling = sampling;
            let g = render_scene(&scene, 40, 40, Device::Gpu(&gpu), Default::default()).unwrap();
            let c = render_scene(&scene, 40, 40, Device::Cpu, Default::default()).unwrap();
            let (close, cover) = agreement(&g.rgba, &c.rgba, scene.render.background.0, 12);
            eprintln!("{name}, {sampling:?}: colour {close:.3}, coverage {cover:.3}");
            assert!(
                cover >= 0.99 && close >= 0.90,
                "{name}, {sampling:?}: colour {close}, coverage {cover}"
            );
            cpu.push((g.rgba, c.rgba));
        }
        let (strat, random) = (&cpu[0], &cpu[1]);
        let samplings_differ = differing(&strat.1, &random.1);
        let gpu_off = differing(&random.0, &random.1);
        eprintln!("{name}: the samplings differ in {samplings_differ} pixels, GPU off {gpu_off}");
        assert!(samplings_differ > 4 * gpu_off.max(1), "{name}");
    }
}

/// What a GPU test draws `scene` with: its parameter values, its shader and its default
/// hierarchy.
fn caster_inputs(scene: &Scene) -> (Vec<f64>, shader::Shader, fourfold::tree::Hierarchy) {
    let (formula, params, tree) = common::build(scene, scene.tree.into());
    let shader = shader::generate(&formula).unwrap();
    let h = fourfold::tree::Hierarchy::for_formula(&tree, &formula, &params);
    (params, shader, h)
}

/// Frame 0 of `scene` seen by `camera` (by brute force at `brute_force_level`, if given).
fn frame_uniforms(
    scene: &Scene,
    camera: &Camera,
    h: &fourfold::tree::Hierarchy,
    params: &[f64],
    brute_force_level: Option<u32>,
) -> fourfold::render::Uniforms {
    let options = fourfold::render::FrameOptions {
        frame: 0,
        brute_force_level,
        ..Default::default()
    };
    fourfold::render::Uniforms::new(camera, &scene.render, &scene.domain, h, params, options)
}

/// How many pixels (RGBA8) of two pictures differ.
fn differing(a: &[u8], b: &[u8]) -> usize {
    a.chunks(4).zip(b.chunks(4)).filter(|(x, y)| x != y).count()
}

#[test]
fn a_caster_reused_across_views_draws_what_a_fresh_one_draws() {
    // A view's tile lists and box records are written into the caster's buffers in place
    // (they grow when too small): what a view leaves behind must not show in the next.
    // Views alternate between many entries (a large picture) and few (a small one, at
    // other angles), on the tiger (many marched boxes) and the chapter's scene (one).
    use fourfold::render::{RayCaster, TileLists};
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["tiger", "fig-3-9-left"]) {
        let scene = small(&scene);
        let (params, shader, h) = caster_inputs(&scene);
        let mut reused = RayCaster::new(&gpu, &shader, &h).unwrap();
        let mut turned = scene.view;
        turned.angles = [0.3, 1.1, 0.4, 0.9, 0.2, 0.6];
        let mut entries = Vec::new();
        for (view, size) in [
            (scene.view, 96),
            (turned, 24),
            (scene.view, 40),
            (turned, 96),
        ] {
            let camera = Camera::new(&scene.domain, &view, size, size);
            let lists = TileLists::build_within(&h, &camera, gpu.tile_entry_budget());
            entries.push(lists.entries());
            let uniforms = frame_uniforms(&scene, &camera, &h, &params, None);
            reused.set_tiles(&gpu, Some(&lists));
            let mut fresh = RayCaster::new(&gpu, &shader, &h).unwrap();
            fresh.set_tiles(&gpu, Some(&lists));
            let a = reused.render_rgba(&gpu, &uniforms).unwrap();
            let b = fresh.render_rgba(&gpu, &uniforms).unwrap();
            let differ = differing(&a, &b);
            assert_eq!(differ, 0, "{name}, {size}²: {differ} pixels differ");
            assert!(
                b.chunks(4).any(|p| p[..3] != scene.render.background.0),
                "{name}, {size}²: nothing drawn"
            );
        }
        eprintln!("{name}: entries per view {entries:?}");
        assert!(
            entries[0] > entries[1] && entries[3] > entries[2],
            "{entries:?}"
        );

        // A new hierarchy for the same shader (parameters moved, as the viewer's sliders
        // do): the reused caster must read the new nodes (the walk) and bounds (steeper
        // here: old ones would step over roots).
        let mut moved = scene.clone();
        for v in moved.params.values_mut() {
            *v *= 1.5;
        }
        let (params, _, h) = caster_inputs(&moved);
        reused.set_hierarchy(&gpu, &h).unwrap();
        let camera = Camera::new(&moved.domain, &moved.view, 64, 64);
        let lists = TileLists::build_within(&h, &camera, gpu.tile_entry_budget());
        let uniforms = frame_uniforms(&moved, &camera, &h, &params, None);
        let mut fresh = RayCaster::new(&gpu, &shader, &h).unwrap();
        for lists in [None, Some(&lists)] {
            reused.set_tiles(&gpu, lists);
            fresh.set_tiles(&gpu, lists);
            let a = reused.render_rgba(&gpu, &uniforms).unwrap();
            let b = fresh.render_rgba(&gpu, &uniforms).unwrap();
            let differ = differing(&a, &b);
            let how = if lists.is_some() { "tiles" } else { "walk" };
            assert_eq!(
                differ, 0,
                "{name}, new hierarchy, {how}: {differ} pixels differ"
            );
        }
    }
}

#[test]
fn passes_in_regions_blended_into_a_target_draw_the_offscreen_picture() {
    // The viewer's way: a target that holds the running mean of passes, each pass drawn
    // in strips (regions). A first pass (weight 1) must set every pixel, background
    // included, whatever the target held; a second pass of the same frame (weight 1/2)
    // must leave the mean as it was. Against the offscreen picture of the same frame.
    use fourfold::render::{Pass, RayCaster, Target, TileLists};
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["fig-3-9-left", "tiger"]) {
        let scene = small(&scene);
        let (params, shader, h) = caster_inputs(&scene);
        let (w, ht) = (72, 56);
        let camera = Camera::new(&scene.domain, &scene.view, w, ht);
        let lists = TileLists::build_within(&h, &camera, gpu.tile_entry_budget());
        let mut offscreen = RayCaster::new(&gpu, &shader, &h).unwrap();
        offscreen.set_tiles(&gpu, Some(&lists));
        let target = Target {
            format: wgpu::TextureFormat::Rgba8Unorm,
            accumulate: true,
        };
        let mut caster = RayCaster::with_target(&gpu, &shader, &h, target).unwrap();
        caster.set_tiles(&gpu, Some(&lists));
        for brute_force_level in [None, Some(scene.tree.max_level)] {
            let uniforms = frame_uniforms(&scene, &camera, &h, &params, brute_force_level);
            let expected = offscreen.render_rgba(&gpu, &uniforms).unwrap();
            let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
            let texture = caster.target_texture(&gpu, w, ht, usage);
            let view = texture.create_view(&Default::default());
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: 1.0,
                            g: 0.0,
                            b: 1.0,
                            a: 1.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            gpu.queue.submit([encoder.finish()]);
            for weight in [1.0, 0.5] {
                for y in (0..ht).step_by(16) {
                    let mut encoder = gpu.device.create_command_encoder(&Default::default());
                    let pass = Pass {
                        region: Some([0, y, w, 16]),
                        weight,
                    };
                    caster.encode_pass(&gpu, &mut encoder, &view, &uniforms, pass);
                    gpu.queue.submit([encoder.finish()]);
                }
            }
            let got = common::read_texture(&gpu, &texture);
            let off = got
                .chunks(4)
                .zip(expected.chunks(4))
                .filter(|(a, b)| {
                    a.iter()
                        .zip(b.iter())
                        .take(3)
                        .any(|(x, y)| x.abs_diff(*y) > 1)
                })
                .count();
            assert_eq!(
                off,
                0,
                "{name}, brute force {brute_force_level:?}: {off} of {} pixels differ",
                w * ht
            );
        }
    }
}

#[test]
fn brute_force_setting_draws_the_same_picture() {
    // render.brute_force (--brute-force, the viewer's checkbox): every ray marched across the
    // domain with the finest leaves' step, on the GPU and on the CPU.
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["fig-3-9-left", "duocylinder"]) {
        let scene = small(&scene);
        let mut brute = scene.clone();
        brute.render.brute_force = true;
        // The setting reaches the shader: the brute-force flag, and the finest leaves' step.
        let (_, params, tree) = common::build(&brute, brute.tree.into());
        let h = fourfold::tree::Hierarchy::from_tree(&tree);
        let camera = Camera::new(&brute.domain, &brute.view, 40, 40);
        let u = fourfold::render::Uniforms::new(
            &camera,
            &brute.render,
            &brute.domain,
            &h,
            &params,
            Default::default(),
        );
        let finest = h.finest_level();
        assert_ne!(
            u.control.flags & fourfold::render::view::FLAG_BRUTE_FORCE,
            0
        );
        assert_eq!(u.counts.brute_steps, brute.render.steps << finest);
        let tiles = render_scene(&scene, 40, 40, Device::Gpu(&gpu), Default::default()).unwrap();
        for device in [Device::Gpu(&gpu), Device::Cpu] {
            let b = render_scene(&brute, 40, 40, device, Default::default()).unwrap();
            let (close, same_cover) =
                agreement(&tiles.rgba, &b.rgba, scene.render.background.0, 16);
            eprintln!("{name}: colour {close:.3}, coverage {same_cover:.3}");
            assert!(
                same_cover >= 0.99,
                "{name}: coverage agrees on {same_cover}"
            );
            assert!(close >= 0.90, "{name}: colours agree on {close}");
        }
    }
}

#[test]
fn marching_coarser_boxes_draws_the_leaves_picture() {
    // The ray caster marches the nodes a level above the finest leaves, or coarser ones
    // where the slope bounds allow, at the finest leaves' step: the same picture as marching
    // the leaves, on the GPU (tile lists and the walk of the hierarchy) and on the CPU.
    use fourfold::render::{FrameOptions, RayCaster, TileLists, Uniforms, twin};
    use fourfold::tree::{Hierarchy, hierarchy::MARCH_LEVELS_ABOVE_FINEST};
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["glome", "fig-3-9-left", "tiger"]) {
        let mut scene = small(&scene);
        scene.tree.min_level = 5;
        let (formula, params, tree) = common::build(&scene, scene.tree.into());
        let shader = shader::generate(&formula).unwrap();
        let h = Hierarchy::from_tree(&tree);
        let finest = h.finest_level();
        assert_eq!(h.march_level, finest - MARCH_LEVELS_ABOVE_FINEST);
        let leaves = Hierarchy::from_tree_at(&tree, finest);
        assert!(
            h.march_boxes() * 4 < leaves.march_boxes(),
            "{name}: {} boxes against {} leaves",
            h.march_boxes(),
            leaves.march_boxes()
        );
        // The default cut, coarser where the slope bounds allow, with the slope skip.
        let adaptive = Hierarchy::for_formula(&tree, &formula, &params);
        let camera = Camera::new(&scene.domain, &scene.view, 48, 48);
        let mut pictures = Vec::new();
        for h in [&leaves, &h, &adaptive] {
            let u = Uniforms::new(
                &camera,
                &scene.render,
                &scene.domain,
                h,
                &params,
                FrameOptions::default(),
            );
            let mut caster = RayCaster::new(&gpu, &shader, h).unwrap();
            caster.set_tiles(&gpu, Some(&TileLists::build(h, &camera)));
            let tiles = caster.render_rgba(&gpu, &u).unwrap();
            caster.set_tiles(&gpu, None);
            let walk = caster.render_rgba(&gpu, &u).unwrap();
            let reference = twin::render_rgba(&formula, &params, h, None, &u);
            for (what, picture) in [("tiles", &tiles), ("walk", &walk)] {
                let (close, cover) = agreement(picture, &reference, scene.render.background.0, 12);
                eprintln!(
                    "{name} march level {}: {what} vs CPU {close:.3} {cover:.3}",
                    h.march_level
                );
                assert!(
                    cover >= 0.99 && close >= 0.90,
                    "{name}: {what} vs CPU: {close} {cover}"
                );
            }
            pictures.push(reference);
        }
        for (what, picture) in [
            ("coarser boxes", &pictures[1]),
            ("the default cut", &pictures[2]),
        ] {
            let (close, cover) = agreement(&pictures[0], picture, scene.render.background.0, 16);
            eprintln!("{name}: leaves vs {what} {close:.3} {cover:.3}");
            assert!(
                cover >= 0.98 && close >= 0.90,
                "{name}: leaves vs {what}: colour {close}, coverage {cover}"
            );
        }
    }
}

#[test]
fn stepping_over_samples_by_slope_and_curvature_bounds_draws_the_same_picture() {
    // With slope and curvature bounds the march skips samples that cannot change sign: the
    // roots found, and so the picture, must be those of the plain march (the same sign
    // changes of the same samples), pixel for pixel but for f32 ties; on the GPU and on the
    // CPU; with both bounds and with the curvature alone.
    use fourfold::render::{FrameOptions, RayCaster, TileLists, Uniforms, twin};
    use fourfold::tree::Hierarchy;
    let gpu = gpu();
    for (name, scene) in
        example_scenes_named(&["glome", "fig-3-11", "tiger", "duocylinder", "fig-3-9-left"])
    {
        let mut scene = small(&scene);
        scene.tree.min_level = 5;
        let (formula, params, tree) = common::build(&scene, scene.tree.into());
        let shader = shader::generate(&formula).unwrap();
        let mut h = Hierarchy::from_tree(&tree);
        h.bound_slopes(&formula, &params);
        let bounded = h
            .slopes
            .iter()
            .filter(|s| s.iter().all(|v| v.is_finite()))
            .count();
        assert!(
            bounded * 2 > h.nodes.len(),
            "{name}: {bounded} of {} bounded",
            h.nodes.len()
        );
        let marched = h.nodes.iter().filter(|n| n.is_marched()).count();
        let bent = h.curvature.iter().filter(|c| c.is_bounded()).count();
        assert!(
            bent * 2 > marched && bent <= marched,
            "{name}: {bent} of {marched} marched boxes with curvature bounds"
        );
        let camera = Camera::new(&scene.domain, &scene.view, 64, 64);
        let u = Uniforms::new(
            &camera,
            &scene.render,
            &scene.domain,
            &h,
            &params,
            FrameOptions::default(),
        );
        // Tile lists (records) and the walk (node slopes), on the GPU; the CPU reference.
        let mut caster = RayCaster::new(&gpu, &shader, &h).unwrap();
        let mut draw = |h: &Hierarchy| {
            caster.set_hierarchy(&gpu, h).unwrap();
            caster.set_tiles(&gpu, Some(&TileLists::build(h, &camera)));
            let tiles = caster.render_rgba(&gpu, &u).unwrap();
            caster.set_tiles(&gpu, None);
            let walk = caster.render_rgba(&gpu, &u).unwrap();
            [
                tiles,
                walk,
                twin::render_rgba(&formula, &params, h, None, &u),
            ]
        };
        let skipping = draw(&h);
        h.slopes.clear();
        let bending = draw(&h);
        h.curvature.clear();
        let plain = draw(&h);
        let covered = coverage(&plain[0], scene.render.background.0)
            .iter()
            .filter(|c| **c)
            .count();
        let both = ["tiles", "walk", "CPU"]
            .iter()
            .zip(skipping.iter().zip(&plain));
        let bend = [
            "tiles, curvature only",
            "walk, curvature only",
            "CPU, curvature only",
        ]
        .iter()
        .zip(bending.iter().zip(&plain));
        for (what, (a, b)) in both.chain(bend) {
            let same = a.chunks(4).zip(b.chunks(4)).filter(|(x, y)| x == y).count();
            eprintln!(
                "{name} {what}: {same} of {} pixels the same, {covered} covered",
                64 * 64
            );
            assert!(
                same * 1000 >= 999 * 64 * 64,
                "{name} {what}: {same} of {} pixels the same",
                64 * 64
            );
        }
        assert!(
            covered > 64 * 64 / 20,
            "{name}: too little on screen to tell"
        );
    }
}

/// The pixels of a size² picture's coverage that contradict a disk about its centre: not
/// covered within `inner` pixels of the centre, or covered beyond `outer`.
fn off_disk(covered: &[bool], size: u32, inner: f64, outer: f64) -> usize {
    let mid = 0.5 * f64::from(size);
    (0..size * size)
        .filter(|&i| {
            let (px, py) = (i % size, i / size);
            let (dx, dy) = (f64::from(px) + 0.5 - mid, f64::from(py) + 0.5 - mid);
            let r = dx.hypot(dy);
            let c = covered[i as usize];
            (r < inner && !c) || (r > outer && c)
        })
        .count()
}

/// The unit glome in [-1.5, 1.5]⁴, refined uniformly to level 5.
fn unit_glome() -> Scene {
    let mut scene = Scene::from_formula("x^2 + y^2 + z^2 + w^2 = 1");
    scene.domain = Domain::parse_list("-1.5,1.5,-1.5,1.5,-1.5,1.5,-1.5,1.5").unwrap();
    scene.tree.max_level = 5;
    scene.tree.min_level = 5;
    scene
}

#[test]
fn the_glome_covers_exactly_its_disk_at_any_angles() {
    let gpu = gpu();
    let mut scene = unit_glome();
    scene.render.rays = 16;
    let size = 64;
    for angles in [[0.0; 6], [0.4, 1.2, -0.8, 0.3, 2.0, -1.1]] {
        scene.view.angles = angles;
        let picture =
            render_scene(&scene, size, size, Device::Gpu(&gpu), Default::default()).unwrap();
        let covered = coverage(&picture.rgba, scene.render.background.0);
        // Independent: the projection of S³ onto any plane through its centre is the unit disk.
        let camera = Camera::new(&scene.domain, &scene.view, size, size);
        let radius_px = 1.0 / camera.pixel_size;
        let wrong = off_disk(&covered, size, radius_px - 1.0, radius_px + 1.0);
        assert_eq!(wrong, 0, "{wrong} pixels off the disk at angles {angles:?}");
    }
}

/// Pixels whose whole observer plane meets M, by brute force on the CPU: the plane
/// o + a·n1 + b·n2 sampled on a 201×201 grid over the domain's extent, a pixel counting as
/// covered where F changes sign between neighbouring samples inside the domain.
fn plane_coverage(scene: &Scene, size: u32) -> Vec<bool> {
    use fourfold::eval::PointEvaluator;
    use rayon::prelude::*;
    let f = CompiledFormula::compile(&scene.formula).unwrap();
    let params = scene.param_values(&f.param_names());
    let camera = Camera::new(&scene.domain, &scene.view, size, size);
    let axes = scene.domain.axes();
    let extent = scene.domain.half_diagonal();
    const N: usize = 201;
    (0..size * size)
        .into_par_iter()
        .map_init(PointEvaluator::new, |eval, i| {
            let o = camera.origin(f64::from(i % size), f64::from(i / size));
            let mut row_prev: Vec<Option<f64>> = vec![None; N];
            for ia in 0..N {
                let a = -extent + 2.0 * extent * ia as f64 / (N - 1) as f64;
                let mut left: Option<f64> = None;
                for ib in 0..N {
                    let b = -extent + 2.0 * extent * ib as f64 / (N - 1) as f64;
                    let p: [f64; 4] =
                        std::array::from_fn(|k| o[k] + a * camera.n1[k] + b * camera.n2[k]);
                    let inside = (0..4).all(|k| axes[k].lo <= p[k] && p[k] <= axes[k].hi);
                    let v = if inside {
                        Some(eval.eval(&f.tape_f, p, &params)).filter(|v| v.is_finite())
                    } else {
                        None
                    };
                    let changes =
                        |u: Option<f64>| matches!((u, v), (Some(x), Some(y)) if x * y <= 0.0);
                    if changes(left) || changes(row_prev[ib]) {
                        return true;
                    }
                    left = v;
                    row_prev[ib] = v;
                }
            }
            false
        })
        .collect()
}

#[test]
fn coverage_grows_with_rays_towards_the_whole_plane_check() {
    let gpu = gpu();
    let (_, scene) = example_scenes()
        .into_iter()
        .find(|(n, _)| *n == "fig-3-9-left")
        .unwrap();
    let mut scene = small(&scene);
    // A coarser tree keeps the test quick (and each pixel's work under llvmpipe's loop cap).
    scene.tree.max_level = 4;
    scene.tree.min_level = 3;
    scene.render.silhouette.enabled = false;
    scene.render.border.enabled = false;
    let size = 48;
    let truth = plane_coverage(&scene, size);
    let covered_truth = truth.iter().filter(|c| **c).count();
    assert!(
        covered_truth > 100,
        "the scene should cover part of the picture"
    );
    let mut found = Vec::new();
    eprintln!("rays  detected  shown-not-on-M  pixels-cut-by-driver  missed-and-not-flagged");
    for rays in [1, 2, 4, 8, 16, 32, 64] {
        scene.render.rays = rays;
        let g = render_scene(&scene, size, size, Device::Gpu(&gpu), Default::default()).unwrap();
        let c = coverage(&g.rgba, scene.render.background.0);
        // Pixels whose loops the driver cut short are flagged (see fs_main).
        let mut flagged = vec![false; (size * size) as usize];
        for &i in &g.cut_pixels {
            flagged[i] = true;
        }
        let detected =
            c.iter().zip(&truth).filter(|(g, t)| **g && **t).count() as f64 / covered_truth as f64;
        let false_pos =
            c.iter().zip(&truth).filter(|(g, t)| **g && !**t).count() as f64 / (size * size) as f64;
        let cut = flagged.iter().filter(|f| **f).count();
        let unexplained = (0..c.len())
            .filter(|&i| truth[i] && !c[i] && !flagged[i])
            .count();
        eprintln!(
            "{rays:>4}  {:>7.1}%  {:>7.1}%  {cut:>6}  {unexplained:>6}",
            100.0 * detected,
            100.0 * false_pos
        );
        // A pixel the rays show must really meet M (up to the grid's resolution).
        assert!(
            false_pos <= 0.01,
            "{rays} rays: {:.1}% shown but not on M",
            100.0 * false_pos
        );
        found.push((detected, unexplained));
    }
    // More rays find more of the plane's intersection with M (32 rays nearly all of it), and
    // what the rays miss at 64 rays is only where the driver cut the work, which is flagged.
    assert!(
        found[5].0 >= found[2].0,
        "coverage fell from 4 to 32 rays: {found:?}"
    );
    assert!(
        found[5].0 >= 0.97,
        "32 rays find only {:.1}%",
        100.0 * found[5].0
    );
    assert!(
        found[6].1 as f64 <= 0.01 * covered_truth as f64,
        "64 rays: {} pixels missed without a flag",
        found[6].1
    );
}

#[test]
fn a_picture_over_the_devices_limits_is_a_clear_error_not_a_panic() {
    use fourfold::render::{GpuError, check_image_size};
    // wgpu's downlevel defaults: textures up to 2048 wide, buffers up to 256 MiB.
    let limits = wgpu::Limits::downlevel_defaults();
    assert!(check_image_size(2048, 2048, &limits).is_ok());
    let err = check_image_size(4096, 512, &limits).unwrap_err();
    assert!(
        matches!(err, GpuError::ImageTooLarge { max_side: 2048, .. }),
        "{err}"
    );
    let text = err.to_string();
    assert!(text.contains("4096x512"), "{text}");
    assert!(text.contains("largest texture side is 2048"), "{text}");
    assert!(text.contains("--size"), "{text}");
    // Within the side, over the read-back buffer: the largest square within both.
    let small_buffers = wgpu::Limits {
        max_texture_dimension_2d: 16384,
        max_buffer_size: 64 << 20,
        ..limits
    };
    let err = check_image_size(8192, 8192, &small_buffers).unwrap_err();
    assert!(
        matches!(err, GpuError::ImageTooLarge { max_side: 4096, .. }),
        "{err}"
    );
    assert!(check_image_size(4096, 4096, &small_buffers).is_ok());
    // And the device fourfold opens takes the largest picture its adapter can draw (the
    // command line's side of this: tests/cli.rs in the fourfold-cli crate).
    let gpu = gpu();
    let limits = gpu.device.limits();
    assert!(limits.max_texture_dimension_2d >= 2048);
}

#[test]
fn tile_lists_hold_every_leaf_a_pixel_can_see() {
    use fourfold::render::TileLists;
    use fourfold::render::view::tiles::{MAX_TILE, MIN_TILE};
    use fourfold::tree::Hierarchy;
    for (name, scene) in example_scenes().into_iter().take(4) {
        let scene = small(&scene);
        let (formula, params, tree) = common::build(&scene, scene.tree.into());
        let h = Hierarchy::from_tree(&tree);
        // The default cut: coarser boxes, binned by the boxes they cover.
        let cut = Hierarchy::for_formula(&tree, &formula, &params);
        for (w, hgt) in [(40, 24), (97, 61)] {
            let camera = Camera::new(&scene.domain, &scene.view, w, hgt);
            // The smallest tiles, and larger ones forced by a small entry budget.
            let finest = TileLists::build(&h, &camera);
            let coarse = TileLists::build_within(&h, &camera, finest.entries() / 8);
            assert_eq!(
                finest.tile, MIN_TILE,
                "{name}: small lists should use the smallest tiles"
            );
            assert!(
                coarse.tile > MIN_TILE && coarse.tile <= MAX_TILE,
                "{name}: tile {}",
                coarse.tile
            );
            for lists in [&finest, &coarse] {
                check_tile_lists(name, &h, &camera, lists);
            }
            check_tile_lists(name, &cut, &camera, &TileLists::build(&cut, &camera));
            // Lists of the leaves themselves (the march level at the finest level).
            let leaves = Hierarchy::from_tree_at(&tree, h.finest_level());
            check_tile_lists(name, &leaves, &camera, &TileLists::build(&leaves, &camera));
        }
        // Small images bin by the cover boxes' ancestors (COVER_PER_TILE); a larger one by
        // the cover boxes themselves.
        let camera = Camera::new(&scene.domain, &scene.view, 320, 200);
        check_tile_lists(name, &cut, &camera, &TileLists::build(&cut, &camera));
    }
}

/// Every box the ray caster marches (`Hierarchy::marches`) of which a cover box (see
/// `Hierarchy::cover`) passes the shader's pixel test (sphere and box support along v1, v2)
/// is in the pixel's tile list, once; no node that is not marched is; each list is nearest
/// first (by |q| − r).
/// Whether the plane o + s·n1 + t·n2 meets the box [lo, hi]: the points (s, t) inside
/// the box's 4 slabs form a convex polygon, bounded when n1 and n2 are independent, which
/// is not empty iff one of its vertices, where the boundary lines of two slabs cross, is
/// in all of them (up to 1e-9).
fn plane_meets_box(o: [f64; 4], n1: [f64; 4], n2: [f64; 4], lo: [f64; 4], hi: [f64; 4]) -> bool {
    let lines: Vec<(f64, f64, f64)> = (0..4)
        .flat_map(|k| [lo[k], hi[k]].map(|b| (n1[k], n2[k], b - o[k])))
        .collect();
    let inside = |s: f64, t: f64| {
        (0..4).all(|k| {
            let x = o[k] + s * n1[k] + t * n2[k];
            lo[k] - 1e-9 <= x && x <= hi[k] + 1e-9
        })
    };
    lines.iter().enumerate().any(|(i, &(a1, b1, c1))| {
        lines[i + 1..].iter().any(|&(a2, b2, c2)| {
            let det = a1 * b2 - a2 * b1;
            det.abs() > 1e-12 && inside((c1 * b2 - c2 * b1) / det, (a1 * c2 - a2 * c1) / det)
        })
    })
}

fn check_tile_lists(
    name: &str,
    h: &fourfold::tree::Hierarchy,
    camera: &Camera,
    lists: &fourfold::render::TileLists,
) {
    let t = lists.tile;
    // The rectangles a pass draws the ray caster in: every tile with boxes in exactly one
    // (a pixel drawn twice would be blended twice), whole tiles only.
    let rects = lists.rects();
    for (tx, ty) in (0..lists.tiles_y).flat_map(|ty| (0..lists.tiles_x).map(move |tx| (tx, ty))) {
        let (x, y) = (tx * t, ty * t);
        let holding = rects
            .iter()
            .filter(|r| r[0] <= x && x < r[2] && r[1] <= y && y < r[3])
            .count();
        if lists.tile(tx, ty).is_empty() {
            assert!(
                holding <= 1,
                "{name}: tile ({tx}, {ty}) in {holding} rectangles"
            );
        } else {
            assert_eq!(holding, 1, "{name}: tile ({tx}, {ty}) with boxes");
        }
    }
    assert!(
        rects.iter().flatten().all(|v| v % t == 0),
        "{name}: {rects:?}"
    );
    let key = |i: u32| {
        let node = &h.nodes[i as usize];
        let rel: [f64; 4] = std::array::from_fn(|k| f64::from(node.center[k]) - camera.center[k]);
        let q1: f64 = (0..4).map(|k| rel[k] * camera.n1[k]).sum();
        let q2: f64 = (0..4).map(|k| rel[k] * camera.n2[k]).sum();
        q1.hypot(q2) - f64::from(h.levels[node.level() as usize].radius)
    };
    for ty in 0..lists.tiles_y {
        for tx in 0..lists.tiles_x {
            let list = tile_nodes(lists, tx, ty);
            assert!(
                list.iter().all(|&i| h.marches(&h.nodes[i as usize])),
                "{name}: a node that is not marched in tile ({tx}, {ty})"
            );
            let mut seen = std::collections::HashSet::new();
            assert!(
                list.iter().all(|i| seen.insert(*i)),
                "{name}: a leaf twice in a tile"
            );
            assert!(
                list.windows(2).all(|p| key(p[0]) <= key(p[1]) + 1e-5),
                "{name}: tile ({tx}, {ty}) is not nearest first"
            );
        }
    }
    // Per cover box: its marched box, its centre's offset from the camera's centre along
    // v1 and v2, its sphere's radius, its support along v1 and v2, and its box.
    let dot = |x: &[f64; 4], v: &[f64; 4]| -> f64 { (0..4).map(|k| x[k] * v[k]).sum() };
    type Cover = (u32, f64, f64, f64, f64, f64, [f64; 4], [f64; 4]);
    let cover: Vec<Cover> = h.cover[0]
        .iter()
        .map(|c| {
            let (center, level) = (c.center, c.level);
            let info = &h.levels[level as usize];
            let rel: [f64; 4] = std::array::from_fn(|k| f64::from(center[k]) - camera.center[k]);
            let half = info.half.map(f64::from);
            let support = |v: &[f64; 4]| -> f64 { (0..4).map(|k| half[k] * v[k].abs()).sum() };
            (
                c.node,
                dot(&rel, &camera.v1),
                dot(&rel, &camera.v2),
                f64::from(info.radius),
                support(&camera.v1),
                support(&camera.v2),
                std::array::from_fn(|k| f64::from(center[k]) - half[k]),
                std::array::from_fn(|k| f64::from(center[k]) + half[k]),
            )
        })
        .collect();
    for py in 0..camera.height {
        for px in 0..camera.width {
            let o = camera.origin(f64::from(px), f64::from(py));
            let rel: [f64; 4] = std::array::from_fn(|k| o[k] - camera.center[k]);
            let (oa, ob) = (dot(&rel, &camera.v1), dot(&rel, &camera.v2));
            let list = tile_nodes(lists, px / t, py / t);
            for &(i, ca, cb, r, sa, sb, lo, hi) in &cover {
                let (a, b) = (ca - oa, cb - ob);
                // (The sphere and the supports first: a plane that meets the box meets them.)
                if a * a + b * b <= r * r
                    && a.abs() <= sa
                    && b.abs() <= sb
                    && plane_meets_box(o, camera.n1, camera.n2, lo, hi)
                {
                    assert!(
                        list.contains(&i),
                        "{name} {}x{} tile {t}: box {i} covers a box whose plane meets pixel ({px}, {py}) but is not in its tile",
                        camera.width,
                        camera.height
                    );
                }
            }
        }
    }
}

#[test]
fn a_slab_of_the_glome_covers_the_disk_its_band_allows() {
    // The glome seen at s from its centre has, in each observer plane, a circle of radius
    // r = √(1 − s²) around the pixel's origin, which reaches n2 in [−r, r]: a slab whose band
    // along n2 is [lo, hi], 0 < lo, keeps the pixels with r ≥ lo, a disk of radius √(1 − lo²).
    let gpu = gpu();
    let mut scene = unit_glome();
    scene.render.rays = 16;
    let size = 64;
    let (c, h) = (0.5, 0.2);
    scene.view.slab = Some([c, h]);
    for angles in [[0.0; 6], [0.4, 1.2, -0.8, 0.3, 2.0, -1.1]] {
        scene.view.angles = angles;
        let picture =
            render_scene(&scene, size, size, Device::Gpu(&gpu), Default::default()).unwrap();
        let covered = coverage(&picture.rgba, scene.render.background.0);
        let camera = Camera::new(&scene.domain, &scene.view, size, size);
        let unit = 1.0 / camera.pixel_size;
        let edge = (1.0f64 - (c - h) * (c - h)).sqrt() * unit;
        // Inside 0.9 the band's arcs of the circle are wider than the angle between two of
        // the 16 rays, so a ray meets them; between 0.9 and the edge they may be missed.
        let sure = 0.9 * unit;
        let wrong = off_disk(&covered, size, sure - 1.0, edge + 1.0);
        assert_eq!(wrong, 0, "{wrong} pixels off at angles {angles:?}");
        // Narrower than the projection, which covers the unit disk.
        let projected = {
            let mut whole = scene.clone();
            whole.view.slab = None;
            let p =
                render_scene(&whole, size, size, Device::Gpu(&gpu), Default::default()).unwrap();
            coverage(&p.rgba, scene.render.background.0)
        };
        let count = |v: &[bool]| v.iter().filter(|c| **c).count();
        assert!(
            count(&covered) < count(&projected),
            "the slab cut nothing away"
        );
    }
}

#[test]
fn a_wide_slab_is_the_projection_and_one_outside_draws_nothing() {
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["fig-3-9-left", "glome", "tiger"]) {
        let scene = small(&scene);
        let draw = |slab: Option<[f64; 2]>, device: Device<'_>| {
            let mut s = scene.clone();
            s.view.slab = slab;
            render_scene(&s, 48, 40, device, Default::default())
                .unwrap()
                .rgba
        };
        let whole = draw(None, Device::Gpu(&gpu));
        let reach = 2.0 * scene.domain.half_diagonal();
        assert_eq!(
            differing(&whole, &draw(Some([0.0, reach]), Device::Gpu(&gpu))),
            0,
            "{name}: a slab holding the domain changed the picture"
        );
        let outside = draw(Some([reach + 1.0, 0.5]), Device::Gpu(&gpu));
        assert!(
            !coverage(&outside, scene.render.background.0)
                .into_iter()
                .any(|c| c),
            "{name}: a slab outside the domain drew something"
        );
        // The GPU's slab is the CPU twin's.
        let band = Some([0.3, 0.4]);
        let (g, c) = (draw(band, Device::Gpu(&gpu)), draw(band, Device::Cpu));
        let (close, cover) = agreement(&g, &c, scene.render.background.0, 12);
        assert!(
            cover >= 0.99 && close >= 0.90,
            "{name}: colour {close}, coverage {cover}"
        );
        assert!(
            differing(&whole, &g) > 0,
            "{name}: the band changed nothing"
        );
    }
}

#[test]
fn the_glome_sliced_at_c_is_a_disk_of_radius_root_of_one_minus_c_squared() {
    // Cut by the hyperplane at c along n2, the unit glome is a sphere of radius √(1 − c²)
    // about the domain's centre, whatever the angles: seen along n1, a disk of that radius.
    let gpu = gpu();
    let mut scene = unit_glome();
    let size = 64;
    for angles in [[0.0; 6], [0.4, 1.2, -0.8, 0.3, 2.0, -1.1], [1.1; 6]] {
        for c in [0.0, 0.45, -0.8, 0.95] {
            scene.view.angles = angles;
            scene.view.slice = Some(c);
            let picture =
                render_scene(&scene, size, size, Device::Gpu(&gpu), Default::default()).unwrap();
            let covered = coverage(&picture.rgba, scene.render.background.0);
            let camera = Camera::new(&scene.domain, &scene.view, size, size);
            let radius = (1.0f64 - c * c).sqrt() / camera.pixel_size;
            let wrong = off_disk(&covered, size, radius - 1.0, radius + 1.0);
            assert_eq!(
                wrong, 0,
                "c = {c}, angles {angles:?}: {wrong} pixels off the disk"
            );
        }
    }
    for c in [1.05, -1.3] {
        scene.view.slice = Some(c);
        let picture =
            render_scene(&scene, size, size, Device::Gpu(&gpu), Default::default()).unwrap();
        let covered = coverage(&picture.rgba, scene.render.background.0);
        assert!(
            !covered.iter().any(|c| *c),
            "the slice at {c} misses the glome"
        );
    }
}

#[test]
fn slices_on_the_gpu_are_the_cpu_twin_s() {
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["fig-3-9-left", "tiger", "spheritorus"]) {
        let mut scene = small(&scene);
        scene.view.slice = Some(0.2);
        let g = render_scene(&scene, 48, 40, Device::Gpu(&gpu), Default::default()).unwrap();
        let c = render_scene(&scene, 48, 40, Device::Cpu, Default::default()).unwrap();
        let (close, cover) = agreement(&g.rgba, &c.rgba, scene.render.background.0, 12);
        eprintln!("{name}: colour {close:.3}, coverage {cover:.3}");
        assert!(
            cover >= 0.99 && close >= 0.95,
            "{name}: colour {close}, coverage {cover}"
        );
        let drawn = coverage(&g.rgba, scene.render.background.0);
        assert!(drawn.iter().any(|c| *c), "{name}: the slice drew nothing");
    }
}

#[test]
fn colour_by_the_hidden_direction_brightens_monotonically_along_n2() {
    // The glome cut along a line of places c across n2: with flat colour, each slice has the
    // colour map's colour for c, and viridis gets lighter all the way.
    use fourfold::scene::ColorBy;
    let gpu = gpu();
    let mut scene = unit_glome();
    scene.render.color_by = ColorBy::Hidden;
    scene.render.lighting.enabled = false;
    scene.view.angles = [0.4, 1.2, -0.8, 0.3, 2.0, -1.1];
    let size = 32;
    let mut lightness = Vec::new();
    for k in 0..=8 {
        let c = -0.8 + 0.2 * f64::from(k);
        scene.view.slice = Some(c);
        let picture =
            render_scene(&scene, size, size, Device::Gpu(&gpu), Default::default()).unwrap();
        let centre = ((size / 2) * size + size / 2) as usize * 4;
        let [r, g, b] = [0, 1, 2].map(|i| f64::from(picture.rgba[centre + i]));
        lightness.push(0.2126 * r + 0.7152 * g + 0.0722 * b);
    }
    assert!(
        lightness.windows(2).all(|w| w[1] > w[0]),
        "lightness along n2: {lightness:?}"
    );
    // And the projection coloured so is the CPU twin's.
    scene.view.slice = None;
    scene.render.lighting.enabled = true;
    let g = render_scene(&scene, 40, 40, Device::Gpu(&gpu), Default::default()).unwrap();
    let c = render_scene(&scene, 40, 40, Device::Cpu, Default::default()).unwrap();
    let (close, cover) = agreement(&g.rgba, &c.rgba, scene.render.background.0, 12);
    assert!(
        cover >= 0.99 && close >= 0.90,
        "colour {close}, coverage {cover}"
    );
}

#[test]
fn the_slice_s_place_is_marked_in_the_projection_as_on_the_cpu() {
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["fig-3-9-left", "glome"]) {
        let mut scene = small(&scene);
        let plain = render_scene(&scene, 48, 40, Device::Gpu(&gpu), Default::default()).unwrap();
        scene.view.mark = Some(0.0);
        let g = render_scene(&scene, 48, 40, Device::Gpu(&gpu), Default::default()).unwrap();
        let c = render_scene(&scene, 48, 40, Device::Cpu, Default::default()).unwrap();
        let (close, cover) = agreement(&g.rgba, &c.rgba, scene.render.background.0, 12);
        assert!(
            cover >= 0.99 && close >= 0.90,
            "{name}: colour {close}, coverage {cover}"
        );
        assert!(
            differing(&plain.rgba, &g.rgba) > 0,
            "{name}: nothing marked"
        );
    }
}

#[test]
fn a_frame_read_back_without_waiting_is_the_frame_read_back_at_once() {
    // The web page's PNG export cannot wait for the GPU: it starts the read-back and polls.
    use fourfold::render::RayCaster;
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["glome", "tiger"]) {
        let scene = small(&scene);
        let (params, shader, h) = caster_inputs(&scene);
        let camera = Camera::new(&scene.domain, &scene.view, 96, 64);
        let uniforms = frame_uniforms(&scene, &camera, &h, &params, None);
        let mut caster = RayCaster::new(&gpu, &shader, &h).unwrap();
        caster.bin_view(&gpu, &h, None, &camera, &uniforms);
        let at_once = caster.render_rgba(&gpu, &uniforms).unwrap();
        let pending = caster.start_rgba(&gpu, &uniforms, false).unwrap();
        assert_eq!(pending.size(), [96, 64]);
        let polled = loop {
            if let Some(rgba) = pending.poll(&gpu) {
                break rgba.unwrap();
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        };
        assert_eq!(differing(&polled, &at_once), 0, "{name}");
        assert!(
            polled.chunks(4).any(|p| p[..3] != at_once[..3]),
            "{name}: a blank picture"
        );
    }
}

/// The hierarchy's node indices of tile (tx, ty)'s boxes, in list order.
fn tile_nodes(lists: &fourfold::render::TileLists, tx: u32, ty: u32) -> Vec<u32> {
    lists
        .tile(tx, ty)
        .iter()
        .map(|&b| lists.boxes[b as usize].node)
        .collect()
}

/// The glome at tree level 4, plain: its formula, shader, scene and prepared tree (the
/// pipeline tests' subject).
fn small_glome() -> (
    CompiledFormula,
    shader::Shader,
    Scene,
    fourfold::render::Prepared,
) {
    let text = "x^2 + y^2 + z^2 + w^2 = 1";
    let formula = CompiledFormula::compile(text).unwrap();
    let shader = shader::generate(&formula).unwrap();
    let mut scene = Scene::from_formula(text);
    scene.tree.max_level = 4;
    scene.render.certified = false;
    let prepared = fourfold::render::Prepared::new(&formula, &scene).unwrap();
    (formula, shader, scene, prepared)
}

/// A painter builds the one pipeline its pictures draw with, before the first picture: a
/// slice's and not the projection's, a projection's and not a slice's, a certified one's;
/// drawing builds no other (issue 39: a slice's pipeline used to be built inside its first
/// frame, after the unused projection's).
#[test]
fn a_painter_builds_only_the_pipeline_its_pictures_draw_with_and_before_them() {
    use fourfold::render::Painter;
    let gpu = gpu();
    let (formula, shader, projection, prepared) = small_glome();
    let mut slice = projection.clone();
    slice.view.slice = Some(0.3);
    let mut slab = projection.clone();
    slab.view.slab = Some([0.1, 0.4]);
    let mut certified = projection.clone();
    certified.render.certified = true;
    let h = &prepared.hierarchy;
    for (name, scene) in [
        ("projection", &projection),
        ("slice", &slice),
        ("slab", &slab),
        ("certified", &certified),
    ] {
        let mut painter = Painter::new(Device::Gpu(&gpu), &shader, h, scene).unwrap();
        assert_eq!(
            painter.pipelines(scene, h),
            (1, true),
            "{name}: at preparation"
        );
        for other in [&projection, &slice, &slab, &certified] {
            if !std::ptr::eq(other, scene) {
                assert!(
                    !painter.pipelines(other, h).1,
                    "{name} built another's pipeline"
                );
            }
        }
        let picture = painter
            .start(
                prepared.source(&formula, scene.render.certified),
                scene,
                [24, 16],
                Default::default(),
            )
            .and_then(|pending| pending.wait())
            .unwrap();
        assert_eq!(picture.rgba.len(), 24 * 16 * 4);
        assert_eq!(
            painter.pipelines(scene, h),
            (1, true),
            "{name}: after a picture"
        );
    }
}

/// A sibling of a caster builds and warms up a pipeline on another thread, and the caster
/// takes it (the viewer's settled picture: its certified pipeline follows the caster), then
/// draws with it the picture it draws after building it itself; a caster of another shader
/// is refused.
#[test]
fn a_caster_adopts_the_pipeline_its_sibling_built_on_another_thread() {
    use fourfold::render::{RayCaster, Target};
    let gpu = gpu();
    let (formula, shader, plain, prepared) = small_glome();
    let mut certified = plain.clone();
    certified.render.certified = true;
    let h = &prepared.hierarchy;
    let target = Target::OFFSCREEN;
    let mut caster = RayCaster::for_scene(&gpu, &shader, h, target, &plain).unwrap();
    let mut sibling = caster.sibling(&gpu).unwrap();
    assert_eq!(sibling.pipelines_built(), 0);
    let sibling = std::thread::scope(|s| {
        s.spawn(|| {
            // (A sibling's buffers hold an empty tree.)
            let empty = fourfold::tree::Hierarchy::default();
            sibling.warm_up(&gpu, &empty, &certified).unwrap();
            sibling
        })
        .join()
        .unwrap()
    });
    assert!(!caster.has_pipeline_for(&certified, h));
    assert!(caster.adopt(sibling));
    assert!(caster.has_pipeline_for(&certified, h));
    assert_eq!(caster.pipelines_built(), 2);
    let draw = |caster: &mut RayCaster| {
        let (camera, uniforms) = prepared.frame(&certified, 32, 24, Default::default());
        let lists = Some(prepared.certifying(&formula));
        caster.bin_view(&gpu, h, lists, &camera, &uniforms);
        caster.render_rgba(&gpu, &uniforms).unwrap()
    };
    let adopted = draw(&mut caster);
    let mut own = RayCaster::for_scene(&gpu, &shader, h, target, &certified).unwrap();
    assert_eq!(
        adopted,
        draw(&mut own),
        "the adopted pipeline draws otherwise"
    );
    let other = shader::generate(&CompiledFormula::compile("x + y + z + w").unwrap()).unwrap();
    let stranger = RayCaster::for_scene(&gpu, &other, h, target, &certified).unwrap();
    assert!(
        !caster.adopt(stranger),
        "a caster of another shader was adopted"
    );
}

/// A formula whose numbers alone differ from another's has the same shader (its constants
/// are read from binding 7), and a caster of one draws the other once given its constants,
/// as a caster made for it draws it, certified verdicts included; the interpreting shader's
/// caster likewise takes the other's program. Another structure is another shader.
#[test]
fn a_caster_draws_a_formula_that_differs_only_in_its_numbers_without_a_new_shader() {
    use fourfold::render::{RayCaster, Target};
    let gpu = gpu();
    let texts = [
        "x^2 + y^2 + z^2 + w^2 - 0.7",
        "x^2 + y^2 + z^2 + w^2 - 0.75",
        "x^2 + y^2 + z^2 + w^2 - 0.3",
    ];
    let same = [
        (
            "0.3 x^3 + y^2 + sin(2.5 z) + w^2 - 0.6",
            "0.35 x^3 + y^2 + sin(3 z) + w^2 - 1.1",
        ),
        (
            "sqrt(x + 0.1) + y^2 + z^2 + w^2 - 1.2",
            "sqrt(x + 0.4) + y^2 + z^2 + w^2 - 1e-3",
        ),
    ];
    let source = |t: &str| shader::generate(&CompiledFormula::compile(t).unwrap()).unwrap();
    for (a, b) in same.iter().chain([&(texts[0], texts[1])]) {
        // (Not assert_eq: the sources are long.)
        assert!(
            source(a).source == source(b).source,
            "{a} and {b}: two shaders"
        );
        assert_ne!(source(a).constants, source(b).constants, "{a} and {b}");
    }
    // (A number equal to another one of the formula's is the same constant: x^2 + 2 y^2
    // has one where x^2 + 3 y^2 has two, and another shader.)
    for (a, b) in [
        (texts[0], "x^2 + y^2 + z^2 + w^2 - 0.7 x"),
        (texts[0], "x^2 + y^2 + z^2 + w^4 - 0.7"),
        ("x^2 + 3 y^2 - 1", "x^2 + 2 y^2 - 1"),
    ] {
        assert!(
            source(a).source != source(b).source,
            "{a} and {b}: one shader"
        );
    }
    let interpreter = shader::interpreter().unwrap();
    let prepare = |text: &str, certified: bool| {
        let formula = CompiledFormula::compile(text).unwrap();
        let mut scene = Scene::from_formula(text);
        scene.tree.max_level = 4;
        scene.render.certified = certified;
        let prepared = fourfold::render::Prepared::new(&formula, &scene).unwrap();
        (formula, scene, prepared)
    };
    for certified in [false, true] {
        let (formula, _, prepared) = prepare(texts[0], certified);
        let first = shader::generate(&formula).unwrap();
        let h = &prepared.hierarchy;
        let target = Target::OFFSCREEN;
        let mut reused = RayCaster::new(&gpu, &first, h).unwrap();
        let base = RayCaster::new(&gpu, &interpreter, h).unwrap();
        let mut interpreting = base.interpret(&gpu, &formula, h).unwrap();
        for text in &texts[1..] {
            let (formula, scene, prepared) = prepare(text, certified);
            let own = shader::generate(&formula).unwrap();
            let h = &prepared.hierarchy;
            assert!(reused.draws(&own));
            let lists = certified.then(|| prepared.certifying(&formula));
            let draw = |caster: &mut RayCaster| {
                let (camera, uniforms) = prepared.frame(&scene, 32, 24, Default::default());
                caster.bin_view(&gpu, h, lists, &camera, &uniforms);
                caster.render_rgba(&gpu, &uniforms).unwrap()
            };
            let mut fresh = RayCaster::for_scene(&gpu, &own, h, target, &scene).unwrap();
            reused.set_hierarchy(&gpu, h).unwrap();
            reused.set_formula(&gpu, &formula, &own).unwrap();
            let expected = draw(&mut fresh);
            assert!(
                expected.chunks(4).any(|p| p[3] == 255),
                "{text}: M is drawn"
            );
            assert_eq!(draw(&mut reused), expected, "{text}, certified {certified}");
            if !certified {
                let mut fresh = base.interpret(&gpu, &formula, h).unwrap();
                interpreting.set_hierarchy(&gpu, h).unwrap();
                interpreting.set_formula(&gpu, &formula, &own).unwrap();
                assert_eq!(
                    draw(&mut interpreting),
                    draw(&mut fresh),
                    "{text}, interpreted"
                );
            }
        }
    }
}

#[test]
fn a_section_bins_only_the_boxes_it_meets_and_draws_what_the_walk_draws() {
    // A slice's (or slab's) tile lists hold only the boxes that meet its hyperplane (band),
    // a slice's ordered by where its ray may enter them, each key a lower bound on that; and
    // the picture is the walk's of the whole hierarchy (which reads no lists), pixel for
    // pixel, on examples and invented formulas (thin, kinked, undefined in part).
    use fourfold::render::view::Section;
    use fourfold::render::{RayCaster, TileLists};
    let gpu = gpu();
    let mut scenes = example_scenes_named(&["spheritorus", "tiger", "fig-3-9-left"]);
    for formula in [
        "(sqrt(x^2 + y^2) - 0.8)^2 + z^2 + w^2 - 0.02",
        "abs(x) + abs(y - 0.2) + abs(z) + abs(w) - 1",
        "sqrt(x^2 + y^2 - 0.2) + z^2 + w^2 - 1",
    ] {
        scenes.push((formula, Scene::from_formula(formula)));
    }
    for (name, scene) in scenes {
        let mut scene = small(&scene);
        scene.tree.min_level = 5;
        scene.view.angles = [0.3, 0.5, 0.2, 0.7, 0.1, 0.4];
        let (params, shader, h) = caster_inputs(&scene);
        let mut caster = RayCaster::new(&gpu, &shader, &h).unwrap();
        let plane = TileLists::build(&h, &Camera::new(&scene.domain, &scene.view, 64, 48));
        for (view, slice, slab) in [
            ("slice 0.1", Some(0.1), None),
            ("slice -0.45", Some(-0.45), None),
            ("slab", None, Some([0.2, 0.15])),
        ] {
            let mut scene = scene.clone();
            (scene.view.slice, scene.view.slab) = (slice, slab);
            let camera = Camera::new(&scene.domain, &scene.view, 64, 48);
            let lists = TileLists::build(&h, &camera);
            assert!(lists.boxes.len() <= plane.boxes.len());
            for (k, record) in lists.boxes.iter().enumerate() {
                let level = &h.levels[(record.level & 255) as usize];
                let rel: Vec<f64> = (0..4)
                    .map(|i| f64::from(record.center[i]) - camera.center[i])
                    .collect();
                let dot = |v: &[f64; 4]| (0..4).map(|i| rel[i] * v[i]).sum::<f64>();
                let support = |v: &[f64; 4]| {
                    (0..4)
                        .map(|i| f64::from(level.half[i]) * v[i].abs())
                        .sum::<f64>()
                };
                let (q1, q2) = (dot(&camera.n1), dot(&camera.n2));
                let (s1, s2) = (support(&camera.n1), support(&camera.n2));
                let (lo, hi) = match camera.section {
                    Section::Slice { offset } => (offset, offset),
                    Section::Slab { center, half } => (center - half, center + half),
                    Section::Plane => unreachable!(),
                };
                assert!(
                    q2 - s2 <= hi + 1e-4 && q2 + s2 >= lo - 1e-4,
                    "{name}, {view}: a box that misses the section was binned"
                );
                if slice.is_some() {
                    let entry = camera.slice_start + q1 - s1;
                    assert!(f64::from(record.view[2]) <= entry, "{name}, {view}: key");
                }
                if k > 0 {
                    assert!(
                        lists.boxes[k - 1].view[2] <= record.view[2],
                        "{name}: order"
                    );
                }
            }
            let u = frame_uniforms(&scene, &camera, &h, &params, None);
            caster.set_tiles(&gpu, Some(&lists));
            let tiles = caster.render_rgba(&gpu, &u).unwrap();
            caster.set_tiles(&gpu, None);
            let walk = caster.render_rgba(&gpu, &u).unwrap();
            let drawn = coverage(&tiles, scene.render.background.0)
                .iter()
                .filter(|&&c| c)
                .count();
            eprintln!(
                "{name}, {view}: {} of {} boxes binned, {drawn} pixels drawn",
                lists.boxes.len(),
                plane.boxes.len()
            );
            assert_eq!(differing(&tiles, &walk), 0, "{name}, {view}: tiles vs walk");
        }
    }
}
