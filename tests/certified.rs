//! Certified pixels (docs/method.md §5.9): the GPU's interval arithmetic is sound, and every
//! pixel's verdict holds against an independent, dense look at its observer plane.

mod common;

use common::{Rng, example_scenes, example_scenes_named};
use fourfold::CompiledFormula;
use fourfold::eval::PointEvaluator;
use fourfold::render::certify::Verdict;
use fourfold::render::pipeline::{Device, render_prepared};
use fourfold::render::probe::{Enclosures, enclose};
use fourfold::render::uniforms::FLAG_SLAB;
use fourfold::render::{Gpu, Prepared, Uniforms};
use fourfold::scene::{DEFAULT_CERT_BUDGET, Scene};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, TestRng, TestRunner};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("GPU tests need an adapter: {e}"))
}

/// One formula per operation of the language (and both kinds of power).
const OPERATIONS: &[&str] = &[
    "x + y - z - w",
    "x * y * z - w",
    "x / y - z",
    "(x - y)^2 - z^3 + w^4 - x^5",
    "x^-2 - y^-3",
    "sqrt(x) - y",
    "sqrt(x^2 + y^2) - z",
    "cbrt(x) - y",
    "abs(x) - y",
    "exp(x) - y",
    "ln(x) - y",
    "sin(x) - y",
    "cos(3x) + w",
    "sin(x * y) * cos(z - w)",
    "tan(x) - y",
    "asin(x) - y",
    "acos(x) - y",
    "atan(x) - y",
    "sinh(x) - y",
    "cosh(x) - y",
    "tanh(x) - y",
    "sign(x) + y",
    "step(x) - y",
    "min(x, y) - max(z, w)",
    "pow(x, y) - z",
    "x^0.5 - y",
    "atan2(y, x) - z",
    "a x - b y + 1e-30 z + 1e30 w",
];

/// A box among the kinds that break interval code: huge, tiny, negative, straddling 0,
/// points, beside 0.
fn box_strategy() -> impl Strategy<Value = ([f32; 4], [f32; 4])> {
    let axis = prop_oneof![
        (-4.0f32..4.0, 0.0f32..2.0).prop_map(|(c, w)| (c, c + w)),
        (-1e6f32..1e6, 0.0f32..1e6).prop_map(|(c, w)| (c, c + w)),
        (-1.0f32..1.0, 0.0f32..1e-6).prop_map(|(c, w)| (c, c + w)),
        (-1e-30f32..1e-30, 0.0f32..1e-30).prop_map(|(c, w)| (c, c + w)),
        (-50.0f32..-1e-3, 0.0f32..1e-3).prop_map(|(c, w)| (c, c + w)),
        (0.0f32..3.0).prop_map(|h| (-h, h)),
        (-3.0f32..3.0).prop_map(|c| (c, c)),
        Just((0.0f32, 0.0f32)),
        (0.0f32..2.0).prop_map(|h| (0.0, h)),
    ];
    [axis.clone(), axis.clone(), axis.clone(), axis].prop_map(|a| {
        (
            std::array::from_fn(|i| a[i].0),
            std::array::from_fn(|i| a[i].1),
        )
    })
}

/// Where an enclosure [lo, hi] from the GPU holds v: ±2^62 stand for ±inf.
fn holds(e: [f32; 2], v: f64) -> bool {
    const BIG: f64 = 4_611_686_018_427_387_904.0;
    let lo = if f64::from(e[0]) <= -BIG {
        f64::NEG_INFINITY
    } else {
        f64::from(e[0])
    };
    let hi = if f64::from(e[1]) >= BIG {
        f64::INFINITY
    } else {
        f64::from(e[1])
    };
    lo <= v && v <= hi
}

/// The corners, the centre and random points of a box.
fn points_of((lo, hi): ([f32; 4], [f32; 4]), rng: &mut Rng) -> Vec<[f64; 4]> {
    let mut points: Vec<[f64; 4]> = (0..16)
        .map(|k| std::array::from_fn(|i| f64::from(if k >> i & 1 == 1 { hi[i] } else { lo[i] })))
        .collect();
    points.push(std::array::from_fn(|i| {
        0.5 * (f64::from(lo[i]) + f64::from(hi[i]))
    }));
    for _ in 0..8 {
        points.push(std::array::from_fn(|i| {
            rng.range(f64::from(lo[i]), f64::from(hi[i]))
        }));
    }
    points
}

/// Checks the GPU's enclosures of `formula` over `boxes` against F and ∇F at points of each.
fn check_enclosures(
    gpu: &Gpu,
    text: &str,
    formula: &CompiledFormula,
    params: &[f64],
    boxes: &[([f32; 4], [f32; 4])],
) {
    let found: Vec<Enclosures> = enclose(gpu, formula, params, boxes).expect("probe runs");
    let mut eval = PointEvaluator::new();
    let mut rng = Rng(0x5eed);
    for (b, e) in boxes.iter().zip(&found) {
        for p in points_of(*b, &mut rng) {
            let mut all = [0.0; 5];
            eval.eval_into(&formula.tape_all, p, params, &mut all);
            let f = eval.eval(&formula.tape_f, p, params);
            if f.is_finite() {
                assert!(
                    holds(e.f, f) && holds(e.f_grad[0], f),
                    "{text}: F({p:?}) = {f} outside the GPU's {:?} / {:?} over {b:?}",
                    e.f,
                    e.f_grad[0]
                );
            }
            for k in 1..5 {
                if all[k].is_finite() && all.iter().all(|v| v.is_finite()) {
                    assert!(
                        holds(e.f_grad[k], all[k]),
                        "{text}: dF/d{}({p:?}) = {} outside the GPU's {:?} over {b:?}",
                        ["x", "y", "z", "w"][k - 1],
                        all[k],
                        e.f_grad[k]
                    );
                }
            }
        }
    }
}

/// For every operation and every example formula, over boxes of every kind, the GPU's
/// enclosures of F and ∇F hold their values at the corners, the centre and random points.
#[test]
fn gpu_enclosures_hold_the_values() {
    let gpu = gpu();
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::deterministic_rng(proptest::test_runner::RngAlgorithm::ChaCha),
    );
    let strategy = proptest::collection::vec(box_strategy(), 400);
    let examples = example_scenes();
    let formulas = OPERATIONS
        .iter()
        .map(|t| (t.to_string(), vec![1.5, -0.25]))
        .chain(examples.iter().map(|(_, s)| {
            let f = CompiledFormula::compile(&s.formula).unwrap();
            (s.formula.clone(), s.param_values(&f.param_names()))
        }));
    for (text, params) in formulas {
        let formula = CompiledFormula::compile(&text).unwrap();
        let params = &params[..formula.params.len().min(params.len())];
        let boxes = strategy.new_tree(&mut runner).unwrap().current();
        check_enclosures(&gpu, &text, &formula, params, &boxes);
    }
}

/// Each pixel's observer plane sampled on a grid of `side`² points over the disk that
/// holds the domain (within the slab, for one), in f64: whether F takes both signs at
/// points inside the domain.
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
    let mut eval = PointEvaluator::new();
    let (mut pos, mut neg) = (false, false);
    for i in 0..side {
        for j in 0..side {
            let sv = reach * (2.0 * (i as f64 + 0.5) / side as f64 - 1.0);
            let tv = reach * (2.0 * (j as f64 + 0.5) / side as f64 - 1.0);
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
) -> fourfold::render::pipeline::Picture {
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

/// Certified pictures' verdicts for `scene` at `side`², on the GPU and the CPU twin.
fn certified_pictures(
    gpu: &Gpu,
    scene: &Scene,
    side: u32,
    budget: u32,
) -> (Uniforms, [Vec<Verdict>; 2]) {
    let mut scene = scene.clone();
    scene.render.certified = true;
    scene.render.cert_budget = budget;
    scene.render.rays = 4;
    let formula = CompiledFormula::compile(&scene.formula).unwrap();
    let prepared = Prepared::new(&formula, &scene).unwrap();
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
        let (u, verdicts) = certified_pictures(&gpu, scene, side, budget);
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
