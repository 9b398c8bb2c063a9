//! An animated GIF written a frame at a time into any writer: a file (`fourfold animate`,
//! the desktop's export) or a page's memory (its download).

use std::io::Write;

use image::codecs::gif::{GifEncoder, Repeat};

/// A frame's delay in milliseconds at `fps` frames a second, as GIF and PNG store it.
pub fn frame_delay_ms(fps: f64) -> u16 {
    (1000.0 / fps).round().clamp(1.0, 65_535.0) as u16
}

/// An animated GIF being written (it loops); dropping it writes the file's end.
pub struct GifFrames<W: Write> {
    encoder: GifEncoder<W>,
    width: u32,
    height: u32,
    delay_ms: u16,
}

impl<W: Write> GifFrames<W> {
    /// Starts the GIF of `width`×`height` frames at `fps` in `out`.
    pub fn new(out: W, width: u32, height: u32, fps: f64) -> Result<Self, String> {
        let mut encoder = GifEncoder::new_with_speed(out, 10);
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(|e| e.to_string())?;
        Ok(Self {
            encoder,
            width,
            height,
            delay_ms: frame_delay_ms(fps),
        })
    }

    /// Adds a frame (RGBA8 rows).
    pub fn add(&mut self, rgba: Vec<u8>) -> Result<(), String> {
        let image = image::RgbaImage::from_raw(self.width, self.height, rgba)
            .ok_or("internal error: a frame of the wrong size")?;
        let delay = image::Delay::from_numer_denom_ms(u32::from(self.delay_ms), 1);
        self.encoder
            .encode_frame(image::Frame::from_parts(image, 0, 0, delay))
            .map_err(|e| e.to_string())
    }
}
