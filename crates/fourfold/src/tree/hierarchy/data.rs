//! The sphere hierarchy as the GPU gets it: the kept boxes of a tree in depth-first order,
//! the per-level table, the cut the ray caster marches, the boxes each marched box covers,
//! and the bounds on F's slope and curvature per box; with the constants that choose the
//! cut.

use crate::gpu_layout::{Curvature, LevelInfo, NodeBounds, SphereNode};

/// Half extents of a level-`level` box: `base · 2^-level + pad`, in f32 (the scaling by a
/// power of two is exact, so the shader gets the same bits).
pub fn level_half(base: [f32; 4], pad: f32, level: u32) -> [f32; 4] {
    let scale = f32::from_bits((127 - level.min(126)) << 23);
    base.map(|b| b * scale + pad)
}

/// How many levels above the finest leaves the ray caster stops descending (see
/// [`Hierarchy::march_level`]): a box costs a pixel far more than a sample of F, so coarser
/// boxes marched at the finest step are cheaper, but only one level up is where boxes have
/// no slope bounds (near a singular point). Measured in docs/benchmarks.md ("Design choices").
pub const MARCH_LEVELS_ABOVE_FINEST: u32 = 1;

/// Most nodes at the default march level: the binning of the boxes into per-tile lists
/// runs on the CPU for every view, in time about proportional to their number. (The glome
/// and the chapter's scene at level 7 march from level 4 under this rule.)
pub const MARCH_BOXES: usize = 32_768;

/// How many levels above the finest cover certified pixels search boxes (see
/// [`Hierarchy::for_certifying`]): each box a plane crosses costs a pixel at least one cell,
/// and a coarser box's cells subdivide only where M may be (measured in
/// docs/benchmarks.md, "Certified pixels").
pub const CERTIFY_LEVELS_ABOVE: usize = 2;

/// How much looser than its descendants' a box's slope bound may be for the box to be
/// marched whole where it has no curvature bounds (see [`Hierarchy::for_formula`]); the
/// best on the example scenes (docs/benchmarks.md, "Design choices").
pub const COARSEN_LOOSENESS: f32 = 3.0;

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

impl Hierarchy {
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
