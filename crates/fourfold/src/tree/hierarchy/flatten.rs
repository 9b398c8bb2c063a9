//! Flattening a 16-tree into its sphere hierarchy (docs/method.md §3): the kept boxes in
//! depth-first order, each with a skip index to the next node outside its subtree, so a
//! shader walks it with a loop and no stack; down to the march level, with the boxes each
//! marched box covers, and with slope and curvature bounds where there is a formula.

use rayon::prelude::*;

use crate::eval::IntervalEvaluator;
use crate::formula::CompiledFormula;
use crate::gpu_layout::{Curvature, LEAF_BIT, LevelInfo, MARCH_BIT, SphereNode};
use crate::tree::build::Tree16;

use super::bounds::{box_curvature, box_slope};
use super::cut::{always_marched, cut};
use super::data::{
    CERTIFY_LEVELS_ABOVE, CoverBox, Hierarchy, MARCH_BOXES, MARCH_LEVELS_ABOVE_FINEST, level_half,
};

impl Hierarchy {
    /// Flattens `tree` (empty tree → empty hierarchy) down to the default march level:
    /// [`MARCH_LEVELS_ABOVE_FINEST`] above the finest level, or higher where that level holds
    /// more than [`MARCH_BOXES`] nodes. The ray caster never visits deeper nodes, so they are
    /// not kept (a GPU buffer 64x smaller or more, and trees too large for the device as a
    /// whole fit). No slope bounds: see [`Hierarchy::for_formula`].
    pub fn from_tree(tree: &Tree16) -> Self {
        Self::flatten(tree, default_march_level(tree), None)
    }

    /// The boxes certified pixels search (docs/method.md §5.9): `tree` flattened down to
    /// [`CERTIFY_LEVELS_ABOVE`] levels above the deepest level with at most [`MARCH_BOXES`]
    /// boxes, each box there (and each leaf above) searched whole. Finer than the ray
    /// caster's cut, which is often the root box. Each searched box gets its bounds on F's
    /// second derivatives (`formula` with parameter values `params`, the tree's): with them
    /// the second-order forms prove cells near M that the mean-value form would split
    /// (docs/method.md §5.9).
    pub fn for_certifying(tree: &Tree16, formula: &CompiledFormula, params: &[f64]) -> Self {
        let deepest = tree.levels.len().saturating_sub(1);
        let level = deepest_within_budget(tree, deepest).saturating_sub(CERTIFY_LEVELS_ABOVE);
        let mut hierarchy = Self::flatten(tree, level as u32, None);
        hierarchy.bound_curvature(formula, params);
        hierarchy
    }

    /// Flattens `tree` down to `march_level` (clamped to the finest level; the finest level
    /// keeps every node and marches the leaves themselves). No slope bounds.
    pub fn from_tree_at(tree: &Tree16, march_level: u32) -> Self {
        Self::flatten(tree, march_level, None)
    }

    /// The hierarchy the ray caster draws `tree` of `formula` (with parameter values
    /// `params`, the tree's) with: down to the default march level, with slope and
    /// curvature bounds, and coarser where they allow: a node is marched as one box, its
    /// subtree dropped, when it and its descendants at the march level have slope bounds
    /// and it has curvature bounds, or its slope bound is at most [`COARSEN_LOOSENESS`]
    /// times the largest of its descendants'. (With the bounds the march steps over empty
    /// space, and with curvature bounds close to a root too, so a large box costs little
    /// more than its descendants would, and saves their visits: the polynomial examples are
    /// marched as one box. Where F has no bounds, as at a singular point, or a kink, the
    /// boxes stay small.)
    pub fn for_formula(tree: &Tree16, formula: &CompiledFormula, params: &[f64]) -> Self {
        Self::flatten(tree, default_march_level(tree), Some((formula, params)))
    }

    fn flatten(
        tree: &Tree16,
        march_level: u32,
        formula: Option<(&CompiledFormula, &[f64])>,
    ) -> Self {
        let geometry = FlatGeometry::of(tree);
        let levels = geometry.level_table(tree.levels.len().max(1));
        let march_level = march_level.min(levels.len() as u32 - 1);
        let depth = (march_level as usize + 1).min(tree.levels.len());
        let mut hierarchy = Self {
            nodes: Vec::new(),
            levels,
            march_level,
            base_half: geometry.base_half,
            pad: geometry.pad,
            slopes: Vec::new(),
            curvature: Vec::new(),
            cover: Vec::new(),
            continuous: formula.is_some_and(|(f, params)| {
                let mut eval = IntervalEvaluator::new();
                eval.eval(&f.tape_f, &tree.domain, params);
                eval.continuous_on_last_box(&f.tape_f)
            }),
        };
        if tree.is_empty() {
            return hierarchy;
        }
        // The cover's level: the deepest with at most MARCH_BOXES boxes (the binning's cost
        // grows with their number), not above the march level.
        let cover_level = deepest_within_budget(tree, tree.levels.len() - 1).max(depth - 1);
        let centers: Vec<Vec<[f32; 4]>> = tree.levels[..depth]
            .iter()
            .enumerate()
            .map(|(l, boxes)| {
                boxes
                    .iter()
                    .map(|b| geometry.center(l as u32, b.coords))
                    .collect()
            })
            .collect();
        let curvature_of = |eval: &mut IntervalEvaluator, l: usize, i: usize| match formula {
            Some((formula, params)) => box_curvature(
                eval,
                formula,
                params,
                centers[l][i],
                hierarchy.levels[l].half,
            ),
            None => Curvature::NONE,
        };
        let (slopes, marched, known) = match root_marched_whole(&hierarchy, &centers, formula) {
            Some((slope, curvature)) => {
                let (marched, known) = only_root(tree, depth, curvature);
                (vec![vec![slope]], marched, known)
            }
            None => {
                // Slope bounds of every box down to the march level, and which boxes are
                // marched.
                let slopes: Vec<Vec<[f32; 4]>> = match formula {
                    Some((formula, params)) => centers
                        .iter()
                        .enumerate()
                        .map(|(l, c)| {
                            let half = hierarchy.levels[l].half;
                            c.par_iter()
                                .map_init(IntervalEvaluator::new, |eval, &center| {
                                    box_slope(eval, formula, params, center, half)
                                })
                                .collect()
                        })
                        .collect(),
                    None => Vec::new(),
                };
                let (marched, known) = cut(tree, depth, &slopes, curvature_of);
                (slopes, marched, known)
            }
        };
        let walk = DepthFirst::walk(tree, &marched, &centers, &slopes, cover_level);
        hierarchy.cover = cover_levels(walk.cover, &walk.nodes, &geometry);
        // The marched boxes' curvature: what the cut worked out, the rest now.
        if formula.is_some() {
            hierarchy.curvature = walk
                .nodes
                .par_iter()
                .zip(&walk.origin)
                .map_init(IntervalEvaluator::new, |eval, (node, &(l, i))| {
                    if !node.is_marched() {
                        return Curvature::NONE;
                    }
                    known[l][i].unwrap_or_else(|| curvature_of(eval, l, i))
                })
                .collect();
        }
        hierarchy.nodes = walk.nodes;
        hierarchy.slopes = walk.slopes;
        hierarchy
    }

    /// Fills [`Hierarchy::slopes`] and [`Hierarchy::curvature`] for `formula` with
    /// parameter values `params` (the ones the tree was built with), keeping the cut: one
    /// interval evaluation of F and one of F and ∇F per node, and one of F's second
    /// derivatives per marched node.
    pub fn bound_slopes(&mut self, formula: &CompiledFormula, params: &[f64]) {
        let slopes = self
            .nodes
            .par_iter()
            .map_init(IntervalEvaluator::new, |eval, node| {
                let half = self.levels[node.level() as usize].half;
                box_slope(eval, formula, params, node.center, half)
            })
            .collect();
        self.slopes = slopes;
        self.bound_curvature(formula, params);
    }

    fn bound_curvature(&mut self, formula: &CompiledFormula, params: &[f64]) {
        let curvature = self
            .nodes
            .par_iter()
            .map_init(IntervalEvaluator::new, |eval, node| {
                if !node.is_marched() {
                    return Curvature::NONE;
                }
                let half = self.levels[node.level() as usize].half;
                box_curvature(eval, formula, params, node.center, half)
            })
            .collect();
        self.curvature = curvature;
    }
}

/// The root's slope and curvature bounds where the cut marches it whole for them: F's
/// slope bound over it finite and F'' bounded. Every box inside the root then has finite
/// slope bounds too (an enclosure over a box lies within the one over a box around it), so
/// `cut` would march the root whole whatever its descendants' bounds, which are then not
/// worked out (most of the hierarchy's time for a smooth formula: the polynomial examples).
fn root_marched_whole(
    hierarchy: &Hierarchy,
    centers: &[Vec<[f32; 4]>],
    formula: Option<(&CompiledFormula, &[f64])>,
) -> Option<([f32; 4], Curvature)> {
    let (formula, params) = formula?;
    let (center, half) = (centers[0][0], hierarchy.levels[0].half);
    let mut eval = IntervalEvaluator::new();
    let slope = box_slope(&mut eval, formula, params, center, half);
    if !slope.iter().sum::<f32>().is_finite() {
        return None;
    }
    let curvature = box_curvature(&mut eval, formula, params, center, half);
    curvature.is_bounded().then_some((slope, curvature))
}

/// The cut of `tree`'s first `depth` levels that marches the root whole (with its
/// `curvature`), as `cut` gives it.
#[allow(clippy::type_complexity)]
fn only_root(
    tree: &Tree16,
    depth: usize,
    curvature: Curvature,
) -> (Vec<Vec<bool>>, Vec<Vec<Option<Curvature>>>) {
    let mut marched = always_marched(tree, depth);
    let mut known: Vec<Vec<Option<Curvature>>> =
        marched.iter().map(|m| vec![None; m.len()]).collect();
    marched[0][0] = true;
    known[0][0] = Some(curvature);
    (marched, known)
}

/// The domain's geometry as the hierarchy stores it, in f32 and padded.
struct FlatGeometry {
    lo: [f64; 4],
    size: [f64; 4],
    /// Half extents of the root box, padded by more than the f32 rounding of centres and
    /// extents.
    base_half: [f32; 4],
    /// A further padding of every box, for the f32 rounding of the domain's coordinates.
    pad: f32,
}

impl FlatGeometry {
    fn of(tree: &Tree16) -> Self {
        let lo = tree.domain.map(|a| a.lo());
        let size = tree.domain.map(|a| a.hi() - a.lo());
        let scale = tree
            .domain
            .iter()
            .map(|a| a.magnitude())
            .fold(0.0, f64::max);
        Self {
            lo,
            size,
            base_half: size.map(|s| (0.5 * s * (1.0 + 1e-5)) as f32),
            pad: (scale * 1e-6) as f32,
        }
    }

    /// The half extents and sphere radius of each of `count` levels.
    fn level_table(&self, count: usize) -> Vec<LevelInfo> {
        (0..count)
            .map(|l| {
                let half = level_half(self.base_half, self.pad, l as u32);
                let radius = half
                    .iter()
                    .map(|&h| f64::from(h).powi(2))
                    .sum::<f64>()
                    .sqrt();
                LevelInfo {
                    half,
                    radius: (radius * (1.0 + 1e-6)) as f32,
                    support: [0.0; 3],
                }
            })
            .collect()
    }

    /// The centre of the box `coords` at `level`, in f32 as the nodes' centres.
    fn center(&self, level: u32, coords: [u16; 4]) -> [f32; 4] {
        let cells = f64::from(1u32 << level);
        std::array::from_fn(|a| {
            (self.lo[a] + self.size[a] * ((f64::from(coords[a]) + 0.5) / cells)) as f32
        })
    }
}

/// A box of the cover while it is gathered: its integer coordinates, its level and the node
/// it is marched in.
type CoverCell = ([u16; 4], u32, u32);

/// The hierarchy's nodes in depth-first order, with what goes along with each.
struct DepthFirst {
    nodes: Vec<SphereNode>,
    /// Each node's box in the tree (level, index), for its curvature.
    origin: Vec<(usize, usize)>,
    /// Each node's slope bounds (empty without a formula).
    slopes: Vec<[f32; 4]>,
    /// The marched boxes' descendants at the cover's level, and leaves above it, depth first.
    cover: Vec<CoverCell>,
}

impl DepthFirst {
    /// Flattens the first levels of `tree` down to its marched boxes (`marched`), with the
    /// skip index of each node (the index after its subtree).
    fn walk(
        tree: &Tree16,
        marched: &[Vec<bool>],
        centers: &[Vec<[f32; 4]>],
        slopes: &[Vec<[f32; 4]>],
        cover_level: usize,
    ) -> Self {
        let subtree = subtree_sizes(tree, marched);
        let kept = subtree[0][0] as usize;
        let mut walk = Self {
            nodes: Vec::with_capacity(kept),
            origin: Vec::with_capacity(kept),
            slopes: Vec::with_capacity(if slopes.is_empty() { 0 } else { kept }),
            cover: Vec::new(),
        };
        let mut stack: Vec<(u32, u32)> = vec![(0, 0)];
        while let Some((l, i)) = stack.pop() {
            let (lu, iu) = (l as usize, i as usize);
            let b = &tree.levels[lu][iu];
            let index = walk.nodes.len() as u32;
            let leaf = b.child_count == 0;
            walk.nodes.push(SphereNode {
                center: centers[lu][iu],
                skip: index + subtree[lu][iu],
                meta: l
                    | if leaf { LEAF_BIT } else { 0 }
                    | if marched[lu][iu] { MARCH_BIT } else { 0 },
            });
            walk.origin.push((lu, iu));
            if let Some(s) = slopes.get(lu) {
                walk.slopes.push(s[iu]);
            }
            if !marched[lu][iu] {
                for c in (0..u32::from(b.child_count)).rev() {
                    stack.push((l + 1, b.first_child + c));
                }
                continue;
            }
            // Its descendants at the cover's level, and leaves above it.
            let mut below = vec![(l, i)];
            while let Some((l, i)) = below.pop() {
                let b = &tree.levels[l as usize][i as usize];
                if l as usize == cover_level || b.child_count == 0 {
                    walk.cover.push((b.coords, l, index));
                } else {
                    below.extend((0..u32::from(b.child_count)).map(|c| (l + 1, b.first_child + c)));
                }
            }
        }
        walk
    }
}

/// The number of nodes in each box's subtree when the boxes `marched` end it, bottom-up.
fn subtree_sizes(tree: &Tree16, marched: &[Vec<bool>]) -> Vec<Vec<u32>> {
    let depth = marched.len();
    let mut subtree: Vec<Vec<u32>> = tree.levels[..depth]
        .iter()
        .map(|l| vec![1; l.len()])
        .collect();
    for l in (0..depth.saturating_sub(1)).rev() {
        let (here, below) = subtree.split_at_mut(l + 1);
        for (i, b) in tree.levels[l].iter().enumerate() {
            if marched[l][i] {
                continue;
            }
            let children = b.first_child as usize..b.first_child as usize + b.child_count as usize;
            here[l][i] += below[0][children].iter().sum::<u32>();
        }
    }
    subtree
}

/// The cover, then its boxes' ancestors level by level until each is its marched box (an
/// ancestor's boxes are consecutive: the cover is depth first).
fn cover_levels(
    mut cover: Vec<CoverCell>,
    nodes: &[SphereNode],
    geometry: &FlatGeometry,
) -> Vec<Vec<CoverBox>> {
    let mut levels = Vec::new();
    let mut first_child = vec![0; cover.len()];
    loop {
        levels.push(
            cover
                .iter()
                .zip(&first_child)
                .map(|(&(coords, level, node), &first_child)| CoverBox {
                    center: geometry.center(level, coords),
                    level,
                    node,
                    first_child,
                })
                .collect(),
        );
        let mut up: Vec<CoverCell> = Vec::with_capacity(cover.len());
        let mut up_first = Vec::with_capacity(cover.len());
        for (i, &(coords, level, node)) in cover.iter().enumerate() {
            let parent = if level > nodes[node as usize].level() {
                (coords.map(|k| k >> 1), level - 1, node)
            } else {
                (coords, level, node)
            };
            if up.last() != Some(&parent) {
                up.push(parent);
                up_first.push(i as u32);
            }
        }
        if up == cover {
            return levels;
        }
        cover = up;
        first_child = up_first;
    }
}

/// The default march level of `tree` (see [`Hierarchy::from_tree`]).
fn default_march_level(tree: &Tree16) -> u32 {
    let finest = tree.levels.len().saturating_sub(1);
    deepest_within_budget(
        tree,
        finest.saturating_sub(MARCH_LEVELS_ABOVE_FINEST as usize),
    ) as u32
}

/// The deepest level of `tree` down to `deepest` with at most [`MARCH_BOXES`] boxes (0 if
/// none).
fn deepest_within_budget(tree: &Tree16, deepest: usize) -> usize {
    (0..=deepest)
        .rev()
        .find(|&l| tree.levels.get(l).is_none_or(|v| v.len() <= MARCH_BOXES))
        .unwrap_or(0)
}
