//! The 16-tree and the sphere hierarchy: soundness, growth, criteria, invariants, budget,
//! cancellation.

mod common;
#[path = "support/unseen.rs"]
mod unseen;

use std::sync::atomic::{AtomicBool, Ordering};

use common::{Rng, build, example_scenes};
use fourfold::CompiledFormula;
use fourfold::eval::{IntervalEvaluator, PointEvaluator};
use fourfold::formula::HESSIAN_PAIRS;
use fourfold::gpu_layout::MARCH_BIT;
use fourfold::render::Rotation4;
use fourfold::scene::{Domain, Scene};
use fourfold::tree::hierarchy::MARCH_LEVELS_ABOVE_FINEST;
use fourfold::tree::{BuildError, BuildSettings, Hierarchy, SphereNode, Touching, Tree16};

/// Points of M found by bisection on random segments of the domain where F changes sign.
fn points_on_manifold(
    f: &CompiledFormula,
    params: &[f64],
    domain: &Domain,
    n: usize,
) -> Vec<[f64; 4]> {
    let mut eval = PointEvaluator::new();
    let mut rng = Rng(77);
    let axes = domain.axes();
    let mut found = Vec::new();
    for _ in 0..n * 50 {
        if found.len() >= n {
            break;
        }
        let a: [f64; 4] = std::array::from_fn(|i| rng.range(axes[i].lo, axes[i].hi));
        let b: [f64; 4] = std::array::from_fn(|i| rng.range(axes[i].lo, axes[i].hi));
        found.extend(root_between(&mut eval, f, params, a, b));
    }
    found
}

/// A point of M on the segment from `a` to `b`, where F takes opposite signs at its ends:
/// found by bisection, and kept only where F is about 0 there (a true root, F continuous
/// across it, not a pole).
fn root_between(
    eval: &mut PointEvaluator,
    f: &CompiledFormula,
    params: &[f64],
    a: [f64; 4],
    b: [f64; 4],
) -> Option<[f64; 4]> {
    let mut fa = eval.eval(&f.tape_f, a, params);
    if !(fa * eval.eval(&f.tape_f, b, params) < 0.0) {
        return None;
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    let at = |t: f64| -> [f64; 4] { std::array::from_fn(|i| a[i] + t * (b[i] - a[i])) };
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let fm = eval.eval(&f.tape_f, at(mid), params);
        if fm.is_nan() {
            break;
        }
        if (fm < 0.0) == (fa < 0.0) {
            (lo, fa) = (mid, fm);
        } else {
            hi = mid;
        }
    }
    let p = at(0.5 * (lo + hi));
    (eval.eval(&f.tape_f, p, params).abs() < 1e-6).then_some(p)
}

#[test]
fn every_point_of_m_lies_in_a_leaf_and_every_leaf_may_hold_m() {
    for (name, scene) in example_scenes() {
        let settings = BuildSettings {
            max_level: 5,
            min_level: 3,
            node_budget: 2_000_000,
        };
        let (f, params, tree) = build(&scene, settings);
        assert!(!tree.is_empty(), "{name}: no tree");
        // (Each changes sign across M: none is told it only touches 0, anywhere.)
        assert_eq!(
            tree.stats.touching(),
            Touching::Nowhere,
            "{name}: {} of the leaves touching",
            tree.stats.touching_share
        );
        let leaves: Vec<_> = tree.leaves().map(|(l, b)| tree.box_of(l, b)).collect();
        let mut eval = IntervalEvaluator::new();
        for bx in &leaves {
            assert!(
                eval.eval(&f.tape_f, bx, &params).contains_zero(),
                "{name}: leaf without 0"
            );
        }
        let points = points_on_manifold(&f, &params, &scene.domain, 200);
        assert!(
            points.len() >= 50,
            "{name}: only {} points found",
            points.len()
        );
        for p in points {
            let inside = leaves.iter().any(|bx| (0..4).all(|i| bx[i].contains(p[i])));
            assert!(inside, "{name}: {p:?} on M is in no leaf");
        }
    }
}

#[test]
fn the_mean_value_form_discards_what_the_natural_extension_cannot_and_keeps_m() {
    // The chapter's formula squares a sum that its other term partly cancels: its natural
    // interval extension is loose, the mean-value form much tighter on small boxes. The
    // glome's sum of squares is enclosed exactly: nothing is left for it to discard.
    let settings = BuildSettings {
        max_level: 5,
        min_level: 5,
        node_budget: 2_000_000,
    };
    for (name, scene) in common::example_scenes_named(&["fig-3-9-left", "glome"]) {
        let (f, params, tree) = build(&scene, settings);
        let discarded = tree.stats.mean_value_discarded;
        if name == "glome" {
            assert_eq!(discarded, 0, "{name}");
        } else {
            assert!(
                discarded * 2 > tree.stats.leaves,
                "{name}: {discarded} discarded, {} leaves",
                tree.stats.leaves
            );
        }
        let leaves: Vec<_> = tree.leaves().map(|(l, b)| tree.box_of(l, b)).collect();
        let points = points_on_manifold(&f, &params, &scene.domain, 400);
        assert!(points.len() >= 100, "{name}: {} points", points.len());
        for p in points {
            let inside = leaves.iter().any(|bx| (0..4).all(|i| bx[i].contains(p[i])));
            assert!(inside, "{name}: {p:?} on M is in no leaf");
        }
    }
}

/// The leaves where F only touches 0 (one-signed over the box and a sliver around it):
/// none where F changes sign across all of M, the unseen scenes (hard ones too) among them, and none where
/// M lies on the boxes' faces (x = 0 on a grid through 0, whose boxes are [0, h] and
/// [−h, 0]); about half of x·y²'s (it crosses 0 along x = 0, touches it along y = 0), all of
/// a square's.
#[test]
fn leaves_where_f_only_touches_zero_are_counted() {
    let settings = BuildSettings {
        max_level: 4,
        min_level: 2,
        node_budget: 2_000_000,
    };
    let mut scenes = unseen::unseen_scenes();
    scenes.extend(unseen::hard_scenes());
    for formula in ["x", "x*y", "x^3", "x*|x|", "x + y", "x*y - z*w", "sin(x)"] {
        scenes.push((formula.to_string(), Scene::from_formula(formula)));
    }
    for (name, scene) in scenes {
        let (_, _, tree) = build(&scene, settings);
        let s = &tree.stats;
        assert!(s.leaves > 0, "{name}: no leaves");
        assert_eq!(
            s.touching_share, 0.0,
            "{name}: {} of the leaves",
            s.touching_share
        );
        assert_eq!(s.touching(), Touching::Nowhere, "{name}");
    }
    for (formula, touching, share) in [
        ("x*y^2", Touching::Partly, 0.3..0.7),
        ("(x^2 + y^2 + z^2 - 1)*w^2", Touching::Partly, 0.5..1.0),
        (
            "(x^2 + y^2 + z^2 + w^2 - 1)^2",
            Touching::Everywhere,
            1.0..1.01,
        ),
    ] {
        let (_, _, tree) = build(&Scene::from_formula(formula), settings);
        let s = &tree.stats;
        assert!(
            s.touching() == touching && share.contains(&s.touching_share),
            "{formula}: {:?}, {} of the leaves",
            s.touching(),
            s.touching_share
        );
    }
}

fn glome() -> Scene {
    let mut scene = Scene::from_formula("x^2 + y^2 + z^2 + w^2 = 1");
    scene.domain = Domain::parse_list("-1.5,1.5,-1.5,1.5,-1.5,1.5,-1.5,1.5").unwrap();
    scene
}

#[test]
fn uniform_glome_grows_like_a_three_manifold() {
    let mut leaves = Vec::new();
    for n in 3..=6 {
        let settings = BuildSettings {
            max_level: n,
            min_level: n,
            node_budget: 4_000_000,
        };
        let (_, _, tree) = build(&glome(), settings);
        assert_eq!(tree.stats.leaves_per_level.len() as u32, n + 1);
        assert_eq!(
            tree.stats.leaves,
            *tree.stats.leaves_per_level.last().unwrap()
        );
        leaves.push(tree.stats.leaves as f64);
    }
    for pair in leaves.windows(2) {
        let ratio = pair[1] / pair[0];
        // A 3-manifold: halving the box side multiplies the boxes it meets by about 2³.
        assert!(
            (6.0..=10.0).contains(&ratio),
            "leaf growth {ratio} per level: {leaves:?}"
        );
    }
}

#[test]
fn the_chapters_criteria_stop_where_the_gradient_excludes_zero() {
    let settings = BuildSettings {
        max_level: 6,
        min_level: 0,
        node_budget: 4_000_000,
    };
    let (f, params, tree) = build(&glome(), settings);
    let mut eval = IntervalEvaluator::new();
    let mut out = [fourfold::eval::Interval::EMPTY; 5];
    for (level, b) in tree.leaves() {
        eval.eval_into(&f.tape_all, &tree.box_of(level, b), &params, &mut out);
        let open = out[1..].iter().all(|g| g.contains_zero());
        // A leaf above the maximum level is one where some partial excludes 0.
        assert!(
            level == 6 || !open,
            "leaf at level {level} still has 0 in every partial"
        );
    }
    // The glome's gradient vanishes only at the origin, outside M: refinement stops early.
    assert!(
        tree.stats.leaves_per_level.len() < 7,
        "{:?}",
        tree.stats.leaves_per_level
    );
    assert_eq!(tree.stats.singular_boxes, 0);
}

#[test]
fn hierarchy_spheres_nest_and_skips_walk_depth_first() {
    let settings = BuildSettings {
        max_level: 5,
        min_level: 2,
        node_budget: 2_000_000,
    };
    for (name, scene) in example_scenes() {
        let (_, _, tree) = build(&scene, settings);
        let h = Hierarchy::from_tree_at(&tree, u32::MAX);
        assert_eq!(h.march_level, h.finest_level());
        assert_eq!(h.nodes.len() as u64, tree.stats.nodes, "{name}");
        // The default hierarchy stops at the march level: the same nodes, in the same order,
        // without the deeper ones, with skips that step over the same subtrees.
        let cut = Hierarchy::from_tree(&tree);
        assert_eq!(
            cut.march_level,
            h.finest_level().saturating_sub(MARCH_LEVELS_ABOVE_FINEST)
        );
        let kept: Vec<usize> = (0..h.nodes.len())
            .filter(|&i| h.nodes[i].level() <= cut.march_level)
            .collect();
        assert_eq!(cut.nodes.len(), kept.len(), "{name}: nodes kept");
        let new_index = |old: usize| kept.partition_point(|&k| k < old);
        for (j, &i) in kept.iter().enumerate() {
            let (a, b) = (&h.nodes[i], &cut.nodes[j]);
            assert_eq!(
                (a.center, a.meta & !MARCH_BIT),
                (b.center, b.meta & !MARCH_BIT),
                "{name}: node {i}"
            );
            assert_eq!(
                b.is_marched(),
                b.is_leaf() || b.level() == cut.march_level,
                "{name}: node {j} marched"
            );
            assert_eq!(
                b.skip as usize,
                new_index(a.skip as usize),
                "{name}: skip of {i}"
            );
            if b.level() == cut.march_level {
                assert_eq!(
                    b.skip as usize,
                    j + 1,
                    "{name}: march box {j} keeps children"
                );
            }
        }
        // Parent of each node, from the depth-first order and skips.
        let mut visits = vec![0u32; h.nodes.len()];
        let mut stack: Vec<usize> = Vec::new();
        for (i, node) in h.nodes.iter().enumerate() {
            while let Some(&top) = stack.last() {
                if (h.nodes[top].skip as usize) <= i {
                    stack.pop();
                } else {
                    break;
                }
            }
            if let Some(&parent) = stack.last() {
                let p = &h.nodes[parent];
                assert_eq!(node.level(), p.level() + 1, "{name}: child level");
                assert!(node.skip <= p.skip, "{name}: subtree escapes its parent");
                let d: f32 = (0..4)
                    .map(|a| (node.center[a] - p.center[a]).powi(2))
                    .sum::<f32>()
                    .sqrt();
                assert!(
                    d + h.radius(node) <= h.radius(p) * 1.0001,
                    "{name}: child sphere outside parent"
                );
            }
            // The sphere holds the box.
            let half = h.levels[node.level() as usize].half;
            let corner: f32 = half.iter().map(|v| v * v).sum::<f32>().sqrt();
            assert!(corner <= h.radius(node) * 1.0001);
            assert_eq!(
                node.is_leaf(),
                node.skip as usize == i + 1,
                "{name}: leaf flag"
            );
            if !node.is_leaf() {
                stack.push(i);
            }
        }
        // A walk that enters every node visits each once.
        let mut i = 0;
        while i < h.nodes.len() {
            visits[i] += 1;
            i += 1;
        }
        assert!(visits.iter().all(|v| *v == 1));
        // A walk that skips every subtree visits only the root's siblings: just the root.
        assert_eq!(h.nodes[0].skip as usize, h.nodes.len(), "{name}: root skip");
    }
}

fn dense() -> Scene {
    let mut scene = Scene::from_formula("sin(20x)sin(20y)sin(20z)sin(20w)");
    scene.domain = Domain::parse_list("-1,1,-1,1,-1,1,-1,1").unwrap();
    scene
}

#[test]
fn the_node_budget_bounds_a_dense_zero_set() {
    let settings = BuildSettings {
        max_level: 10,
        min_level: 10,
        node_budget: 200_000,
    };
    let (_, _, tree) = build(&dense(), settings);
    assert!(tree.stats.budget_hit);
    assert!(tree.stats.nodes <= 200_000, "{} nodes", tree.stats.nodes);
    // Fair: every leaf is on the same level (no corner refined deeper than another).
    let leaf_levels: Vec<usize> = tree
        .stats
        .leaves_per_level
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(l, _)| l)
        .collect();
    assert_eq!(leaf_levels.len(), 1, "{:?}", tree.stats.leaves_per_level);
}

#[test]
fn a_build_can_be_cancelled() {
    let f = CompiledFormula::compile(&dense().formula).unwrap();
    let cancel = AtomicBool::new(false);
    let settings = BuildSettings {
        max_level: 10,
        min_level: 10,
        node_budget: 50_000_000,
    };
    let result = Tree16::build(
        &f,
        &[],
        &dense().domain.to_box(),
        settings,
        &cancel,
        Some(&|level, _| {
            if level >= 3 {
                cancel.store(true, Ordering::Relaxed);
            }
        }),
    );
    assert_eq!(result.unwrap_err(), BuildError::Cancelled);
}

#[test]
fn no_surface_gives_an_empty_tree() {
    let mut scene = Scene::from_formula("x^2 + y^2 + z^2 + w^2 + 1");
    scene.domain = Domain::parse_list("-1,1,-1,1,-1,1,-1,1").unwrap();
    let (_, _, tree) = build(
        &scene,
        BuildSettings {
            max_level: 5,
            min_level: 0,
            node_budget: 1000,
        },
    );
    assert!(tree.is_empty());
    assert!(Hierarchy::from_tree(&tree).is_empty());
}

/// Every node of `scene`'s tree refined to levels `min..=max`, with its slope and curvature
/// bounds, and the formula and parameters.
fn bounded_hierarchy(
    scene: &Scene,
    min_level: u32,
    max_level: u32,
) -> (CompiledFormula, Vec<f64>, Hierarchy) {
    let (f, params, tree) = build(
        scene,
        BuildSettings {
            max_level,
            min_level,
            node_budget: 200_000,
        },
    );
    let mut h = Hierarchy::from_tree_at(&tree, u32::MAX);
    h.bound_slopes(&f, &params);
    (f, params, h)
}

/// A random point of node `node`'s box.
fn point_in(h: &Hierarchy, node: &SphereNode, rng: &mut Rng) -> [f64; 4] {
    let half = h.levels[node.level() as usize].half;
    std::array::from_fn(|k| {
        let (c, r) = (f64::from(node.center[k]), f64::from(half[k]));
        rng.range(c - r, c + r)
    })
}

#[test]
fn slope_and_curvature_bounds_hold_at_sampled_points_of_every_box() {
    // Hierarchy::slopes bound |∂F/∂x_k| and Hierarchy::curvature ∂²F/∂x_i∂x_j over each box:
    // the ray caster steps over samples on that promise, so a bound inside a real value
    // would lose roots.
    let mut eval = PointEvaluator::new();
    let mut rng = Rng(2024);
    for (name, scene) in example_scenes() {
        let (f, params, h) = bounded_hierarchy(&scene, 3, 4);
        assert_eq!(h.slopes.len(), h.nodes.len(), "{name}");
        assert_eq!(h.curvature.len(), h.nodes.len(), "{name}");
        let (mut bounded, mut bent) = (0, 0);
        for (i, node) in h.nodes.iter().enumerate() {
            let slope = h.slope(i);
            if slope.iter().all(|s| s.is_finite()) {
                bounded += 1;
            }
            let (lo, hi) = h.curvature(i).pairs();
            if h.curvature(i).is_bounded() {
                bent += 1;
            }
            for _ in 0..8 {
                let p = point_in(&h, node, &mut rng);
                let mut out = [0.0; 15];
                eval.eval_into(&f.tape_second, p, &params, &mut out);
                for (k, &(a, b)) in HESSIAN_PAIRS.iter().enumerate() {
                    let v = out[k + 5];
                    assert!(
                        !v.is_finite() || (f64::from(lo[k]) <= v && v <= f64::from(hi[k])),
                        "{name}: node {i}, ∂²F/∂x{a}∂x{b} = {v} at {p:?} outside [{}, {}]",
                        lo[k],
                        hi[k]
                    );
                }
                for k in 0..4 {
                    if out[k + 1].is_finite() {
                        assert!(
                            out[k + 1].abs() <= f64::from(slope[k]),
                            "{name}: node {i}, ∂F/∂x{k} = {} at {p:?} above its bound {}",
                            out[k + 1],
                            slope[k]
                        );
                    }
                }
            }
        }
        eprintln!(
            "{name}: {bounded} of {} boxes bounded, {bent} with curvature",
            h.nodes.len()
        );
        // The polynomial examples are smooth: a bound on every box (the ones with sqrt of a
        // sum of squares have none where it may be 0).
        if [
            "glome",
            "fig-3-9-left",
            "hyperplane",
            "duocylinder",
            "fermat-quartic",
        ]
        .contains(&name)
        {
            assert_eq!(bounded, h.nodes.len(), "{name}");
            // Curvature is bound for the marched boxes (here the leaves), and all of them.
            let marched = h.nodes.iter().filter(|n| n.is_marched()).count();
            assert_eq!(bent, marched, "{name}");
        }
    }
}

#[test]
fn curvature_in_the_observer_plane_bounds_every_ray_of_the_plane() {
    // Curvature::in_plane gives A, B, C such that d2F/dt2 along d = a n1 + b n2 lies in
    // a^2 A + ab B + b^2 C: the tile lists' boxes carry them, and the march steps over
    // samples on that promise.
    let mut eval = PointEvaluator::new();
    let mut rng = Rng(77);
    for (name, scene) in example_scenes() {
        let (f, params, h) = bounded_hierarchy(&scene, 3, 3);
        let mut checked = 0;
        for (i, node) in h.nodes.iter().enumerate().step_by(7) {
            let curvature = h.curvature(i);
            let angles: [f64; 6] = std::array::from_fn(|_| rng.range(-3.2, 3.2));
            let rotation = Rotation4::from_angles(angles);
            let (n1, n2) = (rotation.row(2), rotation.row(3));
            let [al, ah, bl, bh, cl, ch] = curvature.in_plane(n1, n2).map(f64::from);
            if !curvature.is_bounded() {
                assert!(al.is_infinite() && ah.is_infinite(), "{name}: node {i}");
                continue;
            }
            for _ in 0..6 {
                let p = point_in(&h, node, &mut rng);
                let phi = rng.range(0.0, std::f64::consts::TAU);
                let (a, b) = (phi.cos(), phi.sin());
                let d: [f64; 4] = std::array::from_fn(|k| a * n1[k] + b * n2[k]);
                let mut out = [0.0; 15];
                eval.eval_into(&f.tape_second, p, &params, &mut out);
                let bend: f64 = HESSIAN_PAIRS
                    .iter()
                    .enumerate()
                    .map(|(k, &(x, y))| {
                        let (x, y) = (usize::from(x), usize::from(y));
                        out[k + 5] * d[x] * d[y] * if x == y { 1.0 } else { 2.0 }
                    })
                    .sum();
                if !bend.is_finite() {
                    continue;
                }
                let ab = a * b;
                let lo = a * a * al + (ab * bl).min(ab * bh) + b * b * cl;
                let hi = a * a * ah + (ab * bl).max(ab * bh) + b * b * ch;
                let slack = 1e-9 * (1.0 + bend.abs());
                assert!(
                    lo - slack <= bend && bend <= hi + slack,
                    "{name}: node {i}: d2F/dt2 = {bend} outside [{lo}, {hi}]"
                );
                checked += 1;
            }
        }
        eprintln!("{name}: {checked} samples checked");
    }
    // For the glome H = 2I exactly: A = C = 2, B = 0, for any observer plane.
    let (_, _, h) = bounded_hierarchy(&glome(), 2, 2);
    let rotation = Rotation4::from_angles([0.3, 1.1, -0.7, 2.0, 0.5, -1.3]);
    let leaf = (0..h.nodes.len())
        .find(|&i| h.curvature(i).is_bounded())
        .expect("a box with curvature bounds");
    let form = h.curvature(leaf).in_plane(rotation.row(2), rotation.row(3));
    for (v, want) in form.iter().zip([2.0, 2.0, 0.0, 0.0, 2.0, 2.0]) {
        assert!((f64::from(*v) - want).abs() < 1e-4, "{form:?}");
    }
}

#[test]
fn slopes_are_not_bounded_where_f_may_be_undefined_or_jump() {
    // A bound on the derivative says nothing across a jump or a gap in F's domain: there
    // the ray caster must take every sample. Nor does a bound on the second derivatives
    // across a kink (where ∇F jumps).
    let domain = Domain::parse_list("-1,1,-1,1,-1,1,-1,1").unwrap();
    let unbounded_on_the_root = |formula: &str| {
        let mut scene = Scene::from_formula(formula);
        scene.domain = domain;
        let (f, params, tree) = build(
            &scene,
            BuildSettings {
                max_level: 0,
                min_level: 0,
                node_budget: 10,
            },
        );
        let mut h = Hierarchy::from_tree(&tree);
        h.bound_slopes(&f, &params);
        let bent = h.curvature(0).is_bounded();
        (h.slope(0).iter().all(|s| s.is_infinite()), bent)
    };
    for formula in [
        "step(x) - 0.5 + 0*y",
        "sign(x) + 0.5*y",
        "atan2(y, x) - 3",
        "sqrt(x + 0.5)^3 - 0.1 + 0*y",
        "(x + 0.5)^0.5 - 0.5",
        "ln(x + 0.5) + y",
        "asin(2*x) + y",
        "1/x + y",
        "exp(100*x) - 1 + y",
    ] {
        assert_eq!(unbounded_on_the_root(formula), (true, false), "{formula}");
    }
    for formula in [
        "x^2 + y^2 + z^2 + w^2 - 1",
        "sqrt(x + 2) - 1.2",
        "step(x + 2) - 0.5 + y",
    ] {
        assert_eq!(unbounded_on_the_root(formula), (false, true), "{formula}");
    }
    // Kinks: F is continuous, ∇F jumps.
    for formula in [
        "abs(x) - 0.5",
        "0.5 - abs(x) + y",
        "min(x, y) + 0.2",
        "max(x^2, y) - 0.1",
    ] {
        assert_eq!(unbounded_on_the_root(formula), (false, false), "{formula}");
    }
}

#[test]
fn a_root_marched_whole_for_its_own_bounds_has_every_descendant_bounded() {
    // Hierarchy::for_formula marches the root whole, without working out its descendants'
    // bounds, when its slope bound is finite and F'' bounded over it: the cut would march
    // it whole whatever their bounds, so long as they are finite, which an enclosure over a
    // box inside the root is. Checked on the examples and on formulas written for this.
    let settings = BuildSettings {
        max_level: 4,
        min_level: 4,
        node_budget: 4_000_000,
    };
    let mut scenes = example_scenes();
    for formula in [
        "x^6 + y^6 + z^6 + w^6 + 4x^2 y^2 z^2 - 1",
        "cos(3x) + cos(3y) + cos(3z) + cos(3w)",
        "sqrt(x^2 + y^2 + 4) - 2.2 + z*w",
        "exp(-x^2 - y^2) - 0.5 + 0.1*z - w^3",
        "abs(x) + y^2 - z*w - 0.3",
    ] {
        scenes.push((formula, Scene::from_formula(formula)));
    }
    let mut whole = 0;
    for (name, scene) in scenes {
        let (f, params, tree) = build(&scene, settings);
        if tree.is_empty() {
            continue;
        }
        let cut = Hierarchy::for_formula(&tree, &f, &params);
        // The root alone, marched, with its bounds; and every box down to the march level.
        let mut root = Hierarchy::from_tree_at(&tree, 0);
        root.bound_slopes(&f, &params);
        let mut every = Hierarchy::from_tree(&tree);
        every.bound_slopes(&f, &params);
        let finite = |h: &Hierarchy, i: usize| h.slope(i).iter().sum::<f32>().is_finite();
        let root_bounded = finite(&root, 0) && root.curvature(0).is_bounded();
        if root_bounded {
            whole += 1;
            assert_eq!(cut.nodes.len(), 1, "{name}");
            assert!((0..every.nodes.len()).all(|i| finite(&every, i)), "{name}");
            assert_eq!(
                (cut.slope(0), cut.curvature(0)),
                (root.slope(0), root.curvature(0)),
                "{name}"
            );
        }
    }
    assert!(whole >= 5, "{whole} roots marched whole");
}

#[test]
fn the_default_cut_marches_each_leaf_once_and_coarser_where_slopes_allow() {
    // Hierarchy::for_formula marches some boxes above the march level: every point of the
    // tree's leaves must still lie in exactly one marched box, none of which keeps children.
    let settings = BuildSettings {
        max_level: 5,
        min_level: 5,
        node_budget: 4_000_000,
    };
    for (name, scene) in example_scenes() {
        let (f, params, tree) = build(&scene, settings);
        let cut = Hierarchy::for_formula(&tree, &f, &params);
        let full = Hierarchy::from_tree_at(&tree, u32::MAX);
        assert_eq!(cut.slopes.len(), cut.nodes.len(), "{name}");
        assert_eq!(
            cut.nodes[0].skip as usize,
            cut.nodes.len(),
            "{name}: root skip"
        );
        let key = |n: &fourfold::tree::SphereNode| (n.level(), n.center.map(f32::to_bits));
        let marched: std::collections::HashSet<_> = cut
            .nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| n.is_marched())
            .map(|(j, n)| {
                assert_eq!(
                    n.skip as usize,
                    j + 1,
                    "{name}: marched box {j} keeps children"
                );
                key(n)
            })
            .collect();
        let unmarched_leaves = cut
            .nodes
            .iter()
            .filter(|n| n.is_leaf() && !n.is_marched())
            .count();
        assert_eq!(unmarched_leaves, 0, "{name}");
        // Every leaf of the full tree: exactly one marched box among it and its ancestors.
        let mut stack: Vec<usize> = Vec::new();
        for (i, node) in full.nodes.iter().enumerate() {
            while stack
                .last()
                .is_some_and(|&t| full.nodes[t].skip as usize <= i)
            {
                stack.pop();
            }
            if node.is_leaf() {
                let covering = stack
                    .iter()
                    .map(|&a| &full.nodes[a])
                    .chain(std::iter::once(node))
                    .filter(|n| marched.contains(&key(n)))
                    .count();
                assert_eq!(covering, 1, "{name}: leaf {i} in {covering} marched boxes");
            } else {
                stack.push(i);
            }
        }
        let uniform = Hierarchy::from_tree(&tree);
        eprintln!(
            "{name}: {} boxes marched ({} at the march level {})",
            cut.march_boxes(),
            uniform.march_boxes(),
            uniform.march_level
        );
        assert!(cut.march_boxes() <= uniform.march_boxes(), "{name}");
        // The cover (what the tile lists bin each marched box by): together, exactly the
        // boxes of the uniform cut at its level (not above the march level), each inside
        // its marched box.
        let cover_level = cut.cover[0].iter().map(|c| c.level).max().unwrap_or(0);
        assert!(cover_level >= uniform.march_level, "{name}: cover level");
        let mut covered: Vec<_> = cut.cover[0]
            .iter()
            .map(|c| (c.level, c.center.map(f32::to_bits)))
            .collect();
        let mut expected: Vec<_> = Hierarchy::from_tree_at(&tree, cover_level)
            .nodes
            .iter()
            .filter(|n| n.is_marched())
            .map(key)
            .collect();
        covered.sort_unstable();
        expected.sort_unstable();
        assert!(
            covered == expected,
            "{name}: the cover is not the uniform cut at level {cover_level}"
        );
        for c in cut.cover.iter().flatten() {
            let center = c.center;
            let m = &cut.nodes[c.node as usize];
            assert!(m.is_marched(), "{name}: cover of a box that is not marched");
            let (mh, ch) = (
                cut.levels[m.level() as usize].half,
                cut.levels[c.level as usize].half,
            );
            assert!(
                (0..4).all(|k| (center[k] - m.center[k]).abs() + ch[k] <= mh[k] * (1.0 + 1e-5)),
                "{name}: a cover box outside its marched box"
            );
        }
        // Each coarser cover's boxes hold consecutive runs of the finer one's (the
        // binning skips a run whose parent it has already covered): every finer box once,
        // in order, inside its parent and of the same marched box.
        for k in 1..cut.cover.len() {
            let (fine, coarse) = (&cut.cover[k - 1], &cut.cover[k]);
            assert_eq!(coarse[0].first_child, 0, "{name}: cover {k}");
            for (j, parent) in coarse.iter().enumerate() {
                let end = coarse
                    .get(j + 1)
                    .map_or(fine.len(), |p| p.first_child as usize);
                let children = &fine[parent.first_child as usize..end];
                assert!(
                    !children.is_empty(),
                    "{name}: cover {k}, box {j} has no children"
                );
                let ph = cut.levels[parent.level as usize].half;
                for c in children {
                    let ch = cut.levels[c.level as usize].half;
                    assert_eq!(c.node, parent.node, "{name}: cover {k}");
                    assert!(
                        (0..4).all(|i| {
                            (c.center[i] - parent.center[i]).abs() + ch[i] <= ph[i] * (1.0 + 1e-5)
                        }),
                        "{name}: cover {k}, a child outside its parent"
                    );
                }
            }
        }
        // Where F is a polynomial the slopes allow coarser boxes than the march level.
        if ["glome", "fig-3-9-left", "hyperplane"].contains(&name) {
            assert!(cut.march_boxes() * 4 <= uniform.march_boxes(), "{name}");
        }
    }
}

/// The web page builds in slices between frames; the tree and hierarchy must be the ones a
/// build in one go makes, budget stop included.
#[test]
fn a_build_in_slices_is_the_build_in_one_go() {
    use fourfold::render::Prepared;
    use std::time::Duration;
    for (name, scene) in example_scenes() {
        let f = CompiledFormula::compile(&scene.formula).unwrap();
        let budget_stop = BuildSettings {
            node_budget: 3000,
            ..scene.tree.into()
        };
        for (settings, split) in [(scene.tree.into(), true), (budget_stop, false)] {
            let whole =
                Prepared::build(&f, &scene, settings, &AtomicBool::new(false), None).unwrap();
            let mut steps = Prepared::steps(&f, &scene, settings).unwrap();
            let mut slices = 0;
            let sliced = loop {
                slices += 1;
                if let Some(p) = steps.step(&f, Duration::ZERO).unwrap() {
                    break p;
                }
            };
            assert_eq!(sliced.tree.levels, whole.tree.levels, "{name}");
            let (mut a, mut b) = (sliced.tree.stats.clone(), whole.tree.stats.clone());
            (a.build_ms, b.build_ms) = (0.0, 0.0);
            assert_eq!(a, b, "{name}");
            assert_eq!(sliced.hierarchy.nodes, whole.hierarchy.nodes, "{name}");
            // (At the scene's own settings some level is cut into slices.)
            assert!(
                !split || slices > whole.tree.stats.nodes_per_level.len(),
                "{name}: {slices} slices"
            );
        }
    }
}

/// A tree built within a slice's hyperplane (`render --slice`'s) holds only boxes that meet
/// it, less than half the whole domain's, and every point of M on the hyperplane (found by
/// bisection on segments within it) lies in one of its leaves; on the examples, each seen
/// through its own turned view, sliced at 0.2 and at −0.35.
#[test]
fn a_tree_within_a_slice_holds_the_slice_of_m_and_little_else() {
    let settings = BuildSettings {
        max_level: 5,
        min_level: 3,
        node_budget: 2_000_000,
    };
    for (name, mut scene) in example_scenes() {
        for offset in [0.2, -0.35] {
            scene.view.slice = Some(offset);
            let region = fourfold::render::view_region(&scene).expect("a slice has a region");
            let f = CompiledFormula::compile(&scene.formula).unwrap();
            let params = scene.param_values(&f.param_names());
            let domain = scene.domain.to_box();
            let cancel = AtomicBool::new(false);
            let within =
                Tree16::build_within(&f, &params, &domain, Some(region), settings, &cancel, None)
                    .unwrap();
            let whole = Tree16::build(&f, &params, &domain, settings, &cancel, None).unwrap();
            let boxes: Vec<_> = (0..within.levels.len())
                .flat_map(|l| within.levels[l].iter().map(move |b| (l as u32, b)))
                .map(|(l, b)| within.box_of(l, b))
                .collect();
            assert!(
                boxes.iter().all(|bx| region.meets(bx)),
                "{name}: a box off the slice"
            );
            assert!(
                within.stats.nodes * 2 < whole.stats.nodes,
                "{name}, slice {offset}: {} nodes within, {} in all",
                within.stats.nodes,
                whole.stats.nodes
            );
            let leaves: Vec<_> = within.leaves().map(|(l, b)| within.box_of(l, b)).collect();
            let points = points_on_slice(&f, &params, &scene, 100);
            assert!(
                points.len() >= 20,
                "{name}, slice {offset}: {} points",
                points.len()
            );
            for p in points {
                let inside = leaves.iter().any(|bx| (0..4).all(|i| bx[i].contains(p[i])));
                assert!(inside, "{name}, slice {offset}: {p:?} on M is in no leaf");
            }
        }
    }
}

/// Points of M on the scene's slice: bisection on segments between random points of the
/// domain moved onto the slice's hyperplane along n2.
fn points_on_slice(f: &CompiledFormula, params: &[f64], scene: &Scene, n: usize) -> Vec<[f64; 4]> {
    let n2 = Rotation4::from_angles(scene.view.angles).row(3);
    let (c, offset) = (scene.domain.center(), scene.view.slice.unwrap());
    let axes = scene.domain.axes();
    let mut rng = Rng(91);
    let mut eval = PointEvaluator::new();
    let mut on_slice = || {
        let p: [f64; 4] = std::array::from_fn(|i| rng.range(axes[i].lo, axes[i].hi));
        let along: f64 = (0..4).map(|i| (p[i] - c[i]) * n2[i]).sum();
        let q: [f64; 4] = std::array::from_fn(|i| p[i] + (offset - along) * n2[i]);
        (0..4)
            .all(|i| (axes[i].lo..=axes[i].hi).contains(&q[i]))
            .then_some(q)
    };
    let mut found = Vec::new();
    for _ in 0..n * 100 {
        if found.len() >= n {
            break;
        }
        if let (Some(a), Some(b)) = (on_slice(), on_slice()) {
            found.extend(root_between(&mut eval, f, params, a, b));
        }
    }
    found
}
