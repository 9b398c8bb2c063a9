//! The second ray caster the window keeps for the projection drawn beside a slice, and its
//! build off the window's frames.

use std::sync::Arc;

use fourfold::render::{RayCaster, Shader};

use crate::platform::Background;

/// A second ray caster, for the projection beside a slice: the shader it was made for and
/// the session's picture generation whose hierarchy it holds.
pub struct InsetCaster {
    pub caster: RayCaster,
    pub shader: Arc<Shader>,
    pub generation: u64,
}

/// An inset caster being built and warmed up beside the window (natively on a thread: a
/// driver compiles a pipeline for a fraction of a second, at its first draw on llvmpipe),
/// for `shader` over the hierarchy of picture generation `generation`.
pub struct InsetBuild {
    pub shader: Arc<Shader>,
    pub generation: u64,
    pub work: Background<Result<RayCaster, String>>,
}
