//! Animations: a scene turning in one of R⁴'s rotation planes, sweeping a parameter or moving
//! a slice, as the scene and the rotation of each frame. (Drawing them and writing the file
//! is the `headless` module's.)

use std::f64::consts::TAU;

use crate::scene::Scene;
use crate::scene::limits::{FRAMES, MAX_FPS, fps_allowed};

use super::view::Rotation4;

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
    /// The slice's place at each frame, where they are not even (placed around the
    /// critical values: `critical::sweep::sweep_places`); empty for even steps.
    pub slice_places: Vec<f64>,
    pub frames: u32,
    /// Frames per second of the file written.
    pub fps: f64,
}

impl Animation {
    /// The view's rotation at frame k: a turn goes round without repeating its first frame
    /// at the end, so the animation loops smoothly.
    pub fn rotation(&self, scene: &Scene, k: u32) -> Rotation4 {
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
    pub fn scene_at(&self, scene: &Scene, k: u32) -> Scene {
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
            let place = self.slice_places.get(k as usize).copied();
            scene.view.slice = Some(place.unwrap_or(from + (to - from) * share));
            scene.view.slab = None;
        }
        scene
    }
}

/// What is wrong with an animation of `frames` frames, if anything: the allowed range.
pub fn frames_problem(frames: u32) -> Option<String> {
    (!FRAMES.contains(&frames)).then(|| format!("between {} and {}", FRAMES.start(), FRAMES.end()))
}

/// What is wrong with a file of `fps` frames per second, if anything.
pub fn fps_problem(fps: f64) -> Option<String> {
    (!fps_allowed(fps)).then(|| format!("above 0 and at most {MAX_FPS}"))
}
