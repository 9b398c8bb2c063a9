//! An animated PNG written a frame at a time into any writer: a file (`fourfold animate`,
//! the desktop's export) or a page's memory (its download). An animated PNG states its
//! frame count before the first frame, so one stopped early is mended once written
//! ([`set_frame_count`]).

use std::io::{Read, Seek, SeekFrom, Write};

use super::gif::frame_delay_ms;

/// Whether a file's extension asks for an animated PNG: `png` or `apng`, in any case (a
/// GIF is `gif`).
pub fn is_apng_extension(extension: &str) -> bool {
    extension.eq_ignore_ascii_case("png") || extension.eq_ignore_ascii_case("apng")
}

/// An animated PNG being written (it loops).
pub struct ApngFrames<W: Write> {
    writer: png::Writer<W>,
    /// The frames the file says it has, and those written.
    declared: u32,
    count: u32,
}

/// How an animated PNG ended: the frames it holds, and whether its stated count must be
/// mended to that ([`set_frame_count`] on what was written).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Finished {
    pub frames: u32,
    pub mend: bool,
}

impl<W: Write> ApngFrames<W> {
    /// Starts the animated PNG of `frames` frames of `width`×`height` at `fps` in `out`.
    pub fn new(out: W, width: u32, height: u32, fps: f64, frames: u32) -> Result<Self, String> {
        let declared = frames.max(1);
        let mut encoder = png::Encoder::new(out, width, height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder
            .set_animated(declared, 0)
            .map_err(|e| e.to_string())?;
        encoder
            .set_frame_delay(frame_delay_ms(fps), 1000)
            .map_err(|e| e.to_string())?;
        Ok(Self {
            writer: encoder.write_header().map_err(|e| e.to_string())?,
            declared,
            count: 0,
        })
    }

    /// Adds a frame (RGBA8 rows).
    pub fn add(&mut self, rgba: &[u8]) -> Result<(), String> {
        self.writer
            .write_image_data(rgba)
            .map_err(|e| e.to_string())?;
        self.count += 1;
        Ok(())
    }

    /// Ends the file with the frames added so far.
    pub fn finish(self) -> Result<Finished, String> {
        let frames = self.count;
        let mend = frames < self.declared;
        if mend {
            // Dropping the writer ends the file; its count is mended afterwards.
            drop(self.writer);
        } else {
            self.writer.finish().map_err(|e| e.to_string())?;
        }
        Ok(Finished { frames, mend })
    }
}

/// Rewrites the frame count in an animated PNG's `acTL` chunk (and its checksum): for one
/// whose writing stopped before the frames it declared.
pub fn set_frame_count(file: &mut (impl Read + Write + Seek), frames: u32) -> std::io::Result<()> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The frame count an animated PNG's decoder reads, and its frames decoded.
    fn decoded(bytes: &[u8]) -> (u32, u32) {
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let stated = reader.info().animation_control().unwrap().num_frames;
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let mut read = 0;
        while read < stated && reader.next_frame(&mut buf).is_ok() {
            read += 1;
        }
        (stated, read)
    }

    #[test]
    fn an_animation_stopped_early_states_the_frames_it_has() {
        let frame = vec![200u8; 4 * 3 * 2];
        for written in [4, 2] {
            let mut bytes = Vec::new();
            let mut apng = ApngFrames::new(&mut bytes, 3, 2, 10.0, 4).unwrap();
            for _ in 0..written {
                apng.add(&frame).unwrap();
            }
            let finished = apng.finish().unwrap();
            assert_eq!(finished.frames, written);
            assert_eq!(finished.mend, written < 4);
            if finished.mend {
                set_frame_count(&mut std::io::Cursor::new(&mut bytes), written).unwrap();
            }
            assert_eq!(decoded(&bytes), (written, written));
        }
    }
}
