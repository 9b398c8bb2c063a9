//! Long work off the interpreter's thread: it runs on a thread of its own while the caller
//! waits with the GIL released, looking for Ctrl-C (or a notebook's stop button) every 50
//! ms; an interrupt sets the work's stop flag and raises `KeyboardInterrupt` at once. The
//! GPU is opened once per process and shared by every call.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock, mpsc};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use fourfold::render::Gpu;

use crate::errors::render_error;

/// How often the waiting interpreter looks for signals.
const SIGNAL_CHECK: Duration = Duration::from_millis(50);

enum Message<T> {
    Progress(u32),
    Done(T),
}

/// What the work is handed: its stop flag, and where to say how far it got.
pub struct Job<'a> {
    pub stop: &'a AtomicBool,
    progress: &'a dyn Fn(u32),
}

impl Job<'_> {
    pub fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    pub fn progress(&self, done: u32) {
        (self.progress)(done);
    }
}

/// What to do once interrupted: return at once (the work stops at its next look at the
/// flag, in the background), or wait for the work to wind up (an animation finishes its
/// file with the frames drawn so far).
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum OnInterrupt {
    Return,
    WindUp,
}

/// Runs `work` on a thread of its own; `on_progress` hears its progress on the caller's
/// thread. A panic in the work is a `RuntimeError`, never a crash.
pub fn run<T: Send + 'static>(
    py: Python<'_>,
    on_interrupt: OnInterrupt,
    work: impl FnOnce(&Job) -> T + Send + 'static,
    mut on_progress: impl FnMut(Python<'_>, u32) -> PyResult<()>,
) -> PyResult<T> {
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel::<Message<T>>();
    let flag = stop.clone();
    std::thread::Builder::new()
        .name("fourfold".into())
        .spawn(move || {
            let progress_tx = tx.clone();
            let progress = move |k: u32| {
                let _ = progress_tx.send(Message::Progress(k));
            };
            let job = Job {
                stop: &flag,
                progress: &progress,
            };
            let _ = tx.send(Message::Done(work(&job)));
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
    // A receiver is not Sync; the lock makes the wait below sendable to `detach`.
    let rx = std::sync::Mutex::new(rx);
    // The first interrupt or error from `on_progress`; raised once the work has wound up.
    let mut failed: Option<PyErr> = None;
    let fail = |e: PyErr, failed: &mut Option<PyErr>| -> Option<PyErr> {
        stop.store(true, Ordering::Relaxed);
        // A second interrupt while winding up returns at once.
        if on_interrupt == OnInterrupt::Return || failed.is_some() {
            return Some(e);
        }
        *failed = Some(e);
        None
    };
    loop {
        let received = py.detach(|| match rx.lock() {
            Ok(rx) => rx.recv_timeout(SIGNAL_CHECK),
            Err(_) => Err(mpsc::RecvTimeoutError::Disconnected),
        });
        match received {
            Ok(Message::Done(value)) => return failed.map_or(Ok(value), Err),
            Ok(Message::Progress(k)) => {
                // A Ctrl-C can surface in the callback's Python code as well as below.
                if failed.is_none()
                    && let Err(e) = on_progress(py, k)
                    && let Some(e) = fail(e, &mut failed)
                {
                    return Err(e);
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err(
                    "fourfold's work stopped without an answer (a bug: please report it \
                     with the formula and settings)",
                ));
            }
        }
        if let Err(e) = py.check_signals()
            && let Some(e) = fail(e, &mut failed)
        {
            return Err(e);
        }
    }
}

/// Runs `work` as [`run`] does, without progress.
pub fn run_quiet<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce(&Job) -> T + Send + 'static,
) -> PyResult<T> {
    run(py, OnInterrupt::Return, work, |_, _| Ok(()))
}

static GPU: OnceLock<Result<Gpu, String>> = OnceLock::new();

/// The process's GPU, opened on first use (on lavapipe where there is no GPU).
pub fn gpu() -> Result<Gpu, String> {
    GPU.get_or_init(|| Gpu::new().map_err(|e| e.to_string()))
        .clone()
}

/// The GPU, or the `RenderError` saying why there is none (and that `cpu=True` draws
/// without one).
pub fn gpu_or_error() -> PyResult<Gpu> {
    gpu().map_err(|e| {
        render_error(format!(
            "{e}\n(render with cpu=True to draw on the CPU reference renderer instead)"
        ))
    })
}
