//! The 16-tree of docs/method.md §2, built level by level (breadth first) over the domain box.
//!
//! A box at level L is identified by integer coordinates in [0, 2^L)⁴, so boxes are exact
//! and a node costs a few bytes. Each level's boxes are evaluated in parallel (rayon) with
//! the rigorous interval evaluator, a box's 16 children in one batch. Breadth-first order
//! makes the node budget fair: a level is refined completely or not at all, so no corner of
//! the domain starves the others.

mod refine;
mod region;
mod steps;
mod touching;
mod tree;

pub use region::{REGION_MARGIN, Region};
pub use steps::TreeSteps;
pub use tree::{
    BuildError, BuildSettings, Geometry, MAX_LEVEL, Progress, Touching, Tree16, TreeBox, TreeStats,
};
