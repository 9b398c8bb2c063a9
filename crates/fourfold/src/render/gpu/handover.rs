//! Casters that share a shader's pipelines or take over another's: a sibling that builds a
//! pipeline on another thread for its caster to adopt, the interpreting shader's casters
//! (one per formula, all with the pipelines built once), and the hand-over of an
//! interpreting caster's buffers to the formula's own shader once it is compiled.

use crate::formula::CompiledFormula;
use crate::render::shader::{Shader, program};
use crate::tree::Hierarchy;

use super::buffers::program_buffer;
use super::caster::RayCaster;
use super::device::{Gpu, GpuError};

impl RayCaster {
    /// A caster of the same shader, target, layouts and pipeline cache, with buffers of its
    /// own for an empty tree and no pipeline: its pipelines can be built and warmed up on
    /// another thread while this one draws, then handed over with [`RayCaster::adopt`]. (A
    /// driver that compiles a pipeline at its first draw, as llvmpipe, would otherwise do
    /// it inside the frame that first needs it, or before a picture that does not.)
    pub fn sibling(&self, gpu: &Gpu) -> Result<Self, GpuError> {
        let pipelines = std::array::from_fn(|_| std::sync::OnceLock::new());
        Self::assemble(
            gpu,
            self.shared.clone(),
            pipelines,
            &Hierarchy::default(),
            self.words.clone(),
        )
    }

    /// Takes the pipelines that `sibling` (made by [`RayCaster::sibling`] from this caster)
    /// built and this caster lacks; false, taking none, if it is another caster's.
    pub fn adopt(&mut self, sibling: RayCaster) -> bool {
        let (mine, theirs) = (&self.shared, &sibling.shared);
        if theirs.module != mine.module || theirs.pipeline_layout != mine.pipeline_layout {
            return false;
        }
        for (mine, theirs) in self.pipelines.iter_mut().zip(sibling.pipelines) {
            if let Some(pipeline) = theirs.into_inner()
                && mine.get().is_none()
            {
                let _ = mine.set(pipeline);
            }
        }
        true
    }

    /// Whether this caster's shader is the interpreting one (`shader::interpreter`): it
    /// draws plain pixels only.
    pub fn interprets(&self) -> bool {
        self.shared.interprets
    }

    /// A caster of the interpreting shader (this one's, which must be it) drawing `formula`
    /// over `hierarchy`, with the pipelines this caster has built: a new formula's frames
    /// at once, with no compile. Err where its tapes do not fit the interpreter.
    pub fn interpret(
        &self,
        gpu: &Gpu,
        formula: &CompiledFormula,
        hierarchy: &Hierarchy,
    ) -> Result<Self, GpuError> {
        debug_assert!(
            self.shared.interprets,
            "a caster of the interpreting shader"
        );
        let program = program(formula)?;
        let pipelines = std::array::from_fn(|i| {
            let lock = std::sync::OnceLock::new();
            if let Some(pipeline) = self.pipelines[i].get() {
                let _ = lock.set(pipeline.clone());
            }
            lock
        });
        Self::assemble(gpu, self.shared.clone(), pipelines, hierarchy, program)
    }

    /// Draws `formula` from now on, whose shader is `shader` and has this caster's source
    /// (the formula's numbers differ, not its WGSL: `shader::constants`): binding 7 takes
    /// its constants, or its program where this caster interprets. No pipeline is built.
    pub fn set_formula(
        &mut self,
        gpu: &Gpu,
        formula: &CompiledFormula,
        shader: &Shader,
    ) -> Result<(), GpuError> {
        let words = if self.shared.interprets {
            program(formula)?
        } else {
            debug_assert!(self.draws(shader), "a shader of this caster's source");
            shader.constants.clone()
        };
        // (A new tree of the same formula, a parameter's: binding 7 stays.)
        if words == self.words {
            return Ok(());
        }
        self.words = words;
        self.program = program_buffer(gpu, &self.words);
        self.rebind(gpu);
        Ok(())
    }

    /// Whether this caster draws with `shader`'s source (so `set_formula` takes formulas
    /// of that shader without a compile).
    pub fn draws(&self, shader: &Shader) -> bool {
        self.shared.source_hash == super::caster::source_hash(&shader.source)
    }

    /// Draws from now on with `own`'s shader and pipelines (a caster of the formula's own
    /// shader, made for any hierarchy), keeping this caster's buffers: its tree, its view's
    /// lists and its settings. So the interpreting shader's caster hands its picture over
    /// to the formula's own shader, with certified pixels, once that is compiled.
    pub fn take_shader(&mut self, gpu: &Gpu, own: RayCaster) {
        self.shared = own.shared;
        self.pipelines = own.pipelines;
        self.background = own.background;
        // (Binding 7: the own shader's constants, where this one held the program.)
        self.program = own.program;
        self.words = own.words;
        self.rebind(gpu);
    }
}
