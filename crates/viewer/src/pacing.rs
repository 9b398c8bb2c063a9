//! Frame pacing: how long the window's frames take, and how much of each the ray caster may
//! use so that the window keeps 20 frames per second whatever the GPU.

use web_time::{Duration, Instant};

/// The UI frame time the viewer aims at: 20 frames per second with a margin. Ray casting gets
/// what the rest of a frame (egui's widgets, the picture blit, presenting) leaves of it.
const FRAME_TARGET_MS: f64 = 40.0;
/// Ray casting per UI frame at least (so the picture always progresses) and at most, and at
/// most while the user drags (a quicker preview).
const RAY_BUDGET_MS: [f64; 2] = [3.0, 20.0];
const RAY_BUDGET_DRAGGING_MS: f64 = 12.0;
/// Time from submitting a run of the picture's squares to the word that it is done, where
/// the window cannot wait for the GPU (a page), at least and at most: the word comes a frame
/// or more later, and the bound keeps a run far inside a browser's GPU watchdog and the
/// window's frames near their pace on a slow adapter.
const GPU_RUN_MS: [f64; 2] = [50.0, 250.0];
/// How long after the last drag or scroll the user still counts as interacting.
const INTERACTION_LINGERS: Duration = Duration::from_millis(150);

/// The window's frame times and the ray caster's share of them.
#[derive(Debug, Default)]
pub struct Pacing {
    /// When the last UI frame began, if it asked for the next (None after an idle frame).
    last_ui_frame: Option<Instant>,
    /// Smoothed UI frame interval while the window draws continuously, ms.
    pub ui_frame_ms: f64,
    /// Running mean of the ray casting time per UI frame, milliseconds.
    pub ray_ms: f64,
    /// Until when the user counts as interacting (dragging, scrolling).
    interacting_until: Option<Instant>,
}

impl Pacing {
    /// A UI frame begins; returns the milliseconds since the previous one, if the window
    /// was drawing continuously.
    pub fn begin_frame(&mut self) -> Option<f64> {
        let now = Instant::now();
        let dt = self
            .last_ui_frame
            .map(|last| now.duration_since(last).as_secs_f64() * 1e3);
        if let Some(dt) = dt {
            self.ui_frame_ms = if self.ui_frame_ms == 0.0 {
                dt
            } else {
                0.9 * self.ui_frame_ms + 0.1 * dt
            };
        }
        self.last_ui_frame = Some(now);
        dt
    }

    /// The window goes idle until the next event: that wait is no frame's time (it read
    /// "UI 1 fps" at the first event after a converged picture).
    pub fn idle(&mut self) {
        self.last_ui_frame = None;
    }

    /// The user dragged or scrolled the picture in this frame.
    pub fn interacted(&mut self) {
        self.interacting_until = Some(Instant::now() + INTERACTION_LINGERS);
    }

    /// Whether the user is interacting (or was a moment ago).
    pub fn interacting(&self) -> bool {
        self.interacting_until.is_some_and(|t| Instant::now() < t)
    }

    /// Milliseconds of ray casting this frame may take: what the rest of a frame leaves of
    /// the target, within the bounds.
    pub fn ray_budget_ms(&self) -> f64 {
        let rest_ms = (self.ui_frame_ms - self.ray_ms).max(0.0);
        let cap = if self.interacting() {
            RAY_BUDGET_DRAGGING_MS
        } else {
            RAY_BUDGET_MS[1]
        };
        (FRAME_TARGET_MS - rest_ms).clamp(RAY_BUDGET_MS[0], cap)
    }

    /// Milliseconds from submitting one run of squares to the word that it is done, where
    /// the window cannot wait for the GPU: six UI frames (the word takes one or more),
    /// within `GPU_RUN_MS`.
    pub fn gpu_run_ms(&self) -> f64 {
        (6.0 * self.ui_frame_ms).clamp(GPU_RUN_MS[0], GPU_RUN_MS[1])
    }

    /// The ray casting of this frame took `ms`.
    pub fn rays_took(&mut self, ms: f64) {
        self.ray_ms = 0.9 * self.ray_ms + 0.1 * ms;
    }

    /// UI frames per second while drawing continuously.
    pub fn fps(&self) -> f64 {
        1000.0 / self.ui_frame_ms.max(1.0)
    }
}
