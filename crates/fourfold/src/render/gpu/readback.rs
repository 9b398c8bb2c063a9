//! Reading a frame back from the GPU without waiting: the copy into a mappable buffer, and
//! the pending frame a caller polls until it is there (a web page cannot wait for the GPU;
//! a native caller waits by polling the device, see the `headless` module).

use std::sync::{Arc, Mutex};

use super::device::{Gpu, GpuError};

/// A buffer being mapped for reading: [`Mapping::ready`] once the GPU is done with it.
pub struct Mapping {
    buffer: wgpu::Buffer,
    state: Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>,
}

impl Mapping {
    /// Starts mapping all of `buffer` (made with MAP_READ, its writes submitted).
    pub fn start(buffer: wgpu::Buffer) -> Self {
        let state = Arc::new(Mutex::new(None));
        let mapped = state.clone();
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            *mapped.lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
        });
        Self { buffer, state }
    }

    /// Whether the mapping is done (or failed). The device must be polled for it to finish
    /// natively (a browser's event loop finishes it in a page).
    pub fn ready(&self) -> bool {
        self.state
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .is_some()
    }

    /// `read` of the buffer's contents, once [`Mapping::ready`]; then unmapped.
    pub fn read<T>(&self, read: impl FnOnce(&[u8]) -> T) -> Result<T, GpuError> {
        let state = self
            .state
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()
            .ok_or_else(|| GpuError::Readback("read before the buffer was mapped".into()))?;
        state.map_err(|e| GpuError::Readback(e.to_string()))?;
        let data = self
            .buffer
            .slice(..)
            .get_mapped_range()
            .map_err(|e| GpuError::Readback(format!("{e:?}")))?;
        let out = read(&data);
        drop(data);
        self.buffer.unmap();
        Ok(out)
    }
}

/// Starts reading back an RGBA8 texture made with COPY_SRC (the viewer's picture, for its
/// certified pixels' verdicts) without waiting: poll the result until it is there.
pub fn start_texture_read(gpu: &Gpu, texture: &wgpu::Texture) -> PendingRgba {
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    let frame = FrameCopy::record(gpu, &mut encoder, texture);
    gpu.queue.submit([encoder.finish()]);
    PendingRgba::map(frame, None)
}

/// A frame copied into a mappable buffer, its rows padded to the copy alignment.
pub(super) struct FrameCopy {
    readback: wgpu::Buffer,
    width: u32,
    height: u32,
    padded_row: u32,
}

impl FrameCopy {
    /// Records the copy of all of `texture` (RGBA8, COPY_SRC) into a new mappable buffer.
    pub(super) fn record(
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
    ) -> Self {
        let (width, height) = (texture.width(), texture.height());
        let padded_row = (width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fourfold readback"),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(height),
                },
            },
            texture.size(),
        );
        Self {
            readback,
            width,
            height,
            padded_row,
        }
    }
}

/// A frame's pixels (tightly packed RGBA8 rows) and the GPU's milliseconds for its pass.
pub type TimedRgba = (Vec<u8>, Option<f64>);

/// A frame on its way back from the GPU (see [`RayCaster::start_rgba`](super::RayCaster::start_rgba)),
/// with the GPU's time for its pass where it was timed.
pub struct PendingRgba {
    width: u32,
    height: u32,
    padded_row: u32,
    pixels: Mapping,
    timer: Option<Mapping>,
}

impl PendingRgba {
    /// Starts mapping the copied frame (and the resolved timestamps, if any).
    pub(super) fn map(frame: FrameCopy, timer: Option<wgpu::Buffer>) -> Self {
        Self {
            width: frame.width,
            height: frame.height,
            padded_row: frame.padded_row,
            pixels: Mapping::start(frame.readback),
            timer: timer.map(Mapping::start),
        }
    }

    /// The frame's width and height.
    pub fn size(&self) -> [u32; 2] {
        [self.width, self.height]
    }

    /// Whether everything is back (the device must be polled natively for it to be).
    pub fn ready(&self) -> bool {
        self.pixels.ready() && self.timer.as_ref().is_none_or(Mapping::ready)
    }

    /// The pixels (tightly packed RGBA8 rows) once the GPU has written them, else None.
    pub fn poll(&self, gpu: &Gpu) -> Option<Result<Vec<u8>, GpuError>> {
        self.poll_timed(gpu).map(|r| r.map(|(rgba, _)| rgba))
    }

    /// As [`PendingRgba::poll`], with the milliseconds of the frame's pass by the GPU's
    /// timestamps (None where it was not timed, or the stamps are out of order).
    pub fn poll_timed(&self, gpu: &Gpu) -> Option<Result<TimedRgba, GpuError>> {
        // (Natively this lets wgpu call the map callbacks; in a browser the page's event
        // loop does.)
        let _ = gpu.device.poll(wgpu::PollType::Poll);
        if !self.ready() {
            return None;
        }
        let (row, padded) = ((self.width * 4) as usize, self.padded_row as usize);
        let pixels = self.pixels.read(|data| {
            let mut pixels = Vec::with_capacity(row * self.height as usize);
            for y in 0..self.height as usize {
                pixels.extend_from_slice(&data[y * padded..][..row]);
            }
            pixels
        });
        let gpu_ms = match &self.timer {
            Some(timer) => timer.read(|data| {
                let stamps: [u64; 2] = bytemuck::pod_read_unaligned(data);
                let period_ns = f64::from(gpu.queue.get_timestamp_period());
                stamps[1]
                    .checked_sub(stamps[0])
                    .map(|t| t as f64 * period_ns / 1e6)
            }),
            None => Ok(None),
        };
        Some(pixels.and_then(|p| Ok((p, gpu_ms?))))
    }
}

/// Two GPU timestamps (a pass's start and end) and the buffers that bring them back.
pub(super) struct Timer {
    pub(super) queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
}

impl Timer {
    const BYTES: u64 = 2 * wgpu::QUERY_SIZE as u64;

    pub(super) fn new(gpu: &Gpu) -> Self {
        let buffer = |usage| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("fourfold timestamps"),
                size: Self::BYTES,
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            queries: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("fourfold frame timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolved: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
        }
    }

    /// Records copying the timestamps to the mappable buffer (after the pass); the buffer
    /// to map once submitted.
    pub(super) fn resolve(self, encoder: &mut wgpu::CommandEncoder) -> wgpu::Buffer {
        encoder.resolve_query_set(&self.queries, 0..2, &self.resolved, 0);
        encoder.copy_buffer_to_buffer(&self.resolved, 0, &self.readback, 0, Self::BYTES);
        self.readback
    }
}
