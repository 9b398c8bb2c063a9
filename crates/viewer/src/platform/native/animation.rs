//! The desktop's animation export: the "Export animation" section (what moves, how many
//! frames, where to) and the animation drawn and written on a thread and a device of its
//! own, with its progress and Cancel.

use super::threads;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, TryRecvError, channel};

use eframe::egui;

use fourfold::CompiledFormula;
use fourfold::critical::sweep::{place_frames, straddle_lines};
use fourfold::headless::{FrameDevice, Output, draw};
use fourfold::render::animation::Animation;
use fourfold::scene::Scene;

use crate::animation::{Asked, choices, chosen_animation, start_or_progress};
use crate::notice::Notice;
use crate::outcome::{Outcome, Window};
use crate::session::Session;
use crate::settings::AnimationChoice;

/// The "Export animation" section: what moves, how many frames, where to.
pub fn section(
    running: &mut Option<AnimationExport>,
    ui: &mut egui::Ui,
    window: Window<'_>,
) -> Outcome {
    let params = window.session.param_names();
    let size = window.settings.export_size;
    let c = &mut window.settings.animation;
    choices(ui, c, &params);
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut c.path).desired_width(150.0))
            .on_hover_text("a .gif, an animated .png, or a folder for numbered PNGs; the size is the PNG export's");
        match start_or_progress(ui, running.as_ref().map(|e| (e.drawn(), e.frames))).0 {
            Asked::Start => {
                let outcome = export_animation(window.session, c, size);
                *running = outcome.1;
                return outcome.0;
            }
            Asked::Cancel => running.iter().for_each(AnimationExport::cancel),
            Asked::Nothing => {}
        }
        Outcome::default()
    })
    .inner
}

/// Starts drawing the animation `choice` asks for of the session's scene at `size`, or
/// says why it cannot.
fn export_animation(
    session: &Session,
    choice: &AnimationChoice,
    size: [u32; 2],
) -> (Outcome, Option<AnimationExport>) {
    let Some(program) = &session.program else {
        let notice = Notice::error("no picture yet: wait for the tree to be built");
        return (Outcome::said(notice), None);
    };
    match chosen_animation(choice) {
        Ok(animation) => {
            let [w, h] = size;
            let path = choice.path.clone();
            let message = format!(
                "drawing {} frames of {w}x{h} into {path}…",
                animation.frames
            );
            let job = Job {
                scene: session.scene.clone(),
                formula: program.formula.clone(),
                animation,
                size,
                fit: choice.fit,
                path,
            };
            let export = AnimationExport::start(job);
            (Outcome::said(Notice::done(message)), Some(export))
        }
        Err(e) => (Outcome::said(Notice::error(e)), None),
    }
}

/// An animation being drawn and written in the background, with its progress.
pub struct AnimationExport {
    result: Receiver<Result<String, String>>,
    /// Frames drawn so far.
    drawn: Arc<AtomicU32>,
    pub frames: u32,
    stop: Arc<AtomicBool>,
}

impl AnimationExport {
    /// Draws `job`'s animation on a new GPU device, off the UI thread.
    fn start(job: Job) -> Self {
        let (tx, rx) = channel();
        let drawn = Arc::new(AtomicU32::new(0));
        let stop = Arc::new(AtomicBool::new(false));
        let frames = job.animation.frames;
        {
            let (drawn, stop) = (drawn.clone(), stop.clone());
            // (If no thread can start, the sender is dropped with the job: the export
            // ends with an error.)
            let _ = threads::spawn("fourfold animation", move || {
                let _ = tx.send(job.write(&stop, &drawn));
            });
        }
        Self {
            result: rx,
            drawn,
            frames,
            stop,
        }
    }

    /// Frames drawn so far.
    pub fn drawn(&self) -> u32 {
        self.drawn.load(Ordering::Relaxed)
    }

    /// Stops after the frame being drawn; the file keeps the frames drawn so far.
    pub fn cancel(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// The export's outcome once it is done.
    pub fn poll(&self) -> Option<Notice> {
        match self.result.try_recv() {
            Ok(result) => Some(Notice::of(result)),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => Some(Notice::error(
                "the animation export stopped before writing its file",
            )),
        }
    }
}

/// An animation to draw: the scene on screen and its compiled formula, what moves, the
/// picture's size, whether to frame the manifold in every frame, and the file.
struct Job {
    scene: Scene,
    formula: Arc<CompiledFormula>,
    animation: Animation,
    size: [u32; 2],
    fit: bool,
    path: String,
}

impl Job {
    /// Draws the frames into the file, counting them in `drawn`, until done or `stop`.
    fn write(&self, stop: &AtomicBool, drawn: &AtomicU32) -> Result<String, String> {
        let [width, height] = self.size;
        let mut animation = self.animation.clone();
        let critical = place_frames(&mut animation, &self.formula, &self.scene);
        let animation = &animation;
        let output = Output::from_path(std::path::Path::new(&self.path))?;
        let mut writer = output.open(width, height, animation.fps, animation.frames)?;
        let gpu = threads::open_gpu()?;
        let done = draw(
            &self.scene,
            &self.formula,
            animation,
            width,
            height,
            self.fit,
            FrameDevice::Gpu(&gpu),
            stop,
            |k, rgba| {
                writer.add(rgba)?;
                drawn.store(k + 1, Ordering::Relaxed);
                Ok(())
            },
        );
        let wrote = writer.finish()?;
        let drawn = done?;
        let done = drawn.frames;
        let mut said = if done < animation.frames {
            format!(
                "stopped after {done} of {} frames: wrote {wrote}",
                animation.frames
            )
        } else {
            format!("wrote {wrote}")
        };
        said.push_str(&crate::export::certified_note(drawn.verdicts));
        if let Some(report) = critical {
            for line in straddle_lines(&animation.slice_places, &report) {
                said.push_str(&format!("\n{line}"));
            }
        }
        Ok(said)
    }
}
