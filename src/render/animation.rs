//! Animations: a scene turning in one of R⁴'s rotation planes, or sweeping a parameter, drawn
//! frame after frame on one device, and written as an animated GIF, an animated PNG or a
//! folder of numbered PNGs. The tree is rebuilt only when a parameter changes.

use std::f64::consts::TAU;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use crate::formula::CompiledFormula;
use crate::scene::Scene;

use super::camera::{Camera, Rotation4};
use super::certify::{VerdictCounts, take_marks};
use super::codegen;
use super::framing;
use super::gpu::{Gpu, RayCaster};
use super::prepare::Prepared;
use super::uniforms::{FrameOptions, Uniforms};

/// The most frames an animation may have.
pub const MAX_FRAMES: u32 = 10_000;

/// What turns during an animation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Turn {
    /// One of the view's six angles θ1..θ6 (index 0..5) grows by `turns` full turns.
    Angle { index: usize, turns: f64 },
    /// The manifold turns by `turns` full turns in the plane of coordinate axes i < j.
    Plane { i: usize, j: usize, turns: f64 },
}

impl Turn {
    /// Parses `PLANE[:TURNS]`: a coordinate plane (xy, xz, xw, yz, yw, zw, either order) or
    /// one of the chapter's angles (θ1..θ6, also t1..t6), and how many full turns (1 if
    /// left out; negative turns the other way).
    pub fn parse(text: &str) -> Result<Self, String> {
        let (plane, turns) = match text.split_once(':') {
            Some((p, t)) => {
                let turns: f64 = t.trim().parse().map_err(|_| {
                    format!("'{t}' is not a number of turns (write PLANE:TURNS, as in xw:0.5)")
                })?;
                if !turns.is_finite() || turns == 0.0 {
                    return Err(format!("{turns} turns: a number of turns other than 0"));
                }
                (p.trim(), turns)
            }
            None => (text.trim(), 1.0),
        };
        let angle = plane
            .strip_prefix('θ')
            .or_else(|| plane.strip_prefix("theta"))
            .or_else(|| plane.strip_prefix('t'))
            .and_then(|k| k.parse::<usize>().ok())
            .filter(|k| (1..=6).contains(k));
        if let Some(k) = angle {
            return Ok(Turn::Angle {
                index: k - 1,
                turns,
            });
        }
        let axis = |c: char| "xyzw".find(c);
        let mut chars = plane.chars();
        match (
            chars.next().and_then(axis),
            chars.next().and_then(axis),
            chars.next(),
        ) {
            (Some(a), Some(b), None) if a != b => Ok(Turn::Plane {
                i: a.min(b),
                j: a.max(b),
                turns,
            }),
            _ => Err(format!(
                "unknown plane '{plane}': use xy, yz, zw, xz, xw or yw (the manifold turns in \
                 that plane), or θ1..θ6 (t1..t6: one of the view's angles)"
            )),
        }
    }
}

/// `A..B`: two different finite numbers.
pub fn parse_range(text: &str) -> Result<(f64, f64), String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("'{text}' is not a range: write A..B, as in -0.9..0.9"))?;
    let number = |v: &str| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{}' is not a finite number: write A..B", v.trim()))
    };
    let (from, to) = (number(a)?, number(b)?);
    if from == to {
        return Err(format!(
            "{from}..{to} is an empty range: give two different values"
        ));
    }
    Ok((from, to))
}

/// A parameter moving from one value to another over the animation.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    pub name: String,
    pub from: f64,
    pub to: f64,
}

impl Sweep {
    /// Parses `NAME=A..B`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let usage = "write NAME=A..B, as in R=1..2";
        let (name, range) = text
            .split_once('=')
            .ok_or_else(|| format!("'{text}': {usage}"))?;
        let (from, to) = parse_range(range).map_err(|e| format!("{name}={e}"))?;
        let name = name.trim();
        if name.is_empty() {
            return Err(format!("'{text}' names no parameter: {usage}"));
        }
        Ok(Self {
            name: name.to_string(),
            from,
            to,
        })
    }
}

/// The frames to draw.
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    pub turn: Option<Turn>,
    pub sweep: Option<Sweep>,
    /// A slice moving from one place along n2 to another.
    pub slice_sweep: Option<(f64, f64)>,
    pub frames: u32,
    /// Frames per second of the file written.
    pub fps: f64,
}

impl Animation {
    /// The view's rotation at frame k: a turn goes round without repeating its first frame
    /// at the end, so the animation loops smoothly.
    fn rotation(&self, scene: &Scene, k: u32) -> Rotation4 {
        let share = f64::from(k) / f64::from(self.frames.max(1));
        let mut angles = scene.view.angles;
        match self.turn {
            Some(Turn::Angle { index, turns }) => {
                angles[index] += TAU * turns * share;
                Rotation4::from_angles(angles)
            }
            Some(Turn::Plane { i, j, turns }) => {
                Rotation4::from_angles(angles).turned(i, j, TAU * turns * share)
            }
            None => Rotation4::from_angles(angles),
        }
    }

    /// The scene at frame k: a sweep's parameter, or the slice's place, runs from its
    /// first value at the first frame to its last at the last.
    fn scene_at(&self, scene: &Scene, k: u32) -> Scene {
        let mut scene = scene.clone();
        let share = if self.frames > 1 {
            f64::from(k) / f64::from(self.frames - 1)
        } else {
            0.0
        };
        if let Some(s) = &self.sweep {
            scene
                .params
                .insert(s.name.clone(), s.from + (s.to - s.from) * share);
        }
        if let Some((from, to)) = self.slice_sweep {
            scene.view.slice = Some(from + (to - from) * share);
            scene.view.slab = None;
        }
        scene
    }
}

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
        let delay_ms = (1000.0 / fps).round().clamp(1.0, 65_535.0) as u16;
        match self {
            Output::Gif(path) => {
                let file = create(path)?;
                let mut encoder = image::codecs::gif::GifEncoder::new_with_speed(file, 10);
                encoder
                    .set_repeat(image::codecs::gif::Repeat::Infinite)
                    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                Ok(FrameWriter::Gif {
                    encoder,
                    path: path.clone(),
                    width,
                    height,
                    delay_ms,
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
        encoder: image::codecs::gif::GifEncoder<BufWriter<File>>,
        path: PathBuf,
        width: u32,
        height: u32,
        delay_ms: u16,
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
                encoder,
                path,
                width,
                height,
                delay_ms,
                count,
            } => {
                let image = image::RgbaImage::from_raw(*width, *height, rgba)
                    .ok_or("internal error: a frame of the wrong size")?;
                let delay = image::Delay::from_numer_denom_ms(u32::from(*delay_ms), 1);
                encoder
                    .encode_frame(image::Frame::from_parts(image, 0, 0, delay))
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
                encoder,
                path,
                count,
                ..
            } => {
                // Dropping the encoder writes the GIF's trailer.
                drop(encoder);
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

/// Where frames are drawn.
pub enum FrameDevice<'a> {
    Gpu(&'a Gpu),
    /// The CPU reference renderer.
    Cpu,
}

/// What `draw` drew.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Drawn {
    pub frames: u32,
    /// With `[render] certified`: the verdicts of every frame's pixels, summed.
    pub verdicts: Option<VerdictCounts>,
    /// Pixels, summed over the frames, whose work the GPU driver cut short.
    pub cut: usize,
}

/// Draws the animation's frames of `scene` at `width`×`height` one after the other, handing
/// each to `frame` (its index and RGBA8 rows); stops early, with the frames drawn so far,
/// once `stop` is set. With `fit`, one zoom and pan frames the manifold in every frame (of
/// the first frame's tree).
#[allow(clippy::too_many_arguments)]
pub fn draw(
    scene: &Scene,
    formula: &CompiledFormula,
    animation: &Animation,
    width: u32,
    height: u32,
    fit: bool,
    device: FrameDevice<'_>,
    stop: &AtomicBool,
    mut frame: impl FnMut(u32, Vec<u8>) -> Result<(), String>,
) -> Result<Drawn, String> {
    let mut scene = scene.clone();
    let mut prepared =
        Prepared::new(formula, &animation.scene_at(&scene, 0)).map_err(|e| e.to_string())?;
    if fit {
        let rotations: Vec<Rotation4> = (0..animation.frames)
            .map(|k| animation.rotation(&scene, k))
            .collect();
        if let Some(view) = framing::fit_through(
            &prepared.hierarchy,
            &scene.domain,
            &scene.view,
            &rotations,
            width,
            height,
        ) {
            scene.view.zoom = view.zoom;
            scene.view.pan = view.pan;
        }
    }
    let mut caster = match device {
        FrameDevice::Gpu(gpu) => {
            let shader = codegen::generate(formula).map_err(|e| e.to_string())?;
            Some((
                gpu,
                RayCaster::new(gpu, &shader, &prepared.hierarchy).map_err(|e| e.to_string())?,
            ))
        }
        FrameDevice::Cpu => None,
    };
    let mut drawn = Drawn {
        verdicts: scene.render.certified.then(VerdictCounts::default),
        ..Drawn::default()
    };
    for k in 0..animation.frames {
        if stop.load(Ordering::Relaxed) {
            return Ok(drawn);
        }
        let at = animation.scene_at(&scene, k);
        if k > 0 && at.params != animation.scene_at(&scene, k - 1).params {
            prepared = Prepared::new(formula, &at).map_err(|e| e.to_string())?;
            if let Some((gpu, caster)) = &mut caster {
                caster
                    .set_hierarchy(gpu, &prepared.hierarchy)
                    .map_err(|e| e.to_string())?;
            }
        }
        let camera = Camera::with_rotation(
            &at.domain,
            &at.view,
            animation.rotation(&at, k),
            width,
            height,
        );
        let uniforms = Uniforms::new(
            &camera,
            &at.render,
            &at.domain,
            &prepared.hierarchy,
            &prepared.params,
            FrameOptions::default(),
        );
        let mut rgba = match &mut caster {
            Some((gpu, caster)) => {
                let certifying = uniforms.certified().then(|| prepared.certifying());
                let hierarchy = &prepared.hierarchy;
                super::pipeline::bin_view(gpu, caster, hierarchy, certifying, &camera, &uniforms);
                caster
                    .render_rgba(gpu, &uniforms)
                    .map_err(|e| e.to_string())?
            }
            None => super::cpu::render_rgba(
                formula,
                &prepared.params,
                &prepared.hierarchy,
                uniforms.certified().then(|| prepared.certifying()),
                &uniforms,
            ),
        };
        let (cut, verdicts) = take_marks(&mut rgba);
        drawn.cut += cut.len();
        if let Some(total) = &mut drawn.verdicts {
            *total += VerdictCounts::of(&verdicts);
        }
        frame(k, rgba)?;
        drawn.frames = k + 1;
    }
    Ok(drawn)
}
