//! The viewer's threads beside the window, counted so that the process waits for them when
//! it exits. A thread still drawing or compiling on the GPU when the process's exit runs
//! the driver's destructors (lavapipe's LLVM) corrupts the heap: the window closed during
//! a gallery or an export, or a test ending while one ran, ended in "double free or
//! corruption" or a segmentation fault (a few runs of the gallery's test in a hundred).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex, Once};
use std::time::Duration;

use fourfold::render::Gpu;

/// The longest the process's exit waits for the threads (one still running after it is
/// left to the exit: a hang would be worse).
const EXIT_WAIT: Duration = Duration::from_secs(20);

/// Threads running, and the signal that one ended.
static RUNNING: Mutex<usize> = Mutex::new(0);
static ENDED: Condvar = Condvar::new();
/// Set once the process exits: long work stops at its next step.
static EXITING: AtomicBool = AtomicBool::new(false);
static AT_EXIT: Once = Once::new();

/// Starts `work` on a thread called `name`, counted until it returns (or panics).
pub fn spawn(name: &str, work: impl FnOnce() + Send + 'static) -> std::io::Result<()> {
    AT_EXIT.call_once(register_wait_at_exit);
    *lock() += 1;
    let counted = Counted;
    std::thread::Builder::new()
        .name(name.into())
        .spawn(move || {
            let _counted = counted;
            work();
        })
        .map(drop)
}

/// A GPU device of a thread's own (the gallery's, an export's). Opening it may register
/// the driver's own exit handlers, which then run before the wait for the threads (an
/// exit runs its handlers last first) and break the device's work in flight: the wait is
/// registered again after them.
pub fn open_gpu() -> Result<Gpu, String> {
    let gpu = Gpu::new().map_err(|e| e.to_string());
    register_wait_at_exit();
    gpu
}

/// Whether the process is exiting: work that takes long stops at its next step.
pub fn exiting() -> bool {
    EXITING.load(Ordering::Relaxed)
}

/// One running thread; uncounted when dropped (its work returned, panicked, or its thread
/// did not start).
struct Counted;

impl Drop for Counted {
    fn drop(&mut self) {
        *lock() -= 1;
        ENDED.notify_all();
    }
}

fn lock() -> std::sync::MutexGuard<'static, usize> {
    RUNNING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Has the process's exit wait for the threads, before the exit handlers registered so far
/// (the GPU driver's: at the first thread, the window's device is open). Again at each
/// device a thread opens (`open_gpu`); the waits after the first find no thread running.
// The workspace's other unsafe call: the standard library has no hook at the process's
// exit.
#[allow(unsafe_code)]
fn register_wait_at_exit() {
    // SAFETY: `atexit` only records the function; `wait_at_exit` is an `extern "C" fn()`
    // that does not unwind (it waits on a lock whose poisoning it ignores) and does not
    // call `exit`.
    unsafe {
        libc::atexit(wait_at_exit);
    }
}

extern "C" fn wait_at_exit() {
    EXITING.store(true, Ordering::Relaxed);
    let _ = ENDED.wait_timeout_while(lock(), EXIT_WAIT, |running| *running > 0);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thread_is_counted_while_it_runs_and_after_a_panic_no_more() {
        let before = *lock();
        let (go, wait) = std::sync::mpsc::channel::<()>();
        spawn("counted", move || {
            let _ = wait.recv();
        })
        .unwrap();
        assert!(*lock() > before);
        go.send(()).unwrap();
        spawn("panicking", || panic!("on purpose")).unwrap();
        let deadline = std::time::Instant::now() + Duration::from_secs(10);
        while *lock() > before {
            assert!(std::time::Instant::now() < deadline, "still counted");
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}
