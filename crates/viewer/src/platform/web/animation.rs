//! The page's animation export: the "Export animation" section and an animated GIF drawn a
//! frame at a time on the page's device, each frame read back over the window's frames
//! (a page cannot wait for the GPU) and encoded in memory, then downloaded; with its
//! progress and Cancel, which downloads the frames drawn so far.

use std::cell::RefCell;
use std::io::Write;
use std::rc::Rc;
use std::sync::Arc;

use eframe::egui;

use fourfold::CompiledFormula;
use fourfold::render::gif::GifFrames;
use fourfold::render::verdict::VerdictCounts;
use fourfold::render::{AnimationFrames, Device, PendingPicture};

use crate::animation::{Asked, choices, chosen_animation, start_or_progress};
use crate::notice::Notice;
use crate::outcome::{Outcome, Window};

use super::files::download;

/// The name the animation downloads as.
const NAME: &str = "fourfold.gif";

/// The "Export animation" section: what moves, how many frames; the size is the PNG
/// export's.
/// `button` is where its button was drawn (the page's tests click it).
pub fn section(
    running: &mut Option<AnimationDownload>,
    button: &mut Option<egui::Rect>,
    ui: &mut egui::Ui,
    window: Window<'_>,
) -> Outcome {
    let params = window.session.param_names();
    let c = &mut window.settings.animation;
    choices(ui, c, &params);
    ui.horizontal(|ui| {
        ui.label(NAME)
            .on_hover_text("an animated GIF, downloaded; the size is the PNG export's");
        let (asked, at) = start_or_progress(ui, running.as_ref().map(|a| (a.drawn, a.frames)));
        *button = Some(at);
        match asked {
            Asked::Start => {
                return match AnimationDownload::start(window) {
                    Ok(export) => {
                        let said = format!("drawing {} frames into {NAME}…", export.frames);
                        *running = Some(export);
                        Outcome::said(Notice::done(said))
                    }
                    Err(e) => Outcome::said(Notice::error(e)),
                };
            }
            Asked::Cancel => running.iter_mut().for_each(|a| a.cancelled = true),
            Asked::Nothing => {}
        }
        Outcome::default()
    })
    .inner
}

/// The GIF's bytes, shared by the encoder writing them and the download reading them.
#[derive(Clone, Default)]
struct Bytes(Rc<RefCell<Vec<u8>>>);

impl Write for Bytes {
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().extend_from_slice(data);
        Ok(data.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// An animation being drawn on the page's device and encoded, a frame at a time.
pub struct AnimationDownload {
    frames_of: AnimationFrames,
    formula: Arc<CompiledFormula>,
    pending: Option<PendingPicture>,
    /// The GIF being written (dropping it writes its end).
    gif: Option<GifFrames<Bytes>>,
    bytes: Bytes,
    /// The certified frames' verdicts, summed (where the scene certifies).
    verdicts: Option<VerdictCounts>,
    /// Frames drawn so far, of all.
    pub drawn: u32,
    pub frames: u32,
    cancelled: bool,
}

impl AnimationDownload {
    /// Starts the animation the section is set to, of the scene on screen.
    fn start(window: Window<'_>) -> Result<Self, String> {
        let (Some(gpu), Some(program)) = (window.gpu, &window.session.program) else {
            return Err("no picture yet: wait for the tree to be built".into());
        };
        let animation = chosen_animation(&window.settings.animation)?;
        let size = window.settings.export_size;
        let formula = program.formula.clone();
        let frames_of = AnimationFrames::new(
            &window.session.scene,
            &formula,
            &animation,
            size,
            window.settings.animation.fit,
            Device::Gpu(gpu),
        )?;
        let bytes = Bytes::default();
        let gif = GifFrames::new(bytes.clone(), size[0], size[1], animation.fps)?;
        Ok(Self {
            frames_of,
            formula,
            pending: None,
            gif: Some(gif),
            bytes,
            verdicts: window.session.scene.render.certified.then(VerdictCounts::default),
            drawn: 0,
            frames: animation.frames,
            cancelled: false,
        })
    }

    /// Takes the frame that came back, if one did, and starts the next; the outcome once
    /// the GIF is downloaded (or failed), else None.
    pub fn poll(&mut self) -> Option<Notice> {
        if let Some(pending) = &mut self.pending {
            let picture = match pending.poll()? {
                Ok(picture) => picture,
                Err(e) => return Some(Notice::error(e.to_string())),
            };
            self.pending = None;
            if let (Some(total), Some(counts)) = (&mut self.verdicts, picture.verdict_counts()) {
                *total += counts;
            }
            let added = self.gif.as_mut().map(|gif| gif.add(picture.rgba));
            if let Some(Err(e)) = added {
                return Some(Notice::error(format!("cannot encode {NAME}: {e}")));
            }
            self.drawn += 1;
        }
        if !self.cancelled {
            match self.frames_of.start_next(&self.formula) {
                Ok(Some(pending)) => {
                    self.pending = Some(pending);
                    return None;
                }
                Ok(None) => {}
                Err(e) => return Some(Notice::error(e)),
            }
        }
        Some(self.finish())
    }

    /// Ends the GIF with the frames drawn and hands it to the browser.
    fn finish(&mut self) -> Notice {
        if self.drawn == 0 {
            return Notice::done(format!("stopped before the first frame: no {NAME}"));
        }
        drop(self.gif.take());
        let bytes = self.bytes.0.borrow();
        let stopped = if self.drawn < self.frames {
            format!("stopped after {} of {} frames: ", self.drawn, self.frames)
        } else {
            String::new()
        };
        match download(NAME, "image/gif", &bytes) {
            Ok(()) => Notice::done(format!(
                "{stopped}{NAME} downloaded ({} frames, {} KB){}",
                self.drawn,
                bytes.len() / 1000,
                crate::export::certified_note(self.verdicts)
            )),
            Err(e) => Notice::error(e),
        }
    }
}
