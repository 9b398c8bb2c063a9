//! The sphere hierarchy sent to the GPU (docs/method.md §3): the kept boxes of a [`Tree16`] in
//! depth-first order, each with a skip index to the next node outside its subtree, so a
//! shader walks it with a loop and no stack.
//!
//! Its records are laid out for the shader in [`crate::gpu_layout`]. The radius of a box's
//! sphere is half the box's diagonal (docs/method.md §3: the chapter's full diagonal is twice
//! what is needed).

mod bounds;
mod cut;
mod data;
mod flatten;

pub use data::{
    CERTIFY_LEVELS_ABOVE, COARSEN_LOOSENESS, CoverBox, Hierarchy, MARCH_BOXES,
    MARCH_LEVELS_ABOVE_FINEST, level_half,
};
