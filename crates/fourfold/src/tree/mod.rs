//! Stage 4: the CPU pre-process: the 16-tree over the domain (docs/method.md §2) and its
//! flattening into the sphere hierarchy the ray caster walks (docs/method.md §3).

pub mod build;
pub mod hierarchy;

pub use crate::gpu_layout::{Curvature, LevelInfo, NodeBounds, SphereNode};
pub use build::{
    BuildError, BuildSettings, Geometry, MAX_LEVEL, Progress, REGION_MARGIN, Region, Touching,
    Tree16, TreeBox, TreeStats, TreeSteps,
};
pub use hierarchy::{CoverBox, Hierarchy};
