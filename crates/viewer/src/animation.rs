//! The "Export animation" section's choices, which the desktop and the page share: what
//! moves (a turn, a parameter, a slice), how far, how many frames and how fast, and the
//! animation they make; and the row's button, or the export's progress and Cancel.

use eframe::egui;

use fourfold::render::animation::{
    Animation, Sweep, Turn, fps_problem, frames_problem, parse_range,
};
use fourfold::scene::limits::{FRAMES, MAX_FPS, TURNS};

use crate::settings::{AnimationChoice, Motion, TURN_PLANES};

/// What moves and how, for the formula's parameters `params`.
pub fn choices(ui: &mut egui::Ui, c: &mut AnimationChoice, params: &[String]) {
    ui.horizontal(|ui| {
        ui.radio_value(&mut c.motion, Motion::Turn, "turn");
        ui.radio_value(&mut c.motion, Motion::Sweep, "sweep a parameter")
            .on_hover_text("the tree is rebuilt for every frame");
        ui.radio_value(&mut c.motion, Motion::Slice, "move a slice")
            .on_hover_text("the cut by a hyperplane moving along the hidden n2");
    });
    if c.motion == Motion::Slice {
        ui.horizontal(|ui| {
            ui.label("slice from");
            ui.add(egui::DragValue::new(&mut c.slice_range.0).speed(0.02));
            ui.label("to");
            ui.add(egui::DragValue::new(&mut c.slice_range.1).speed(0.02));
        });
    } else if c.motion == Motion::Sweep {
        if !params.contains(&c.param) {
            c.param = params.first().cloned().unwrap_or_default();
        }
        ui.horizontal(|ui| {
            egui::ComboBox::from_id_salt("fourfold sweep parameter")
                .selected_text(if c.param.is_empty() {
                    "no parameter"
                } else {
                    &c.param
                })
                .show_ui(ui, |ui| {
                    for p in params {
                        ui.selectable_value(&mut c.param, p.clone(), p);
                    }
                });
            ui.label("from");
            ui.add(egui::DragValue::new(&mut c.range.0).speed(0.05));
            ui.label("to");
            ui.add(egui::DragValue::new(&mut c.range.1).speed(0.05));
        });
    } else {
        ui.horizontal(|ui| {
            egui::ComboBox::from_id_salt("fourfold turn plane")
                .selected_text(&c.plane)
                .show_ui(ui, |ui| {
                    for p in TURN_PLANES {
                        ui.selectable_value(&mut c.plane, p.to_string(), p);
                    }
                })
                .response
                .on_hover_text(
                    "xy … yw: the manifold turns in that plane of R⁴; θ1..θ6: one of the \
                     view's angles turns",
                );
            ui.add(
                egui::DragValue::new(&mut c.turns)
                    .speed(0.05)
                    .range(TURNS)
                    .suffix(" turns"),
            );
        });
    }
    ui.horizontal(|ui| {
        ui.add(
            egui::DragValue::new(&mut c.frames)
                .range(FRAMES)
                .suffix(" frames"),
        );
        ui.add(
            egui::DragValue::new(&mut c.fps)
                .range(f64::MIN_POSITIVE..=MAX_FPS)
                .suffix(" fps"),
        );
        ui.checkbox(&mut c.fit, "fit")
            .on_hover_text("frame the manifold in every frame");
    });
}

/// What the row's button asked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Asked {
    Nothing,
    Start,
    Cancel,
}

/// "Export animation", or while one runs (`running`: frames drawn, of all) its progress and
/// Cancel; what was asked, and where the button (Export animation, or Cancel) is.
pub fn start_or_progress(ui: &mut egui::Ui, running: Option<(u32, u32)>) -> (Asked, egui::Rect) {
    let (label, wanted) = match running {
        Some((done, all)) => {
            ui.add(
                egui::ProgressBar::new(done as f32 / all.max(1) as f32)
                    .desired_width(90.0)
                    .text(format!("{done}/{all}")),
            );
            ("Cancel", Asked::Cancel)
        }
        None => ("Export animation", Asked::Start),
    };
    let button = ui.button(label);
    let asked = if button.clicked() {
        wanted
    } else {
        Asked::Nothing
    };
    (asked, button.rect)
}

/// The animation "Export animation" is set to make, or why it cannot be made.
pub fn chosen_animation(c: &AnimationChoice) -> Result<Animation, String> {
    let (mut turn, mut sweep, mut slice_sweep) = (None, None, None);
    match c.motion {
        Motion::Turn => turn = Some(Turn::parse(&format!("{}:{}", c.plane, c.turns))?),
        Motion::Sweep => {
            let text = format!("{}={}..{}", c.param, c.range.0, c.range.1);
            sweep = Some(Sweep::parse(&text)?);
        }
        Motion::Slice => {
            let (a, b) = c.slice_range;
            slice_sweep = Some(parse_range(&format!("{a}..{b}"))?);
        }
    }
    if let Some(problem) = frames_problem(c.frames) {
        return Err(format!("frames {}: {problem}", c.frames));
    }
    if let Some(problem) = fps_problem(c.fps) {
        return Err(format!("fps {}: {problem}", c.fps));
    }
    Ok(Animation {
        turn,
        sweep,
        slice_sweep,
        slice_places: Vec::new(),
        frames: c.frames,
        fps: c.fps,
    })
}
