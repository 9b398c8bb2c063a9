//! The sphere hierarchy sent to the GPU (docs/method.md §3): the kept boxes of a [`Tree16`] in
//! depth-first order, each with a skip index to the next node outside its subtree, so a
//! shader walks it with a loop and no stack.
//!
//! Its records are laid out for the shader in [`crate::gpu_layout`]. The radius of a box's
//! sphere is half the box's diagonal (docs/method.md §3: the chapter's full diagonal is twice
//! what is needed).

use rayon::prelude::*;

use super::build::Tree16;
use crate::eval::{Interval, IntervalEvaluator};
use crate::formula::{CompiledFormula, HESSIAN_PAIRS};
use crate::gpu_layout::{Curvature, LEAF_BIT, LevelInfo, MARCH_BIT, NodeBounds, SphereNode};

/// Half extents of a level-`level` box: `base · 2^-level + pad`, in f32 (the scaling by a
/// power of two is exact, so the shader gets the same bits).
pub fn level_half(base: [f32; 4], pad: f32, level: u32) -> [f32; 4] {
    let scale = f32::from_bits((127 - level.min(126)) << 23);
    base.map(|b| b * scale + pad)
}

/// How many levels above the finest leaves the ray caster stops descending (see
/// [`Hierarchy::march_level`]).
///
/// Per pixel, a box costs far more than a sample of F in the march (a memory read, the
/// pixel test, the rays that can meet it), and the boxes near a pixel's observer plane
/// multiply about 2x per level, the per-view binning of them 8x. At 256², level 6, 16 rays
/// (`cargo bench --bench frame`, the march-level table), level-(L−2) boxes marched at the
/// step of level L drew the chapter's scene 8.2x and the glome 4.5x faster than the level-L
/// leaves; one level up was 2.0x and 1.7x slower than two, three about the same as two,
/// four the same on the chapter's scene and 1.4x slower on the glome. (Measured without the
/// slope skip, which makes coarser boxes cheaper still: [`Hierarchy::for_formula`] goes
/// coarser where the bounds allow.)
///
/// Since the curvature bounds, `for_formula` marches a box whole wherever it has bounds, so
/// this level matters only where boxes have none (near a singular point), and there
/// smaller boxes are cheaper: one level up drew the tiger 1.8–2.4x and the spheritorus
/// 1.2–1.3x faster than two at level 4 (512², 16 rays, runs alternated), the other
/// example scenes the same (their cut is the root box); at level 6 the 32 768-box cap
/// sets the level. The hierarchy's build took ~5 ms longer for the tiger.
pub const MARCH_LEVELS_ABOVE_FINEST: u32 = 1;

/// Most nodes at the default march level: the binning of the boxes into per-tile lists
/// runs on the CPU for every view, in time about proportional to their number. (The glome
/// and the chapter's scene at level 7 march from level 4 under this rule.)
pub const MARCH_BOXES: usize = 32_768;

/// The flattened hierarchy: nodes in depth-first order, and the per-level table.
#[derive(Debug, Clone, Default)]
pub struct Hierarchy {
    pub nodes: Vec<SphereNode>,
    pub levels: Vec<LevelInfo>,
    /// The deepest level at which the ray caster stops descending: a node at this level, or
    /// a coarser one the cut marks (`SphereNode::is_marched`), is marched as one box, with
    /// the step count per unit length of the finest level (so the same samples per length
    /// as its leaves would get); a leaf above it is marched as a leaf (the chapter's m steps
    /// per span). Nodes below the cut are not kept, but `levels` still describes every
    /// level of the tree. By default the finest level minus [`MARCH_LEVELS_ABOVE_FINEST`].
    pub march_level: u32,
    /// The rule behind `levels[l].half`, in f32 as the shader computes it (instead of reading
    /// the table): `base_half · 2^-l + pad`, `base_half` padded relatively and `pad` more
    /// than the f32 rounding of centres.
    pub base_half: [f32; 4],
    pub pad: f32,
    /// Per node (empty without a formula: see [`Hierarchy::for_formula`] and
    /// [`Hierarchy::bound_slopes`]): a bound on |∂F/∂x|, |∂F/∂y|, |∂F/∂z|, |∂F/∂w| over the
    /// node's (padded) box where F is continuous on it (and |F| < 1e30, far from f32's
    /// overflow), else +∞. Along a ray in the box F
    /// then changes by at most Σ slope_k·|d_k| per unit length, so the march steps over the
    /// samples that cannot change sign (see templates/raycast.wgsl, `march_ray`).
    pub slopes: Vec<[f32; 4]>,
    /// Per node, for the boxes the ray caster marches (empty without a formula, as
    /// `slopes`; [`Curvature::NONE`] for the others): bounds on F's second derivatives over
    /// the box. Along a ray d, F then bends by d²F/dt² ∈ [lo, hi] (`Curvature::along`), so a
    /// sample's value and slope tell how far F surely keeps its sign: often much further
    /// than `slopes` allow, near a root seen at an angle (see `march_ray`).
    pub curvature: Vec<Curvature>,
    /// What each marched box covers, for the per-tile lists: its descendants at the cover's
    /// level (and leaves above it), or the box itself where it is at that level or a leaf.
    /// The cover's level is the deepest with at most [`MARCH_BOXES`] boxes, and at least
    /// the march level. The tree keeps every box that may hold M, so M's part in a marched
    /// box lies in its cover boxes: a pixel whose observer plane meets none of them finds
    /// no root in the box (see `TileLists`). `cover[0]` is that cover, in node order;
    /// `cover[k]` its boxes' ancestors k levels up (not above their marched box), for
    /// views too small to gain from finer ones (see [`Hierarchy::cover_within`]).
    pub cover: Vec<Vec<CoverBox>>,
    /// Whether F is continuous on the whole domain (by interval evaluation over it; false
    /// without a formula): then a sign change between any two points of the domain proves
    /// a root between them (certified pixels, docs/method.md §5.9).
    pub continuous: bool,
}

/// A box of the tree that lies in a marched box (see [`Hierarchy::cover`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoverBox {
    pub center: [f32; 4],
    pub level: u32,
    /// The index of the marched box in [`Hierarchy::nodes`].
    pub node: u32,
    /// In `cover[k]`, k > 0: the index in `cover[k - 1]` of its first child; its children
    /// run to the next box's first child (or the end). 0 in `cover[0]`.
    pub first_child: u32,
}

impl Curvature {
    /// No bound.
    pub const NONE: Self = Self {
        diag_lo: [f32::NEG_INFINITY; 4],
        diag_hi: [f32::INFINITY; 4],
        off_lo: [f32::NEG_INFINITY; 4],
        off_hi: [f32::INFINITY; 4],
        rest: [
            f32::NEG_INFINITY,
            f32::NEG_INFINITY,
            f32::INFINITY,
            f32::INFINITY,
        ],
    };

    /// Whether every bound is finite (else none is: see [`Curvature::NONE`]).
    pub fn is_bounded(&self) -> bool {
        let (lo, hi) = self.pairs();
        lo.iter().chain(&hi).all(|v| v.is_finite())
    }

    /// From bounds in the order of [`HESSIAN_PAIRS`].
    fn from_pairs(lo: [f32; 10], hi: [f32; 10]) -> Self {
        Self {
            diag_lo: [lo[0], lo[1], lo[2], lo[3]],
            diag_hi: [hi[0], hi[1], hi[2], hi[3]],
            off_lo: [lo[4], lo[5], lo[6], lo[7]],
            off_hi: [hi[4], hi[5], hi[6], hi[7]],
            rest: [lo[8], lo[9], hi[8], hi[9]],
        }
    }

    /// Bounds in the order of [`HESSIAN_PAIRS`].
    pub fn pairs(&self) -> ([f32; 10], [f32; 10]) {
        let [xx, yy, zz, ww] = self.diag_lo;
        let [xy, xz, xw, yz] = self.off_lo;
        let lo = [xx, yy, zz, ww, xy, xz, xw, yz, self.rest[0], self.rest[1]];
        let [xx, yy, zz, ww] = self.diag_hi;
        let [xy, xz, xw, yz] = self.off_hi;
        let hi = [xx, yy, zz, ww, xy, xz, xw, yz, self.rest[2], self.rest[3]];
        (lo, hi)
    }

    /// Bounds [lo, hi] on d²F/dt² = dᵀ H d along a ray o + t d in the box, rounded
    /// outwards past f32's rounding; (−∞, +∞) where unbounded. The CPU reference's rule;
    /// the shader bounds its rays by the observer plane's forms instead
    /// ([`Curvature::in_plane`]).
    pub fn along(&self, d: [f64; 4]) -> (f32, f32) {
        self.form(|i, j| d[i] * d[j])
            .unwrap_or((f32::NEG_INFINITY, f32::INFINITY))
    }

    /// Bounds on the second derivative along any ray in the plane of `n1` and `n2`: for
    /// d = a·n1 + b·n2, dᵀ H d = a²·A + ab·B + b²·C with A = n1ᵀ H n1, B = n1ᵀ H n2 + n2ᵀ H n1
    /// and C = n2ᵀ H n2, and this is [A lo, A hi, B lo, B hi, C lo, C hi], rounded outwards
    /// past f32's rounding; all infinite where unbounded. A view's rays all lie in that
    /// plane, so the shader works A, B and C out once per box and view (a box record, see
    /// `render::tiles`), not a ray's 10 products per ray. No looser than [`Curvature::along`]
    /// where H is exact or n1, n2 are coordinate axes (the glome, the chapter's views);
    /// elsewhere the sum over the three forms can be wider.
    pub fn in_plane(&self, n1: [f64; 4], n2: [f64; 4]) -> [f32; 6] {
        let forms = [
            self.form(|i, j| n1[i] * n1[j]),
            self.form(|i, j| n1[i] * n2[j] + n2[i] * n1[j]),
            self.form(|i, j| n2[i] * n2[j]),
        ];
        match forms {
            [Some(a), Some(b), Some(c)] => [a.0, a.1, b.0, b.1, c.0, c.1],
            _ => {
                let (lo, hi) = (f32::NEG_INFINITY, f32::INFINITY);
                [lo, hi, lo, hi, lo, hi]
            }
        }
    }

    /// Bounds on Σ_ij H_ij·p(i, j) over the box (H symmetric: twice p off the diagonal),
    /// rounded outwards past f32's rounding; None where not finite.
    fn form(&self, p: impl Fn(usize, usize) -> f64) -> Option<(f32, f32)> {
        let (lo, hi) = self.pairs();
        let (mut a, mut b, mut mag) = (0.0f64, 0.0f64, 0.0f64);
        for (k, &(i, j)) in HESSIAN_PAIRS.iter().enumerate() {
            let (i, j) = (usize::from(i), usize::from(j));
            let p = p(i, j) * if i == j { 1.0 } else { 2.0 };
            if p == 0.0 {
                continue;
            }
            let (l, h) = (f64::from(lo[k]), f64::from(hi[k]));
            let (x, y) = if p > 0.0 {
                (l * p, h * p)
            } else {
                (h * p, l * p)
            };
            a += x;
            b += y;
            mag += x.abs().max(y.abs());
        }
        if !(a.is_finite() && b.is_finite()) {
            return None;
        }
        let margin = mag * 1e-6;
        Some(((a - margin) as f32, (b + margin) as f32))
    }
}

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
    /// caster's cut, which is often the root box.
    pub fn for_certifying(tree: &Tree16) -> Self {
        let deepest = tree.levels.len().saturating_sub(1);
        let level = deepest_within_budget(tree, deepest).saturating_sub(CERTIFY_LEVELS_ABOVE);
        Self::flatten(tree, level as u32, None)
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
        // Slope bounds of every box down to the march level, and which boxes are marched.
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
        let (marched, known) = cut(tree, depth, &slopes, curvature_of);
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

    /// The finest cover (see [`Hierarchy::cover`]) with at most `limit` boxes, or the
    /// coarsest; empty for an empty hierarchy.
    pub fn cover_within(&self, limit: usize) -> &[CoverBox] {
        self.cover_level_within(limit)
            .map_or(&[], |k| self.cover[k].as_slice())
    }

    /// The index in [`Hierarchy::cover`] of [`Hierarchy::cover_within`]'s cover (None for an
    /// empty hierarchy).
    pub fn cover_level_within(&self, limit: usize) -> Option<usize> {
        let finest = self.cover.iter().position(|c| c.len() <= limit);
        finest.or(self.cover.len().checked_sub(1))
    }

    /// Node `i`'s slope bounds (+∞ when not bound).
    pub fn slope(&self, i: usize) -> [f32; 4] {
        self.slopes.get(i).copied().unwrap_or([f32::INFINITY; 4])
    }

    /// Node `i`'s bounds on F's second derivatives ([`Curvature::NONE`] when not bound).
    pub fn curvature(&self, i: usize) -> Curvature {
        self.curvature.get(i).copied().unwrap_or(Curvature::NONE)
    }

    /// Node `i`'s bounds as the GPU gets them.
    pub fn bounds(&self, i: usize) -> NodeBounds {
        NodeBounds {
            slope: self.slope(i),
            curvature: self.curvature(i),
        }
    }

    /// The deepest level of the tree.
    pub fn finest_level(&self) -> u32 {
        self.levels.len().saturating_sub(1) as u32
    }

    /// Whether the ray caster marches `node` as one box (a leaf, a node at the march level,
    /// or one the cut made coarser).
    pub fn marches(&self, node: &SphereNode) -> bool {
        node.is_marched()
    }

    /// The cut in words, for users: "1 box (the root)", "352 boxes of levels 2–4".
    pub fn march_summary(&self) -> String {
        let levels = self
            .nodes
            .iter()
            .filter(|n| self.marches(n))
            .map(SphereNode::level);
        let (lo, hi) = levels.fold((u32::MAX, 0), |(lo, hi), l| (lo.min(l), hi.max(l)));
        match self.march_boxes() {
            0 => "no box".to_string(),
            1 if hi == 0 => "1 box (the root)".to_string(),
            1 => format!("1 box of level {hi}"),
            n if lo == hi => format!("{n} boxes of level {hi}"),
            n => format!("{n} boxes of levels {lo}–{hi}"),
        }
    }

    /// Boxes the ray caster marches.
    pub fn march_boxes(&self) -> usize {
        self.nodes.iter().filter(|n| self.marches(n)).count()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Bytes the GPU buffers take.
    pub fn bytes(&self) -> u64 {
        // The nodes, their bounds (unbounded where none), the level table.
        (std::mem::size_of_val(self.nodes.as_slice())
            + self.nodes.len() * std::mem::size_of::<NodeBounds>()
            + std::mem::size_of_val(self.levels.as_slice())) as u64
    }

    pub fn radius(&self, node: &SphereNode) -> f32 {
        self.levels[node.level() as usize].radius
    }
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
            .map(|a| a.lo().abs().max(a.hi().abs()))
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

/// How many levels above the finest cover certified pixels search boxes (see
/// [`Hierarchy::for_certifying`]): each box a plane crosses costs a pixel at least one cell,
/// and a coarser box's cells subdivide only where M may be (the choice is measured in
/// docs/benchmarks.md, "Certified pixels").
pub const CERTIFY_LEVELS_ABOVE: usize = 2;

/// How much looser than its descendants' a box's slope bound may be for the box to be
/// marched whole where it has no curvature bounds (see [`Hierarchy::for_formula`]). Chosen
/// on the eight example scenes at level 6, 256², 16 rays (`cargo bench --bench frame`, runs
/// alternated), before curvature bounds: 3 was the best or within noise of it on each; 2
/// kept 1.2–2x slower cuts on the glome, the chapter's scene and the hyperplane, 4–5 made
/// the tiger and the spheritorus slower.
pub const COARSEN_LOOSENESS: f32 = 3.0;

/// Which boxes of `tree`'s first `depth` levels are marched whole: leaves, the boxes at
/// level `depth - 1` (the march level), and, where `slopes` are given (per level), every
/// box whose bound (the sum of its four) and its descendants' at the march level or leaves
/// are finite, and that either has a slope bound at most [`COARSEN_LOOSENESS`] times the
/// largest of its descendants' or curvature bounds (`curvature(evaluator, level, index)`).
/// Also the curvature it worked out, per level and box (None where it did not need it).
#[allow(clippy::type_complexity)]
fn cut(
    tree: &Tree16,
    depth: usize,
    slopes: &[Vec<[f32; 4]>],
    curvature: impl Fn(&mut IntervalEvaluator, usize, usize) -> Curvature + Sync,
) -> (Vec<Vec<bool>>, Vec<Vec<Option<Curvature>>>) {
    let total = |s: &[f32; 4]| s.iter().sum::<f32>();
    let mut marched: Vec<Vec<bool>> = tree.levels[..depth]
        .iter()
        .enumerate()
        .map(|(l, boxes)| {
            boxes
                .iter()
                .map(|b| b.child_count == 0 || l + 1 == depth)
                .collect()
        })
        .collect();
    let mut known: Vec<Vec<Option<Curvature>>> =
        marched.iter().map(|m| vec![None; m.len()]).collect();
    if slopes.is_empty() {
        return (marched, known);
    }
    // The largest descendant bound, bottom-up (a box marched anyway: its own).
    let mut below: Vec<Vec<f32>> = marched.iter().map(|m| vec![0.0; m.len()]).collect();
    for l in (0..depth).rev() {
        for (i, b) in tree.levels[l].iter().enumerate() {
            below[l][i] = if marched[l][i] {
                total(&slopes[l][i])
            } else {
                let children =
                    b.first_child as usize..b.first_child as usize + b.child_count as usize;
                below[l + 1][children].iter().copied().fold(0.0, f32::max)
            };
        }
    }
    // Top-down: a box inside one marched whole needs no decision (nor its curvature).
    let mut inside: Vec<Vec<bool>> = marched.iter().map(|m| vec![false; m.len()]).collect();
    for l in 0..depth {
        let decided: Vec<(bool, Option<Curvature>)> = (0..marched[l].len())
            .into_par_iter()
            .map_init(IntervalEvaluator::new, |eval, i| {
                let own = total(&slopes[l][i]);
                if inside[l][i] || !(own.is_finite() && below[l][i].is_finite()) {
                    (false, None)
                } else if own <= COARSEN_LOOSENESS * below[l][i] {
                    (true, None)
                } else {
                    let c = curvature(eval, l, i);
                    (c.is_bounded(), Some(c))
                }
            })
            .collect();
        for (i, b) in tree.levels[l].iter().enumerate() {
            marched[l][i] |= decided[i].0;
            known[l][i] = decided[i].1;
            if (marched[l][i] || inside[l][i]) && l + 1 < depth {
                let children =
                    b.first_child as usize..b.first_child as usize + b.child_count as usize;
                inside[l + 1][children].fill(true);
            }
        }
    }
    (marched, known)
}

/// Largest |F| on a box that gets a slope bound (f32 overflows at 3.4e38).
const F32_SAFE: f64 = 1e30;

/// The box `center ± half`, padded past the f32 rounding of the shader's box and samples.
fn padded_box(center: [f32; 4], half: [f32; 4]) -> [Interval; 4] {
    std::array::from_fn(|k| {
        let (c, h) = (f64::from(center[k]), f64::from(half[k]));
        let e = (c.abs() + h) * 1e-6;
        Interval::new(c - h - e, c + h + e)
    })
}

/// A bound on |∂F/∂x_k| over the box `center ± half` (padded past the f32 rounding of the
/// shader's box and samples) if F is continuous on it and far from f32's overflow, else +∞
/// (see `Hierarchy::slopes`).
fn box_slope(
    eval: &mut IntervalEvaluator,
    formula: &CompiledFormula,
    params: &[f64],
    center: [f32; 4],
    half: [f32; 4],
) -> [f32; 4] {
    let unbounded = [f32::INFINITY; 4];
    let bx = padded_box(center, half);
    eval.eval(&formula.tape_f, &bx, params);
    if !eval.continuous_on_last_box(&formula.tape_f) {
        return unbounded;
    }
    let mut out = [Interval::EMPTY; 5];
    eval.eval_into(&formula.tape_all, &bx, params, &mut out);
    // The shader evaluates F in f32: where it may overflow, an infinite |F| would step
    // over the whole span.
    if !(out[0].lo().abs() < F32_SAFE && out[0].hi().abs() < F32_SAFE) {
        return unbounded;
    }
    std::array::from_fn(|k| {
        let g = out[k + 1];
        let m = g.lo().abs().max(g.hi().abs());
        if g.is_empty() || !m.is_finite() {
            f32::INFINITY
        } else {
            // Rounded up past f32's rounding.
            (m * (1.0 + 1e-6)) as f32
        }
    })
}

/// Bounds on F's second derivatives over the box `center ± half` (padded as `box_slope`'s)
/// if F, ∇F and they are continuous on it and far from f32's overflow, else
/// [`Curvature::NONE`].
fn box_curvature(
    eval: &mut IntervalEvaluator,
    formula: &CompiledFormula,
    params: &[f64],
    center: [f32; 4],
    half: [f32; 4],
) -> Curvature {
    let bx = padded_box(center, half);
    let mut out = [Interval::EMPTY; 15];
    eval.eval_into(&formula.tape_second, &bx, params, &mut out);
    // Taylor's bound needs ∇F continuous too: every part of F, ∇F and the second
    // derivatives (abs and min / max put sign and step in ∇F).
    if !eval.continuous_on_last_box(&formula.tape_second) {
        return Curvature::NONE;
    }
    // F (as in box_slope) and the bounds (an f32 would round them to infinity) far from
    // f32's overflow.
    let second = &out[5..];
    if std::iter::once(&out[0])
        .chain(second)
        .any(|h| h.is_empty() || !(h.lo().abs() < F32_SAFE && h.hi().abs() < F32_SAFE))
    {
        return Curvature::NONE;
    }
    // Rounded outwards past f32's rounding.
    let widen = |v: f64| v.abs() * 1e-6 + 1e-30;
    let lo = std::array::from_fn(|k| (second[k].lo() - widen(second[k].lo())) as f32);
    let hi = std::array::from_fn(|k| (second[k].hi() + widen(second[k].hi())) as f32);
    Curvature::from_pairs(lo, hi)
}
