//! The page's animation export: the "Export animation" section and an animated GIF or PNG
//! drawn a frame at a time on the page's device, each frame read back over the window's
//! frames (a page cannot wait for the GPU) and encoded in memory, then downloaded; with its
//! progress and Cancel, which downloads the frames drawn so far.

use std::cell::RefCell;
use std::io::Write;
use std::rc::Rc;
use std::sync::Arc;

use eframe::egui;

use fourfold::CompiledFormula;
use fourfold::render::apng::{ApngFrames, is_apng_extension, set_frame_count};
use fourfold::render::gif::GifFrames;
use fourfold::render::verdict::VerdictCounts;
use fourfold::render::{AnimationFrames, Device, PendingPicture};

use crate::animation::{Asked, choices, chosen_animation, start_or_progress};
use crate::notice::Notice;
use crate::outcome::{Outcome, Window};

use super::files::download;

/// The kinds of file the page's animation downloads as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Gif,
    Apng,
}

impl Kind {
    /// The kind the section's file name asks for: an animated PNG for `.png` or `.apng`
    /// (as the desktop's path does), else a GIF.
    fn of(path: &str) -> Self {
        let extension = std::path::Path::new(path).extension();
        if extension
            .and_then(|e| e.to_str())
            .is_some_and(is_apng_extension)
        {
            Kind::Apng
        } else {
            Kind::Gif
        }
    }

    /// The name it downloads as, and its MIME type.
    fn file(self) -> (&'static str, &'static str) {
        match self {
            Kind::Gif => ("fourfold.gif", "image/gif"),
            Kind::Apng => ("fourfold.png", "image/png"),
        }
    }
}

/// The encoder writing the frames into memory.
enum Encoder {
    Gif(GifFrames<Bytes>),
    Apng(ApngFrames<Bytes>),
}

impl Encoder {
    fn add(&mut self, rgba: Vec<u8>) -> Result<(), String> {
        match self {
            Encoder::Gif(gif) => gif.add(rgba),
            Encoder::Apng(apng) => apng.add(&rgba),
        }
    }

    /// Ends the file in `bytes` (an animated PNG stopped early says how many frames it has).
    fn finish(self, bytes: &Bytes) -> Result<(), String> {
        match self {
            // Dropping the encoder writes the GIF's end.
            Encoder::Gif(gif) => drop(gif),
            Encoder::Apng(apng) => {
                let finished = apng.finish()?;
                if finished.mend {
                    let mut written = bytes.0.borrow_mut();
                    set_frame_count(&mut std::io::Cursor::new(&mut *written), finished.frames)
                        .map_err(|e| e.to_string())?;
                }
            }
        }
        Ok(())
    }
}

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
    choices(ui, &mut window.settings.animation, &params);
    ui.horizontal(|ui| {
        let path = &mut window.settings.animation.path;
        let mut kind = Kind::of(path);
        ui.radio_value(&mut kind, Kind::Gif, "GIF").on_hover_text(
            "an animated GIF, downloaded (256 colours); the size is the PNG export's",
        );
        ui.radio_value(&mut kind, Kind::Apng, "animated PNG")
            .on_hover_text(
                "an animated PNG, downloaded (full colour, larger); the size is the PNG export's",
            );
        *path = kind.file().0.to_string();
        let (asked, at) = start_or_progress(ui, running.as_ref().map(|a| (a.drawn, a.frames)));
        *button = Some(at);
        match asked {
            Asked::Start => {
                return match AnimationDownload::start(window) {
                    Ok(export) => {
                        let said =
                            format!("drawing {} frames into {}…", export.frames, export.name());
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
    /// The file being written, and its kind.
    encoder: Option<Encoder>,
    kind: Kind,
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
        let [width, height] = size;
        let kind = Kind::of(&window.settings.animation.path);
        let encoder = match kind {
            Kind::Gif => Encoder::Gif(GifFrames::new(bytes.clone(), width, height, animation.fps)?),
            Kind::Apng => Encoder::Apng(ApngFrames::new(
                bytes.clone(),
                width,
                height,
                animation.fps,
                animation.frames,
            )?),
        };
        Ok(Self {
            frames_of,
            formula,
            pending: None,
            encoder: Some(encoder),
            kind,
            bytes,
            verdicts: window
                .session
                .scene
                .render
                .certified
                .then(VerdictCounts::default),
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
            let added = self.encoder.as_mut().map(|e| e.add(picture.rgba));
            if let Some(Err(e)) = added {
                return Some(Notice::error(format!("cannot encode {}: {e}", self.name())));
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

    /// The name the animation downloads as.
    fn name(&self) -> &'static str {
        self.kind.file().0
    }

    /// Ends the file with the frames drawn and hands it to the browser.
    fn finish(&mut self) -> Notice {
        let (name, mime) = self.kind.file();
        if self.drawn == 0 {
            return Notice::done(format!("stopped before the first frame: no {name}"));
        }
        if let Some(Err(e)) = self.encoder.take().map(|e| e.finish(&self.bytes)) {
            return Notice::error(format!("cannot encode {name}: {e}"));
        }
        let bytes = self.bytes.0.borrow();
        let stopped = if self.drawn < self.frames {
            format!("stopped after {} of {} frames: ", self.drawn, self.frames)
        } else {
            String::new()
        };
        match download(name, mime, &bytes) {
            Ok(()) => Notice::done(format!(
                "{stopped}{name} downloaded ({} frames, {} KB){}",
                self.drawn,
                bytes.len() / 1000,
                crate::export::certified_note(self.verdicts)
            )),
            Err(e) => Notice::error(e),
        }
    }
}
