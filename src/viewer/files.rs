//! The viewer's file actions: open and save scene files, export the WGSL, and export a PNG
//! or an animation rendered on a device of its own in the background. Each says what it did in a
//! [`Notice`] for the status line.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, channel};

use crate::CompiledFormula;
use crate::render::animation::{Animation, FrameDevice, Output, draw};
use crate::render::pipeline::{Device, render_scene};
use crate::render::{FrameOptions, Gpu};
use crate::scene::Scene;

/// A short message after an action: what was done, or what went wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct Notice {
    pub text: String,
    pub is_error: bool,
}

impl Notice {
    pub fn done(text: impl Into<String>) -> Self {
        Self {
            text: text.into(),
            is_error: false,
        }
    }

    pub fn error(text: impl Into<String>) -> Self {
        Self {
            text: text.into(),
            is_error: true,
        }
    }

    fn of(result: Result<String, String>) -> Self {
        match result {
            Ok(text) => Self::done(text),
            Err(text) => Self::error(text),
        }
    }
}

/// What a background job sent once it is done; `died` if its thread ended without a word.
fn outcome(result: &Receiver<Result<String, String>>, died: &str) -> Option<Notice> {
    use std::sync::mpsc::TryRecvError;
    match result.try_recv() {
        Ok(result) => Some(Notice::of(result)),
        Err(TryRecvError::Empty) => None,
        Err(TryRecvError::Disconnected) => Some(Notice::error(died)),
    }
}

/// Writes `scene` as TOML to `path`.
pub fn save_scene(scene: &Scene, path: &str) -> Notice {
    match std::fs::write(path, scene.to_toml()) {
        Ok(()) => Notice::done(format!("saved scene to {path}")),
        Err(e) => Notice::error(format!("cannot write {path}: {e}")),
    }
}

/// Reads the scene file at `path`.
pub fn open_scene(path: &str) -> Result<Scene, Notice> {
    Scene::load(std::path::Path::new(path)).map_err(|e| Notice::error(e.to_string()))
}

/// Writes the shader's source to `path`.
pub fn export_wgsl(source: &str, path: &str) -> Notice {
    match std::fs::write(path, source) {
        Ok(()) => Notice::done(format!("saved the shader to {path}")),
        Err(e) => Notice::error(format!("cannot write {path}: {e}")),
    }
}

/// A PNG export running in the background.
pub struct PngExport {
    result: Receiver<Result<String, String>>,
}

impl PngExport {
    /// Renders `scene` at `width`×`height` on a new GPU device, off the UI thread, and
    /// writes it to `path`.
    pub fn start(scene: Scene, width: u32, height: u32, path: String) -> Self {
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            let picture = render_scene(
                &scene,
                width,
                height,
                Device::NewGpu,
                FrameOptions::default(),
            )
            .map_err(|e| e.to_string());
            let result = picture.and_then(|pic| {
                image::save_buffer(
                    &path,
                    &pic.rgba,
                    width,
                    height,
                    image::ExtendedColorType::Rgba8,
                )
                .map_err(|e| format!("cannot write {path}: {e}"))
                .map(|_| {
                    format!(
                        "saved {path} ({width}x{height}, frame {:.0} ms on {})",
                        pic.times.frame_ms, pic.adapter
                    )
                })
            });
            let _ = tx.send(result);
        });
        Self { result: rx }
    }

    /// The export's outcome once it is done.
    pub fn poll(&self) -> Option<Notice> {
        outcome(
            &self.result,
            "the export stopped before writing its picture",
        )
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
    /// Draws `animation` of `scene` at `width`×`height` on a new GPU device, off the UI
    /// thread, into `path` (a .gif, an animated .png or a folder).
    pub fn start(
        scene: Scene,
        animation: Animation,
        width: u32,
        height: u32,
        fit: bool,
        path: String,
    ) -> Self {
        let (tx, rx) = channel();
        let drawn = Arc::new(AtomicU32::new(0));
        let stop = Arc::new(AtomicBool::new(false));
        let frames = animation.frames;
        {
            let (drawn, stop) = (drawn.clone(), stop.clone());
            std::thread::spawn(move || {
                let result =
                    write_animation(&scene, &animation, width, height, fit, &path, &stop, &drawn);
                let _ = tx.send(result);
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
        outcome(
            &self.result,
            "the animation export stopped before writing its file",
        )
    }
}

#[allow(clippy::too_many_arguments)]
fn write_animation(
    scene: &Scene,
    animation: &Animation,
    width: u32,
    height: u32,
    fit: bool,
    path: &str,
    stop: &AtomicBool,
    drawn: &AtomicU32,
) -> Result<String, String> {
    let formula = CompiledFormula::compile(&scene.formula)
        .map_err(|e| e.render("formula", &scene.formula))?;
    let output = Output::from_path(std::path::Path::new(path))?;
    let mut writer = output.open(width, height, animation.fps, animation.frames)?;
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    let done = draw(
        scene,
        &formula,
        animation,
        width,
        height,
        fit,
        FrameDevice::Gpu(&gpu),
        stop,
        |k, rgba| {
            writer.add(rgba)?;
            drawn.store(k + 1, Ordering::Relaxed);
            Ok(())
        },
    );
    let wrote = writer.finish()?;
    let done = done?.frames;
    Ok(if done < animation.frames {
        format!(
            "stopped after {done} of {} frames: wrote {wrote}",
            animation.frames
        )
    } else {
        format!("wrote {wrote}")
    })
}
