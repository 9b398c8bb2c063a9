//! Stage 4: the CPU pre-process: the 16-tree over the domain (SPEC.md §2) and its
//! flattening into the sphere hierarchy the ray caster walks (SPEC.md §3).

pub mod build;
pub mod hierarchy;

pub use build::{BuildError, BuildSettings, Geometry, Tree16, TreeBox, TreeStats};
pub use hierarchy::{CoverBox, Curvature, Hierarchy, LevelInfo, NodeBounds, SphereNode};
