//! Where an animation's frames go: an animated GIF, an animated PNG or a folder of numbered
//! PNGs, written a frame at a time, and finished (or mended, when stopped early) at the end.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use crate::render::apng::{ApngFrames, is_apng_extension, set_frame_count};
use crate::render::gif::GifFrames;

/// Where the frames go, by the output's name: `.gif`, `.png` or `.apng` (an animated PNG),
/// or a folder (a name without an extension, or ending in '/') of `frame-0001.png`, ….
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    Gif(PathBuf),
    Apng(PathBuf),
    Folder(PathBuf),
}

impl Output {
    pub fn from_path(path: &Path) -> Result<Self, String> {
        let text = path.to_string_lossy();
        if text.ends_with('/') || path.is_dir() {
            return Ok(Output::Folder(path.to_path_buf()));
        }
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("gif") => Ok(Output::Gif(path.to_path_buf())),
            Some(e) if is_apng_extension(e) => Ok(Output::Apng(path.to_path_buf())),
            None => Ok(Output::Folder(path.to_path_buf())),
            Some(e) => Err(format!(
                "{}: unknown kind of file '.{e}': name a .gif, a .png (animated) or a folder",
                path.display()
            )),
        }
    }

    /// Opens the output for writing (before any frame is drawn, so that an unwritable
    /// place is said at once).
    /// `frames` is how many frames the animation will have (an animated PNG declares it
    /// first; one stopped early is mended when it is finished).
    pub fn open(
        &self,
        width: u32,
        height: u32,
        fps: f64,
        frames: u32,
    ) -> Result<FrameWriter, String> {
        match self {
            Output::Gif(path) => {
                let frames = GifFrames::new(create(path)?, width, height, fps)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                Ok(FrameWriter::Gif {
                    frames,
                    path: path.clone(),
                    count: 0,
                })
            }
            Output::Apng(path) => {
                let frames = ApngFrames::new(create(path)?, width, height, fps, frames)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                Ok(FrameWriter::Apng {
                    frames,
                    path: path.clone(),
                })
            }
            Output::Folder(path) => {
                std::fs::create_dir_all(path)
                    .map_err(|e| format!("cannot make the folder {}: {e}", path.display()))?;
                Ok(FrameWriter::Folder {
                    path: path.clone(),
                    width,
                    height,
                    count: 0,
                })
            }
        }
    }
}

fn create(path: &Path) -> Result<BufWriter<File>, String> {
    File::create(path)
        .map(BufWriter::new)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// An output being written, a frame at a time.
pub enum FrameWriter {
    Gif {
        frames: GifFrames<BufWriter<File>>,
        path: PathBuf,
        count: u32,
    },
    Apng {
        frames: ApngFrames<BufWriter<File>>,
        path: PathBuf,
    },
    Folder {
        path: PathBuf,
        width: u32,
        height: u32,
        count: u32,
    },
}

impl FrameWriter {
    /// Adds a frame (RGBA8 rows).
    pub fn add(&mut self, rgba: Vec<u8>) -> Result<(), String> {
        match self {
            FrameWriter::Gif {
                frames,
                path,
                count,
            } => {
                frames
                    .add(rgba)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                *count += 1;
            }
            FrameWriter::Apng { frames, path } => {
                frames
                    .add(&rgba)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            }
            FrameWriter::Folder {
                path,
                width,
                height,
                count,
            } => {
                *count += 1;
                let file = path.join(format!("frame-{count:04}.png"));
                image::save_buffer(
                    &file,
                    &rgba,
                    *width,
                    *height,
                    image::ExtendedColorType::Rgba8,
                )
                .map_err(|e| format!("cannot write {}: {e}", file.display()))?;
            }
        }
        Ok(())
    }

    /// Finishes the file with the frames added so far; says what was written.
    pub fn finish(self) -> Result<String, String> {
        match self {
            FrameWriter::Gif {
                frames,
                path,
                count,
            } => {
                // Dropping the encoder writes the GIF's trailer.
                drop(frames);
                Ok(format!("{} ({count} frames, animated GIF)", path.display()))
            }
            FrameWriter::Apng { frames, path } => {
                let failed = |e: String| format!("cannot write {}: {e}", path.display());
                let finished = frames.finish().map_err(failed)?;
                let count = finished.frames;
                if count == 0 {
                    std::fs::remove_file(&path).ok();
                    return Ok(format!("{} (no frame drawn, not written)", path.display()));
                }
                if finished.mend {
                    // Stopped early: the file says how many frames it has.
                    std::fs::OpenOptions::new()
                        .read(true)
                        .write(true)
                        .open(&path)
                        .and_then(|mut file| set_frame_count(&mut file, count))
                        .map_err(|e| failed(e.to_string()))?;
                }
                Ok(format!("{} ({count} frames, animated PNG)", path.display()))
            }
            FrameWriter::Folder { path, count, .. } => Ok(format!(
                "{} ({count} frames, frame-0001.png …)",
                path.display()
            )),
        }
    }
}
