//! Where an animation's frames go: an animated GIF, an animated PNG or a folder of numbered
//! PNGs, written a frame at a time, and finished (or mended, when stopped early) at the end.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use crate::render::gif::{GifFrames, frame_delay_ms};

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
            Some(e) if e.eq_ignore_ascii_case("png") || e.eq_ignore_ascii_case("apng") => {
                Ok(Output::Apng(path.to_path_buf()))
            }
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
        let delay_ms = frame_delay_ms(fps);
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
                let failed =
                    |e: png::EncodingError| format!("cannot write {}: {e}", path.display());
                let mut encoder = png::Encoder::new(create(path)?, width, height);
                encoder.set_color(png::ColorType::Rgba);
                encoder.set_depth(png::BitDepth::Eight);
                encoder.set_animated(frames.max(1), 0).map_err(failed)?;
                encoder.set_frame_delay(delay_ms, 1000).map_err(failed)?;
                Ok(FrameWriter::Apng {
                    writer: encoder.write_header().map_err(failed)?,
                    path: path.clone(),
                    declared: frames.max(1),
                    count: 0,
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
        writer: png::Writer<BufWriter<File>>,
        path: PathBuf,
        /// The frames the file says it has.
        declared: u32,
        count: u32,
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
            FrameWriter::Apng {
                writer,
                path,
                count,
                ..
            } => {
                writer
                    .write_image_data(&rgba)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                *count += 1;
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
            FrameWriter::Apng {
                writer,
                path,
                declared,
                count,
            } => {
                let failed = |e: String| format!("cannot write {}: {e}", path.display());
                if count == declared {
                    writer.finish().map_err(|e| failed(e.to_string()))?;
                } else {
                    // Stopped early: close the file, then say how many frames it has.
                    drop(writer);
                    if count == 0 {
                        std::fs::remove_file(&path).ok();
                        return Ok(format!("{} (no frame drawn, not written)", path.display()));
                    }
                    set_frame_count(&path, count).map_err(|e| failed(e.to_string()))?;
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

/// Rewrites the frame count in an animated PNG's `acTL` chunk (and its checksum): for a file
/// whose writing stopped before the frames it declared.
fn set_frame_count(path: &Path, frames: u32) -> std::io::Result<()> {
    use std::io::{Read, Seek, SeekFrom, Write};
    let mut file = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)?;
    // The chunks after the 8-byte signature: length, type, data, CRC.
    let mut at = 8u64;
    loop {
        let mut head = [0u8; 8];
        file.seek(SeekFrom::Start(at))?;
        file.read_exact(&mut head)?;
        let length = u64::from(u32::from_be_bytes([head[0], head[1], head[2], head[3]]));
        if &head[4..] == b"acTL" {
            let mut data = [0u8; 8];
            file.read_exact(&mut data)?;
            data[..4].copy_from_slice(&frames.to_be_bytes());
            let mut crc = crc32fast::Hasher::new();
            crc.update(b"acTL");
            crc.update(&data);
            file.seek(SeekFrom::Start(at + 8))?;
            file.write_all(&data)?;
            file.write_all(&crc.finalize().to_be_bytes())?;
            return Ok(());
        }
        if &head[4..] == b"IDAT" || &head[4..] == b"IEND" {
            return Err(std::io::Error::other("no acTL chunk before the image data"));
        }
        at += 12 + length;
    }
}
