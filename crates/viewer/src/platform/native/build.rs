//! Builds on the desktop: on a thread of their own, cancelled by a newer one, the pipeline
//! warmed up there (a driver that compiles a shader at its first draw does it off the
//! window's thread).

use super::threads;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, TryRecvError, channel};

use web_time::Duration;

use fourfold::CompiledFormula;
use fourfold::critical::{CriticalReport, CriticalSteps};
use fourfold::render::{Gpu, Prepared, RayCaster};
use fourfold::scene::Scene;
use fourfold::tree::{BuildError, Hierarchy};

use crate::job::{JobInputs, JobResult, Settling};

/// The window's thread may wait for the GPU to finish a run of the picture's squares, and
/// so time it as it draws.
pub const WAITS_FOR_GPU: bool = true;

/// A new formula's first frames draw with the interpreting shader while its own compiles
/// on the build's thread (`job::build_interpreter`).
pub const INTERPRETS: bool = true;

/// A new formula's first preview is the GPU's: the interpreting shader draws it while the
/// formula's own compiles (see `progressive::cpu_preview`).
pub const CPU_PREVIEWS: bool = false;

/// Boxes the slice slider's search for critical values may look at: on a thread of its
/// own, the library's default.
pub const CRITICAL_BOX_BUDGET: usize = fourfold::scene::limits::CRITICAL_BOX_BUDGET;

/// The slice sweep's critical values, searched on a thread of their own, to the end.
pub struct CriticalWork(Background<Option<CriticalReport>>);

impl CriticalWork {
    pub fn start(mut steps: CriticalSteps<Arc<CompiledFormula>>) -> Self {
        Self(Background::start("fourfold critical values", move || {
            loop {
                if let Some(report) = steps.step(Duration::MAX) {
                    return Some(report);
                }
            }
        }))
    }

    /// The report once the search is done (`Some(None)` if its thread died).
    pub fn poll(&mut self, _budget: Duration) -> Option<Option<CriticalReport>> {
        self.0.poll().map(Option::flatten)
    }
}

/// Waits a moment between two looks at a build (`Session::wait`).
pub fn pause() {
    std::thread::sleep(std::time::Duration::from_millis(2));
}

/// Draws a few pixels with the caster's pipeline (`RayCaster::warm_up`), on the build's
/// thread, so that a driver that compiles a shader at its first draw (llvmpipe) does not do
/// it in a window's frame.
pub fn warm_up(
    gpu: &Gpu,
    caster: &mut RayCaster,
    hierarchy: &Hierarchy,
    scene: &Scene,
) -> Result<(), String> {
    caster
        .warm_up(gpu, hierarchy, scene)
        .map_err(|e| e.to_string())
}

/// Where the build made a caster of the interpreting shader, or one for a certified scene:
/// the formula's own pipelines built beside the window (a caster of its own shader, or a
/// sibling with the certified pipeline), handed to the window in `result`
/// (`JobResult::settling`), and the work that builds and warms them up, to be run once
/// `result` is sent.
fn settle_beside(inputs: &JobInputs, result: &mut JobResult) -> Option<impl FnOnce() + use<>> {
    let gpu = inputs.gpu.clone()?;
    let (Some(Ok(caster)), Ok((hierarchy, ..))) = (&result.caster, &result.tree) else {
        return None;
    };
    // What is built: a caster of the formula's own shader for an interpreting one, or the
    // settled picture's certified pipeline in a sibling of the caster; each warmed up over
    // the tree (llvmpipe generates a pipeline's code at the first draw that runs its
    // pixels: over an empty tree, the first certified frame took a second more).
    let hierarchy = hierarchy.clone();
    let build: Box<BuildBeside> = if caster.interprets() {
        let own = inputs.own_caster();
        Box::new(move |gpu| own.build(gpu, &hierarchy, warm_up))
    } else {
        let (sibling, scene) = (caster.sibling(&gpu).ok()?, inputs.settled_scene()?);
        Box::new(move |gpu| warm_sibling(gpu, sibling, &hierarchy, &[scene]))
    };
    let (sender, receiver) = channel();
    let (wanted, still_wanted) = channel();
    result.settling = Some(Settling { receiver, wanted });
    Some(move || {
        // A moment's wait first: while the user types, the next keystroke's build abandons
        // this one (drops its Settling) before its compile, which cannot be stopped, takes
        // the cores from it.
        let abandoned = matches!(
            still_wanted.recv_timeout(SETTLING_DELAY),
            Err(RecvTimeoutError::Disconnected)
        );
        if abandoned {
            return;
        }
        let built = build(&gpu);
        let _ = sender.send(built);
    })
}

/// Builds the pipelines that frames of `scenes` draw with in a sibling of `caster`, warmed
/// up over `hierarchy`, on a thread of its own: the sibling comes through the Settling (to
/// adopt). None where no sibling could be made.
pub fn pipelines_beside(
    gpu: &Gpu,
    caster: &RayCaster,
    hierarchy: &Arc<Hierarchy>,
    scenes: Vec<Scene>,
) -> Option<Settling> {
    let sibling = caster.sibling(gpu).ok()?;
    let (gpu, hierarchy) = (gpu.clone(), hierarchy.clone());
    let (sender, receiver) = channel();
    let (wanted, _) = channel();
    // If no thread can start, the sender is dropped with the work: the Settling says so.
    let _ = threads::spawn("fourfold pipelines", move || {
        let _ = sender.send(warm_sibling(&gpu, sibling, &hierarchy, &scenes));
    });
    Some(Settling { receiver, wanted })
}

/// `sibling` (of the session's caster; its buffers hold an empty tree) given `hierarchy`,
/// with the pipelines that frames of `scenes` draw with built and warmed up over it.
fn warm_sibling(
    gpu: &Gpu,
    mut sibling: RayCaster,
    hierarchy: &Hierarchy,
    scenes: &[Scene],
) -> Result<RayCaster, String> {
    sibling
        .set_hierarchy(gpu, hierarchy)
        .map_err(|e| e.to_string())?;
    for scene in scenes {
        warm_up(gpu, &mut sibling, hierarchy, scene)?;
    }
    Ok(sibling)
}

/// What the build's thread makes beside the window once the caster is handed over.
type BuildBeside = dyn FnOnce(&Gpu) -> Result<RayCaster, String> + Send;

/// How long the certified pipeline's build waits after its caster is handed over: about a
/// keystroke's interval; the preview and half-resolution stages take longer than that.
const SETTLING_DELAY: Duration = Duration::from_millis(250);

/// A build on a thread of its own, cancelled by a newer one.
pub struct BuildWork {
    cancel: Arc<AtomicBool>,
    progress: Arc<AtomicU64>,
    receiver: Receiver<JobResult>,
}

impl BuildWork {
    /// Starts building `inputs` on a new thread.
    pub fn start(inputs: JobInputs) -> Result<Self, String> {
        let cancel = Arc::new(AtomicBool::new(false));
        let progress = Arc::new(AtomicU64::new(0));
        let (sender, receiver) = channel();
        let (thread_cancel, thread_progress) = (cancel.clone(), progress.clone());
        threads::spawn("fourfold build", move || {
            let report = |_level: u32, nodes: u64| thread_progress.store(nodes, Ordering::Relaxed);
            let prepared = Prepared::build(
                &inputs.program.formula,
                &inputs.scene,
                inputs.scene.tree.into(),
                &thread_cancel,
                Some(&report),
            );
            if matches!(prepared, Err(BuildError::Cancelled)) {
                return;
            }
            let mut result = inputs.finish(prepared, warm_up);
            let settling = settle_beside(&inputs, &mut result);
            let _ = sender.send(result);
            if let Some(work) = settling {
                work();
            }
            inputs.complete_interpreter();
        })
        .map_err(|e| format!("could not start the tree build: {e}"))?;
        Ok(Self {
            cancel,
            progress,
            receiver,
        })
    }

    /// Nodes made so far.
    pub fn progress(&self) -> u64 {
        self.progress.load(Ordering::Relaxed)
    }

    /// The result once the thread is done (`budget` is for builds run in slices); Err if
    /// it ended without one (cancelled, or died).
    pub fn poll(&mut self, _budget: Duration) -> Option<Result<JobResult, ()>> {
        match self.receiver.try_recv() {
            Ok(result) => Some(Ok(result)),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => Some(Err(())),
        }
    }

    /// Stops the build: a newer one replaces it.
    pub fn cancel(self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}

/// Work done on a thread of its own beside the window's.
pub struct Background<T> {
    receiver: Option<Receiver<T>>,
}

impl<T: Send + 'static> Background<T> {
    /// Starts `work` on a thread called `name`.
    pub fn start(name: &str, work: impl FnOnce() -> T + Send + 'static) -> Self {
        let (send, receiver) = channel();
        // If no thread can start, the sender is dropped with the work, and `poll` says the
        // work died.
        let _ = threads::spawn(name, move || {
            let _ = send.send(work());
        });
        Self {
            receiver: Some(receiver),
        }
    }

    /// The result once the work is done (`Some(None)` if its thread died without one); None
    /// while it runs, and after the result was taken.
    pub fn poll(&mut self) -> Option<Option<T>> {
        let result = match self.receiver.as_ref()?.try_recv() {
            Ok(result) => Some(result),
            Err(TryRecvError::Empty) => return None,
            Err(TryRecvError::Disconnected) => None,
        };
        self.receiver = None;
        Some(result)
    }
}
