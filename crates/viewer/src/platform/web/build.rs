//! Builds in the web page: a page has one thread, so a build runs in slices of the window's
//! frames (the library's `PrepareSteps`), replaced by a newer one.

use web_time::Duration;

use std::sync::Arc;

use fourfold::CompiledFormula;
use fourfold::critical::{CriticalReport, CriticalSteps};
use fourfold::render::{Gpu, PrepareSteps, Prepared, RayCaster};
use fourfold::scene::Scene;
use fourfold::tree::Hierarchy;

use crate::job::{JobInputs, JobResult, Settling};

/// A page cannot wait for the GPU: the picture's squares go in runs, at most two queued,
/// the next once the queue says one is done (queued as fast as they were encoded, a
/// stage's squares could keep a software GPU busy for minutes).
pub const WAITS_FOR_GPU: bool = false;

/// A page draws every formula with its own shader: its build has no thread to compile the
/// formula's shader on beside the interpreting one's frames (a page's pipelines compile in
/// the browser's GPU process, in the queue's order).
pub const INTERPRETS: bool = false;

/// A new formula's first preview is drawn on the CPU, while the GPU process compiles its
/// shader (see `progressive::cpu_preview`).
pub const CPU_PREVIEWS: bool = true;

/// Boxes the slice slider's search for critical values may look at: a page searches in
/// slices of its frames, so a search that needs more than a few seconds of them is cut
/// short, its remaining boxes shown undecided.
pub const CRITICAL_BOX_BUDGET: usize = 200_000;

/// The slice sweep's critical values, searched in slices of the window's frames (a page
/// has one thread).
pub struct CriticalWork(Box<CriticalSteps<Arc<CompiledFormula>>>);

impl CriticalWork {
    pub fn start(steps: CriticalSteps<Arc<CompiledFormula>>) -> Self {
        Self(Box::new(steps))
    }

    /// Searches for about `budget`; the report once the search is done.
    pub fn poll(&mut self, budget: Duration) -> Option<Option<CriticalReport>> {
        self.0.step(budget).map(Some)
    }
}

/// A page cannot sleep; `Session::wait` spins (only tests wait, natively).
pub fn pause() {}

/// A page compiles a pipeline when it makes it and cannot wait for a read-back: no warm-up.
pub fn warm_up(
    _gpu: &Gpu,
    _caster: &mut RayCaster,
    _hierarchy: &Hierarchy,
    _scene: &Scene,
) -> Result<(), String> {
    Ok(())
}

/// A page builds no pipeline beside its frames: it has one thread, and the browser compiles
/// a pipeline in its GPU process in the queue's order, so one made ahead would hold up the
/// frames before it (a settled picture's certified one, the previews after an edit). A
/// frame makes what it lacks when it first draws.
pub fn pipelines_beside(
    _gpu: &Gpu,
    _caster: &RayCaster,
    _hierarchy: &Arc<Hierarchy>,
    _scenes: Vec<Scene>,
) -> Option<Settling> {
    None
}

/// A build run in slices of the window's frames (the library's `PrepareSteps`), replaced by
/// a newer one.
pub struct BuildWork(Box<(PrepareSteps, JobInputs)>);

impl BuildWork {
    /// Starts building `inputs` a slice at a time.
    pub fn start(inputs: JobInputs) -> Result<Self, String> {
        let settings = inputs.scene.tree.into();
        let steps = Prepared::steps(&inputs.program.formula, &inputs.scene, settings)
            .map_err(|e| e.to_string())?;
        Ok(Self(Box::new((steps, inputs))))
    }

    /// Nodes made so far.
    pub fn progress(&self) -> u64 {
        self.0.0.nodes()
    }

    /// Works for about `budget`; the result once the build is done.
    pub fn poll(&mut self, budget: Duration) -> Option<Result<JobResult, ()>> {
        let (steps, inputs) = &mut *self.0;
        match steps.step(&inputs.program.formula, budget) {
            Ok(None) => None,
            Ok(Some(prepared)) => Some(Ok(inputs.finish(Ok(prepared), warm_up))),
            Err(e) => Some(Ok(inputs.finish(Err(e), warm_up))),
        }
    }

    /// Stops the build: dropping it is enough.
    pub fn cancel(self) {}
}

/// Work a native viewer does beside the window: a page has one thread, so it is done here,
/// at once.
pub struct Background<T> {
    result: Option<T>,
}

impl<T> Background<T> {
    /// Does `work` now (`_name` names a native viewer's thread).
    pub fn start(_name: &str, work: impl FnOnce() -> T) -> Self {
        Self {
            result: Some(work()),
        }
    }

    /// The result, once (as a native viewer's, which may have lost its thread: never here).
    pub fn poll(&mut self) -> Option<Option<T>> {
        self.result.take().map(Some)
    }
}
