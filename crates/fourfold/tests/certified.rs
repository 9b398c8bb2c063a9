//! Certified pixels (docs/method.md §5.9): every pixel's verdict holds against an
//! independent, dense look at its observer plane. (The GPU's interval arithmetic is checked
//! with the other evaluators, in tests/conformance.rs.)

mod common;
#[path = "support/unseen.rs"]
mod unseen;

use common::example_scenes_named;
use fourfold::CompiledFormula;
use fourfold::eval::PointEvaluator;
use fourfold::headless::render_prepared;
use fourfold::render::Device;
use fourfold::render::verdict::Verdict;
use fourfold::render::view::{FLAG_SLAB, FLAG_SLICE};
use fourfold::render::{Gpu, Prepared, Uniforms};
use fourfold::scene::{DEFAULT_CERT_BUDGET, Scene};
use rayon::prelude::*;
use std::sync::atomic::AtomicBool;
use unseen::{hard_scenes, unseen_scenes};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"))
}

/// Each pixel's observer plane sampled on a grid of `side`² points over the disk that
/// holds the domain (within the slab, for one; for a slice, `side`² points along its line),
/// in f64: whether F takes both signs at points inside the domain.
fn dense_sign_change(
    u: &Uniforms,
    formula: &CompiledFormula,
    params: &[f64],
    (px, py): (u32, u32),
    side: usize,
) -> bool {
    let f32v = |v: [f32; 4]| v.map(f64::from);
    let (v1, v2, n1, n2, c) = (
        f32v(u.v1),
        f32v(u.v2),
        f32v(u.n1),
        f32v(u.n2),
        f32v(u.center),
    );
    let (lo, hi) = (f32v(u.domain_lo), f32v(u.domain_hi));
    let s = f64::from(u.misc.pixel_size);
    let (w, h) = (f64::from(u.size.width), f64::from(u.size.height));
    let (a, b) = (
        s * (f64::from(px) + 0.5 - 0.5 * w),
        s * (0.5 * h - f64::from(py) - 0.5),
    );
    let reach = 0.5 * (0..4).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt();
    // A slab: only where the coordinate along n2 is within its range.
    let (mid, half) = (
        f64::from(u.root.section_offset),
        f64::from(u.root.section_half),
    );
    let slab = (u.control.flags & FLAG_SLAB != 0).then_some((mid - half, mid + half));
    let slice = u.control.flags & FLAG_SLICE != 0;
    let (along_s, along_t) = if slice {
        (side * side, 1)
    } else {
        (side, side)
    };
    let mut eval = PointEvaluator::new();
    let (mut pos, mut neg) = (false, false);
    for i in 0..along_s {
        for j in 0..along_t {
            let sv = reach * (2.0 * (i as f64 + 0.5) / along_s as f64 - 1.0);
            let tv = if slice {
                mid
            } else {
                reach * (2.0 * (j as f64 + 0.5) / side as f64 - 1.0)
            };
            if slab.is_some_and(|(lo, hi)| tv < lo || tv > hi) {
                continue;
            }
            let p: [f64; 4] =
                std::array::from_fn(|k| c[k] + a * v1[k] + b * v2[k] + sv * n1[k] + tv * n2[k]);
            if (0..4).any(|k| p[k] < lo[k] || p[k] > hi[k]) {
                continue;
            }
            let f = eval.eval(&formula.tape_f, p, params);
            pos |= f > 1e-9;
            neg |= f < -1e-9;
        }
    }
    pos && neg
}

/// A certified picture of `scene` (with its compiled formula and preparation) at `side`².
fn certified_picture(
    scene: &Scene,
    formula: &CompiledFormula,
    prepared: &Prepared,
    side: u32,
    device: Device<'_>,
) -> fourfold::render::Picture {
    render_prepared(
        scene,
        formula,
        prepared,
        side,
        side,
        device,
        Default::default(),
    )
    .unwrap()
}

/// The tree a picture is drawn from: `render`'s and Python's (a slice's or a slab's holds
/// only the boxes that meet its hyperplane or band), or the viewer's, over the whole domain.
#[derive(Clone, Copy, Debug)]
enum Tree {
    ForPicture,
    WholeDomain,
}

/// Certified pictures' verdicts for `scene` at `side`², on the GPU and the CPU twin.
fn certified_pictures(
    gpu: &Gpu,
    scene: &Scene,
    side: u32,
    budget: u32,
    tree: Tree,
) -> (Uniforms, [Vec<Verdict>; 2]) {
    let mut scene = scene.clone();
    scene.render.certified = true;
    scene.render.cert_budget = budget;
    scene.render.rays = 4;
    let formula = CompiledFormula::compile(&scene.formula).unwrap();
    let prepared = match tree {
        Tree::ForPicture => {
            Prepared::for_picture(&formula, &scene, false, &AtomicBool::new(false)).unwrap()
        }
        Tree::WholeDomain => Prepared::new(&formula, &scene).unwrap(),
    };
    let (_, uniforms) = prepared.frame(&scene, side, side, Default::default());
    let verdicts = [Device::Gpu(gpu), Device::Cpu].map(|device| {
        certified_picture(&scene, &formula, &prepared, side, device)
            .verdicts
            .expect("a certified picture has verdicts")
    });
    (uniforms, verdicts)
}

/// Against an independent look: wherever a dense grid of points on a pixel's observer plane
/// finds F taking both signs in the domain, neither the GPU nor the CPU twin says EMPTY;
/// and every HIT pixel's plane does hold a sign change (found by a finer grid).
#[test]
fn no_pixel_where_m_is_is_empty_and_every_hit_is_real() {
    let gpu = gpu();
    let mut scenes = example_scenes_named(&["glome", "fig-3-9-left", "tiger", "hyperplane"]);
    let mut slab = scenes[1].1.clone();
    slab.view.slab = Some([1.0, 0.8]);
    scenes.push(("fig-3-9-left, slab", slab));
    let side = 40;
    // (A small budget too: its searches stop between boxes and within them.)
    let runs = scenes
        .iter()
        .flat_map(|s| [(s, DEFAULT_CERT_BUDGET), (s, 8)]);
    for ((name, scene), budget) in runs {
        let (u, verdicts) = certified_pictures(&gpu, scene, side, budget, Tree::ForPicture);
        let formula = CompiledFormula::compile(&scene.formula).unwrap();
        let params = scene.param_values(&formula.param_names());
        for (k, device) in ["GPU", "CPU"].iter().enumerate() {
            let v = &verdicts[k];
            let mut hits = 0;
            for py in 0..side {
                for px in 0..side {
                    let verdict = v[(py * side + px) as usize];
                    if verdict == Verdict::Undecided {
                        continue;
                    }
                    let dense = dense_sign_change(&u, &formula, &params, (px, py), 48);
                    assert!(
                        !(dense && verdict == Verdict::Empty),
                        "{name}, {device}, budget {budget}: pixel ({px}, {py}) is EMPTY but F changes sign on its plane"
                    );
                    if verdict == Verdict::Hit {
                        hits += 1;
                        assert!(
                            dense || dense_sign_change(&u, &formula, &params, (px, py), 400),
                            "{name}, {device}: pixel ({px}, {py}) is HIT but no sign change is found on its plane"
                        );
                    }
                }
            }
            assert!(
                hits > 20,
                "{name}, {device}: only {hits} hit pixels: the scene shows nothing"
            );
        }
    }
}

/// On the scenes the search was not tuned for (tests/data/unseen), at 96² and the default
/// budget: no pixel where a dense look at its plane finds F taking both signs is EMPTY, on
/// the GPU or the CPU twin; and at most 0.5% of the covered pixels (hit or undecided) stay
/// undecided, on both (the shares are printed).
#[test]
fn unseen_scenes_are_sound_and_decided() {
    let gpu = gpu();
    for (name, scene) in unseen_scenes() {
        assert_sound_and_decided(&gpu, &name, &scene, (96, 1), 50, Tree::ForPicture, DECIDED);
    }
}

/// The same at 512²: every EMPTY pixel within two of a covered one is looked at densely,
/// and one in 8 × 8 of the others (at 96² every pixel is).
#[test]
fn unseen_scenes_are_sound_and_decided_at_512() {
    let gpu = gpu();
    for (name, scene) in unseen_scenes() {
        assert_sound_and_decided(&gpu, &name, &scene, (512, 8), 50, Tree::ForPicture, DECIDED);
    }
}

/// The hard unseen scenes (tests/data/unseen-hard: a jump of sign(x), the cusps of
/// Σ sqrt|xᵢ|, a tube of radius 0.02 about a surface), on which issue 34's 0.5% is not met
/// on the GPU (docs/benchmarks.md, "Twelve more unseen scenes"): sound all the same, at 96²
/// and 512², on the GPU and the CPU twin (their undecided shares printed, not bounded).
/// (Across the jump F takes both signs without a zero, which the dense look counts as M:
/// stricter than soundness there.)
#[test]
fn hard_scenes_are_sound() {
    let gpu = gpu();
    for (name, scene) in hard_scenes() {
        for size in [(96, 1), (512, 8)] {
            assert_sound_and_decided(&gpu, &name, &scene, size, 50, Tree::ForPicture, 1.0);
        }
    }
}

/// Issue 34's bound on the undecided share of the covered pixels.
const DECIDED: f64 = 0.005;

/// The unseen scenes' slices, which `render --slice` draws on the CPU twin when small, at
/// 96² and at two places, from the tree `render` builds within the slice's hyperplane and
/// at one of them from the viewer's, over the whole domain; and a slab within its band: as
/// sound and as decided as their projections.
#[test]
fn unseen_slices_are_sound_and_decided() {
    let gpu = gpu();
    for (name, scene) in unseen_scenes() {
        for (c, tree) in [
            (0.15, Tree::ForPicture),
            (-0.4, Tree::ForPicture),
            (0.15, Tree::WholeDomain),
        ] {
            let mut sliced = scene.clone();
            sliced.view.slice = Some(c);
            let name = format!("{name}, slice {c}, {tree:?}");
            // (A slice of a thin tube covers a few pixels only.)
            assert_sound_and_decided(&gpu, &name, &sliced, (96, 1), 10, tree, DECIDED);
        }
        let mut slab = scene.clone();
        slab.view.slab = Some([0.1, 0.2]);
        let name = format!("{name}, slab 0.1 ± 0.2");
        assert_sound_and_decided(&gpu, &name, &slab, (96, 1), 10, Tree::ForPicture, DECIDED);
    }
}

/// Certifies `scene` at `side`² on the GPU and the twin: no EMPTY pixel whose plane a dense
/// look finds F taking both signs on (every pixel within two of a covered one, finely; of
/// the others one in `stride`² per axis), at most `most_undecided` of the covered pixels
/// undecided, and more than `least_hits` hits (the scene shows something).
fn assert_sound_and_decided(
    gpu: &Gpu,
    name: &str,
    scene: &Scene,
    (side, stride): (u32, u32),
    least_hits: usize,
    tree: Tree,
    most_undecided: f64,
) {
    let (u, verdicts) = certified_pictures(gpu, scene, side, DEFAULT_CERT_BUDGET, tree);
    let formula = CompiledFormula::compile(&scene.formula).unwrap();
    let params = scene.param_values(&formula.param_names());
    // (A finer look near covered pixels, where thin parts would be missed; the planes
    // of a finer picture lie closer together, so each needs a less fine one.)
    let near_grid = if side > 128 { 48 } else { 128 };
    for (k, device) in ["GPU", "CPU"].into_iter().enumerate() {
        let v = &verdicts[k];
        let covered = |x: i64, y: i64| {
            (0..side as i64).contains(&x)
                && (0..side as i64).contains(&y)
                && v[(y * side as i64 + x) as usize] != Verdict::Empty
        };
        let wrong: Vec<(u32, u32)> = (0..v.len())
            .into_par_iter()
            .filter_map(|i| {
                let px = (i as u32 % side, i as u32 / side);
                let (x, y) = (i64::from(px.0), i64::from(px.1));
                let near = (-2..=2).any(|dy| (-2..=2).any(|dx| covered(x + dx, y + dy)));
                let looked_at =
                    near || (px.0.is_multiple_of(stride) && px.1.is_multiple_of(stride));
                let grid = if near { near_grid } else { 32 };
                (v[i] == Verdict::Empty
                    && looked_at
                    && dense_sign_change(&u, &formula, &params, px, grid))
                .then_some(px)
            })
            .collect();
        assert!(
            wrong.is_empty(),
            "{name}, {device}, {side}²: pixels {wrong:?} are EMPTY but F changes sign on their planes"
        );
        let count = |w: Verdict| v.iter().filter(|&&x| x == w).count();
        let (hit, undecided) = (count(Verdict::Hit), count(Verdict::Undecided));
        let share = undecided as f64 / (hit + undecided).max(1) as f64;
        eprintln!(
            "{name}, {device}, {side}²: {hit} hit, {undecided} undecided ({:.2}% of the covered)",
            100.0 * share
        );
        assert!(hit > least_hits, "{name}, {device}: only {hit} hit pixels");
        assert!(
            share <= most_undecided,
            "{name}, {device}, {side}²: {:.2}% of the covered pixels undecided (at most {}%)",
            100.0 * share,
            100.0 * most_undecided
        );
    }
}

/// Where the plain picture found a hit, the certified one shows the same colour and calls the
/// pixel HIT (or at worst undecided), never EMPTY.
#[test]
fn certified_and_plain_pictures_agree_where_the_plain_one_hits() {
    let gpu = gpu();
    for (name, scene) in example_scenes_named(&["fig-3-9-left", "tiger"]) {
        let mut scene = scene.clone();
        scene.render.rays = 4;
        let formula = CompiledFormula::compile(&scene.formula).unwrap();
        let prepared = Prepared::new(&formula, &scene).unwrap();
        let side = 64;
        let picture = |certified: bool| {
            let mut s = scene.clone();
            s.render.certified = certified;
            render_prepared(
                &s,
                &formula,
                &prepared,
                side,
                side,
                Device::Gpu(&gpu),
                Default::default(),
            )
            .unwrap()
        };
        let (plain, certified) = (picture(false), picture(true));
        let verdicts = certified.verdicts.as_ref().unwrap();
        let background = scene.render.background.0;
        let mut compared = 0;
        for i in 0..(side * side) as usize {
            let p = &plain.rgba[4 * i..4 * i + 3];
            if p == background {
                continue;
            }
            compared += 1;
            assert_eq!(
                p,
                &certified.rgba[4 * i..4 * i + 3],
                "{name}: pixel {i} differs"
            );
            assert_ne!(
                verdicts[i],
                Verdict::Empty,
                "{name}: pixel {i} has a hit but is EMPTY"
            );
        }
        assert!(compared > 100, "{name}: only {compared} pixels with hits");
    }
}

/// Undecided pixels are never drawn as background: with a budget too small to decide, each
/// shows a hit's colour or the marker's, on the GPU and the CPU twin alike.
#[test]
fn undecided_pixels_are_never_background() {
    let gpu = gpu();
    let (_, mut scene) = example_scenes_named(&["fig-3-9-left"]).remove(0);
    scene.render.certified = true;
    scene.render.cert_budget = 2;
    scene.render.rays = 1;
    let formula = CompiledFormula::compile(&scene.formula).unwrap();
    let prepared = Prepared::new(&formula, &scene).unwrap();
    let side = 48;
    let background = scene.render.background.0;
    for device in [Device::Gpu(&gpu), Device::Cpu] {
        let picture = certified_picture(&scene, &formula, &prepared, side, device);
        let verdicts = picture.verdicts.as_ref().unwrap();
        let mut marked = 0;
        for (i, v) in verdicts.iter().enumerate() {
            let rgb = &picture.rgba[4 * i..4 * i + 3];
            if *v == Verdict::Undecided {
                assert_ne!(
                    rgb, background,
                    "{}: undecided pixel {i} drawn as background",
                    picture.adapter
                );
                marked += usize::from(rgb == [255, 0, 255]);
            }
        }
        assert!(
            marked > 0,
            "{}: no undecided pixel shows the marker",
            picture.adapter
        );
    }
}

/// The viewer's settled picture: a certified pass, then plain passes blended into it
/// (`FrameOptions::keep_misses`). Where a plain pass finds no hit, the pixel stays as the
/// certified pass drew it (a proved hit the pencil misses keeps M's colour, an undecided one
/// its mark); where it finds one, the pixel is the mean of the two.
#[test]
fn plain_passes_blended_into_a_certified_picture_keep_what_it_proved() {
    use fourfold::render::{FrameOptions, Pass, RayCaster, Target, shader};
    let gpu = gpu();
    let scenes = unseen_scenes()
        .into_iter()
        .filter(|(name, _)| name == "helix-tube" || name == "gyroid-4d");
    for (name, scene) in scenes {
        let mut scene = scene.clone();
        scene.render.rays = 2;
        scene.render.certified = true;
        let formula = CompiledFormula::compile(&scene.formula).unwrap();
        let prepared = Prepared::new(&formula, &scene).unwrap();
        let shader = shader::generate(&formula).unwrap();
        let side = 64;
        let (camera, proved) = prepared.frame(&scene, side, side, FrameOptions::default());
        let mut plain_scene = scene.clone();
        plain_scene.render.certified = false;
        let second = |keep_misses| FrameOptions {
            frame: 1,
            keep_misses,
            ..FrameOptions::default()
        };
        let (_, plain) = prepared.frame(&plain_scene, side, side, second(false));
        let (_, keeping) = prepared.frame(&plain_scene, side, side, second(true));
        let h = &prepared.hierarchy;
        let certifying = Some(prepared.certifying(&formula));
        let mut offscreen = RayCaster::new(&gpu, &shader, h).unwrap();
        offscreen.bin_view(&gpu, h, certifying, &camera, &proved);
        let first = offscreen.render_rgba(&gpu, &proved).unwrap();
        let next = offscreen.render_rgba(&gpu, &plain).unwrap();
        let target = Target {
            format: wgpu::TextureFormat::Rgba8Unorm,
            accumulate: true,
        };
        let mut caster = RayCaster::with_target(&gpu, &shader, h, target).unwrap();
        caster.bin_view(&gpu, h, certifying, &camera, &proved);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let texture = caster.target_texture(&gpu, side, side, usage);
        let view = texture.create_view(&Default::default());
        for (uniforms, weight) in [(&proved, 1.0), (&keeping, 0.5)] {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let pass = Pass {
                region: None,
                weight,
            };
            caster.encode_pass(&gpu, &mut encoder, &view, uniforms, pass);
            gpu.queue.submit([encoder.finish()]);
        }
        let got = common::read_texture(&gpu, &texture);
        let background = scene.render.background.0;
        let (mut kept_hits, mut blended) = (0, 0);
        for i in 0..(side * side) as usize {
            let rgb = |p: &[u8]| [p[4 * i], p[4 * i + 1], p[4 * i + 2]];
            let (a, b, g) = (rgb(&first), rgb(&next), rgb(&got));
            let expected = if b == background {
                kept_hits += usize::from(first[4 * i + 3] == Verdict::Hit.alpha() && a != b);
                a
            } else {
                blended += 1;
                std::array::from_fn(|k| ((u16::from(a[k]) + u16::from(b[k])) / 2) as u8)
            };
            let off = (0..3).map(|k| g[k].abs_diff(expected[k])).max().unwrap();
            assert!(
                off <= 2,
                "{name}: pixel {i} is {g:?}, expected {expected:?} (certified {a:?}, plain {b:?})"
            );
        }
        eprintln!(
            "{name}: {kept_hits} proved hits kept where the plain pass saw none, {blended} blended"
        );
        assert!(
            kept_hits > 10,
            "{name}: only {kept_hits} proved hits the plain pass missed"
        );
    }
}

/// The plain pencil sees what lies between its rays (the search in the observer plane,
/// templates/raycast/seek.wgsl): on the unseen scenes and two examples at 96², a single
/// plain frame with the scene's rays (16) draws under 1% of the certified frame's proved
/// hits as background (issue 34's bound for the fast frames), on the GPU and the CPU twin
/// (the shares are printed; before the search, up to 26% of a thin tube's, and up to 2.8%
/// with one start per box); and it draws nothing where the certified frame proved M absent.
#[test]
fn plain_frames_see_what_lies_between_their_rays() {
    let gpu = gpu();
    let side = 96;
    let scenes = example_scenes_named(&["hyperplane", "fig-3-9-left"])
        .into_iter()
        .map(|(name, scene)| (name.to_string(), scene))
        .chain(unseen_scenes());
    for (name, scene) in scenes {
        let (_, verdicts) =
            certified_pictures(&gpu, &scene, side, DEFAULT_CERT_BUDGET, Tree::ForPicture);
        let mut plain = scene.clone();
        plain.render.certified = false;
        let formula = CompiledFormula::compile(&plain.formula).unwrap();
        let prepared = Prepared::new(&formula, &plain).unwrap();
        let background = plain.render.background.0;
        for device in [Device::Gpu(&gpu), Device::Cpu] {
            let which = if matches!(device, Device::Gpu(_)) {
                "GPU"
            } else {
                "CPU"
            };
            let picture = render_prepared(
                &plain,
                &formula,
                &prepared,
                side,
                side,
                device,
                Default::default(),
            )
            .unwrap();
            let (mut proved, mut missed) = (0, 0);
            for (i, &verdict) in verdicts[0].iter().enumerate() {
                let shown = picture.rgba[4 * i..4 * i + 3] != background;
                assert!(
                    !(shown && verdict == Verdict::Empty),
                    "{name}, {which}: pixel {i} shows M where the certified frame proved it absent"
                );
                if verdict == Verdict::Hit {
                    proved += 1;
                    missed += usize::from(!shown);
                }
            }
            let share = missed as f64 / proved.max(1) as f64;
            eprintln!(
                "{name}, {which}: {missed} of {proved} proved hits drawn as background ({:.2}%)",
                100.0 * share
            );
            assert!(proved > 50, "{name}: only {proved} proved hits");
            assert!(
                share < 0.01,
                "{name}, {which}: the plain frame misses {:.2}% of the proved hits",
                100.0 * share
            );
        }
    }
}

/// The second-order forms over each certifying box's curvature bounds (docs/method.md §5.9,
/// step 3: Taylor's, a bowl's least value, about a point of the box) prove cells the
/// mean-value form cannot: at 48² with a small budget, the certifying boxes with their
/// bounds leave under half the undecided pixels that the same boxes without bounds leave,
/// on the GPU and the CPU twin, on the chapter's scene (Taylor's form near the domain's
/// walls; 54 against 156 at 32 cells when written), the glome (the bowl beside a convex
/// silhouette; 0 against 34) and fig. 3.11 (planes cutting the boxes' corners; 6 against
/// 42 at 512 cells); and no pixel is EMPTY where a dense look at its plane finds F taking
/// both signs.
#[test]
fn second_order_forms_prove_what_mean_values_cannot() {
    use fourfold::render::verdict::take_marks;
    use fourfold::render::{RayCaster, shader, twin};
    let gpu = gpu();
    let budgets = [("fig-3-9-left", 32), ("glome", 32), ("fig-3-11", 512)];
    for (name, scene) in example_scenes_named(&budgets.map(|(name, _)| name)) {
        let mut scene = scene.clone();
        scene.render.certified = true;
        let budget = budgets.iter().find(|b| b.0 == name).unwrap().1;
        scene.render.cert_budget = budget;
        scene.render.rays = 4;
        let formula = CompiledFormula::compile(&scene.formula).unwrap();
        let prepared = Prepared::new(&formula, &scene).unwrap();
        let params = scene.param_values(&formula.param_names());
        let shader = shader::generate(&formula).unwrap();
        let side = 48;
        let (camera, u) = prepared.frame(&scene, side, side, Default::default());
        let h = &prepared.hierarchy;
        let bounded = prepared.certifying(&formula).clone();
        assert!(
            bounded
                .curvature
                .iter()
                .any(|c| c.in_plane(camera.n1, camera.n2)[0].is_finite()),
            "{name}: the certifying boxes have no curvature bounds"
        );
        let mut unbounded = bounded.clone();
        unbounded.curvature.clear();
        let mut undecided = [[0usize; 2]; 2];
        for (k, certifying) in [&bounded, &unbounded].into_iter().enumerate() {
            let mut caster = RayCaster::new(&gpu, &shader, h).unwrap();
            caster.bin_view(&gpu, h, Some(certifying), &camera, &u);
            let on_gpu = caster.render_rgba(&gpu, &u).unwrap();
            let on_cpu = twin::render_rgba(&formula, &params, h, Some(certifying), &u);
            for (d, mut rgba) in [on_gpu, on_cpu].into_iter().enumerate() {
                let (_, verdicts) = take_marks(&mut rgba);
                for (i, &verdict) in verdicts.iter().enumerate() {
                    let pixel = (i as u32 % side, i as u32 / side);
                    undecided[k][d] += usize::from(verdict == Verdict::Undecided);
                    assert!(
                        !(verdict == Verdict::Empty
                            && dense_sign_change(&u, &formula, &params, pixel, 48)),
                        "{name}: pixel {pixel:?} is EMPTY but F changes sign on its plane"
                    );
                }
            }
        }
        eprintln!(
            "{name}: undecided pixels at {budget} cells, with curvature bounds / without: GPU {} / {}, CPU {} / {}",
            undecided[0][0], undecided[1][0], undecided[0][1], undecided[1][1]
        );
        for d in 0..2 {
            assert!(
                2 * undecided[0][d] < undecided[1][d],
                "{name}: the second-order forms decided too few pixels: {undecided:?}"
            );
        }
    }
}
