//! The second ray caster the window keeps for the projection drawn beside a slice.

use std::sync::Arc;

use fourfold::render::{RayCaster, Shader};

/// A second ray caster, for the projection beside a slice: the shader it was made for and
/// the session's picture generation whose hierarchy it holds.
pub struct InsetCaster {
    pub caster: RayCaster,
    pub shader: Arc<Shader>,
    pub generation: u64,
}
