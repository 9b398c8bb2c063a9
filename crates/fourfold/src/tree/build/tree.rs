//! The 16-tree as built: its boxes level by level (exact integer coordinates), its settings,
//! its statistics, and how a box's coordinates become an interval box of the domain.

use serde::Serialize;

use crate::eval::{Box4, Interval};

/// The criteria and limits of a build.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildSettings {
    pub max_level: u32,
    /// Kept boxes are refined down to this level whatever the topological criterion says.
    pub min_level: u32,
    /// The most nodes the tree may hold.
    pub node_budget: u32,
}

/// The deepest level a build accepts. At level 12 a box is 1/4096 of the domain per axis;
/// deeper trees only hit the node budget.
pub const MAX_LEVEL: u32 = 12;

/// A kept box: its integer coordinates at its level, its parent (index into the level above)
/// and whether it was refined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TreeBox {
    pub coords: [u16; 4],
    pub parent: u32,
    /// Index of its first kept child in the next level, and how many there are (0 = leaf).
    pub first_child: u32,
    pub child_count: u8,
    /// The topological criterion (0 ∈ every partial) held at this box.
    pub critical: bool,
    /// F□ over it reached below 0, and above 0 (it holds 0: one of them may not).
    pub below: bool,
    pub above: bool,
}

/// What a build did, for users and benchmarks.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TreeStats {
    pub nodes: u64,
    pub leaves: u64,
    pub nodes_per_level: Vec<u64>,
    pub leaves_per_level: Vec<u64>,
    pub discarded_per_level: Vec<u64>,
    /// Leaves at max_level where 0 ∈ ∇F□ still held: F may have a critical point there.
    pub singular_boxes: u64,
    /// Refinement stopped early because the next level would pass the node budget.
    pub budget_hit: bool,
    /// The level at which the budget stopped refinement, if it did.
    pub budget_level: Option<u32>,
    pub interval_evaluations: u64,
    /// Boxes whose natural interval extension held 0 and whose mean-value form did not
    /// (see `mean_value_may_vanish`): discarded.
    pub mean_value_discarded: u64,
    /// F□ over every leaf lies in [0, +∞), or over every leaf in (−∞, 0]: F does not change
    /// sign where it may vanish, so M is where it touches 0 (`(r − 1)^2`, `|y|`), which no
    /// search for sign changes finds or proves.
    pub one_signed: bool,
    /// The share of the leaves over which F□ reaches 0 from one side only, also over the
    /// leaf widened by a sliver: F does not change sign in or across them, so what of M lies
    /// there is where F touches 0 (`x·y²` along y = 0). Estimated from a sample of the
    /// one-sided leaves (`Tree16::measure_touching`, tree/build/touching.rs).
    pub touching_share: f64,
    pub build_ms: f64,
    pub bytes: u64,
}

/// Where F only touches 0 (reaches it from one side) over the tree's leaves: there no
/// search for sign changes finds or proves M.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Touching {
    /// F changes sign across M in (nearly) every leaf.
    Nowhere,
    /// In a share of the leaves (at least [`TreeStats::TOUCHING_SHARE`]) and not all.
    Partly,
    /// F keeps one sign over every leaf (`TreeStats::one_signed`).
    Everywhere,
}

impl TreeStats {
    /// The share of the leaves, touching 0 from one side, from which F is said to touch 0
    /// in part of the domain: below it a leaf or two where interval rounding meets 0 exactly
    /// raise no note.
    pub const TOUCHING_SHARE: f64 = 0.01;

    pub fn touching(&self) -> Touching {
        if self.one_signed {
            Touching::Everywhere
        } else if self.touching_share >= Self::TOUCHING_SHARE {
            Touching::Partly
        } else {
            Touching::Nowhere
        }
    }
}

/// A built 16-tree: kept boxes per level.
#[derive(Debug, Clone)]
pub struct Tree16 {
    /// The domain box H, the root.
    pub domain: Box4,
    pub levels: Vec<Vec<TreeBox>>,
    pub stats: TreeStats,
}

/// Why a build produced no tree.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    #[error("the tree build was cancelled")]
    Cancelled,
    #[error("{0}")]
    InvalidSettings(String),
}

/// Progress reports: (level just finished, nodes so far).
pub type Progress<'a> = &'a (dyn Fn(u32, u64) + Sync);

impl Tree16 {
    /// The box of a node, as intervals.
    pub fn box_of(&self, level: u32, b: &TreeBox) -> Box4 {
        Geometry::new(&self.domain).box_at(level, b.coords)
    }

    /// Every leaf, with its level.
    pub fn leaves(&self) -> impl Iterator<Item = (u32, &TreeBox)> {
        self.levels.iter().enumerate().flat_map(|(l, boxes)| {
            boxes
                .iter()
                .filter(|b| b.child_count == 0)
                .map(move |b| (l as u32, b))
        })
    }

    pub fn is_empty(&self) -> bool {
        self.levels.is_empty()
    }

    pub(super) fn count(&mut self, settings: BuildSettings) {
        let s = &mut self.stats;
        s.nodes_per_level = self.levels.iter().map(|l| l.len() as u64).collect();
        s.leaves_per_level = self
            .levels
            .iter()
            .map(|l| l.iter().filter(|b| b.child_count == 0).count() as u64)
            .collect();
        s.nodes = s.nodes_per_level.iter().sum();
        s.leaves = s.leaves_per_level.iter().sum();
        s.singular_boxes = self
            .levels
            .get(settings.max_level as usize)
            .map_or(0, |l| l.iter().filter(|b| b.critical).count() as u64);
        s.bytes = s.nodes * std::mem::size_of::<TreeBox>() as u64;
        let (below, above) = self.leaves().fold((false, false), |(lo, hi), (_, b)| {
            (lo | b.below, hi | b.above)
        });
        self.stats.one_signed = self.stats.leaves > 0 && !(below && above);
    }
}

pub(super) fn validate(s: BuildSettings) -> Result<(), BuildError> {
    if s.max_level > MAX_LEVEL {
        return Err(BuildError::InvalidSettings(format!(
            "max_level {} is above the limit {MAX_LEVEL}",
            s.max_level
        )));
    }
    if s.min_level > s.max_level {
        return Err(BuildError::InvalidSettings(format!(
            "min_level {} is above max_level {}",
            s.min_level, s.max_level
        )));
    }
    if s.node_budget < 1 {
        return Err(BuildError::InvalidSettings(
            "the node budget must be at least 1".into(),
        ));
    }
    Ok(())
}

/// Box geometry: integer coordinates at a level → intervals of the domain.
#[derive(Debug, Clone, Copy)]
pub struct Geometry {
    lo: [f64; 4],
    size: [f64; 4],
}

impl Geometry {
    pub fn new(domain: &Box4) -> Self {
        Self {
            lo: domain.map(|a| a.lo()),
            size: domain.map(|a| a.hi() - a.lo()),
        }
    }

    /// The box with coordinates `c` at `level`. Bounds are computed as lo + size·k/2^L: the
    /// same expression for the shared face of two neighbours, so the boxes tile H with no gap.
    pub fn box_at(&self, level: u32, c: [u16; 4]) -> Box4 {
        let cells = f64::from(1u32 << level);
        std::array::from_fn(|i| {
            let a = self.lo[i] + self.size[i] * (f64::from(c[i]) / cells);
            let b = self.lo[i] + self.size[i] * (f64::from(c[i] + 1) / cells);
            Interval::new(a, b)
        })
    }
}
