//! Under the slice slider: a tick at each place where the slice can change its topology
//! (the sweep's critical values), coloured by what happens there, with a hover that says
//! it; a click on a tick, or the buttons beside, moves the slice there.

use eframe::egui;
use egui::{Color32, RichText, Sense, Stroke, style::HandleShape, vec2};

use fourfold::critical::{CriticalPoint, CriticalReport, Place, Status};

use super::FourfoldApp;

/// A tick's colour: by Morse index where proved, grey where degenerate, magenta where
/// undecided.
fn colour(p: &CriticalPoint) -> Color32 {
    match (p.status, p.index) {
        (Status::Proved, Some(0)) => Color32::from_rgb(80, 200, 120),
        (Status::Proved, Some(1)) => Color32::from_rgb(240, 170, 60),
        (Status::Proved, Some(2)) => Color32::from_rgb(90, 170, 240),
        (Status::Proved, Some(3)) => Color32::from_rgb(230, 80, 80),
        (Status::Proved, _) => Color32::WHITE,
        (Status::Degenerate, _) => Color32::GRAY,
        (Status::Undecided, _) => Color32::from_rgb(210, 90, 210),
    }
}

/// What a tick's hover says.
pub fn describe(p: &CriticalPoint) -> String {
    let index = p.index.map_or(String::new(), |i| format!(", index {i}"));
    let place = match p.place {
        Place::Interior => String::new(),
        Place::Boundary { .. } => format!(" on the domain's boundary, {}", p.place.describe()),
    };
    format!(
        "c = {:.6} ± {:.1e}: {} ({}{index}){place}",
        p.value.midpoint(),
        0.5 * p.value.width(),
        p.meaning(),
        p.status.name()
    )
}

impl FourfoldApp {
    /// The ticks and the jump buttons for the slice at `range` of the slider above.
    pub(crate) fn critical_controls(&mut self, ui: &mut egui::Ui, range: (f64, f64)) {
        let (Some(program), Some(c)) = (&self.session.program, self.session.scene.view.slice)
        else {
            return;
        };
        let mut jump = None;
        match self.critical.report(&program.formula, &self.session.scene) {
            None => {
                ui.label(
                    RichText::new("finding where the slice changes shape…")
                        .small()
                        .weak(),
                );
            }
            Some(Err(e)) => {
                ui.label(RichText::new(e).small().weak());
            }
            Some(Ok(report)) => {
                let (strip, clicked) = ticks(ui, range, report);
                self.critical_strip_rect = Some(strip);
                jump = clicked;
                ui.horizontal(|ui| {
                    let before = report.next_before(c);
                    let after = report.next_after(c);
                    for (label, target) in [("« previous change", before), ("next change »", after)]
                    {
                        let button = ui.add_enabled(target.is_some(), egui::Button::new(label));
                        let button = match target {
                            Some(p) => button.on_hover_text(describe(p)),
                            None => button.on_disabled_hover_text("no critical value that way"),
                        };
                        if button.clicked() {
                            jump = target.map(|p| p.value.midpoint());
                        }
                    }
                    ui.label(RichText::new(summary(report)).small().weak());
                });
            }
        }
        if let Some(v) = jump {
            self.session.scene.view.slice = Some(v.clamp(range.0, range.1));
        }
    }
}

fn summary(report: &CriticalReport) -> String {
    let count = |s: Status| report.points.iter().filter(|p| p.status == s).count();
    let (proved, degenerate, undecided) = (
        count(Status::Proved),
        count(Status::Degenerate),
        count(Status::Undecided),
    );
    let mut text = format!("{proved} proved");
    if degenerate > 0 {
        text.push_str(&format!(", {degenerate} degenerate"));
    }
    if undecided > 0 {
        text.push_str(&format!(", {undecided} undecided"));
    }
    if report.budget_spent {
        text.push_str(" (search cut short)");
    }
    text
}

/// Draws the ticks under a slider of the ui's width over `range`: where, and the value of
/// a clicked tick.
fn ticks(
    ui: &mut egui::Ui,
    (lo, hi): (f64, f64),
    report: &CriticalReport,
) -> (egui::Rect, Option<f64>) {
    let width = ui.spacing().slider_width;
    // Where the slider's handle centre runs: its rail less a handle's half width at each
    // end (egui's SliderGeometry::position_range).
    let thickness = ui
        .text_style_height(&egui::TextStyle::Body)
        .max(ui.spacing().interact_size.y);
    let radius = thickness / 2.5
        * match ui.visuals().handle_shape {
            HandleShape::Circle => 1.0,
            HandleShape::Rect { aspect_ratio } => aspect_ratio,
        };
    let (row, response) = ui.allocate_exact_size(vec2(width, 12.0), Sense::click());
    let (x0, x1) = (row.left() + radius, row.left() + width - radius);
    let x_of = |v: f64| x0 + (x1 - x0) * ((v - lo) / (hi - lo)).clamp(0.0, 1.0) as f32;
    let painter = ui.painter_at(row);
    painter.hline(
        x0..=x1,
        row.center().y,
        Stroke::new(1.0, ui.visuals().weak_text_color()),
    );
    let mut nearest: Option<(f32, &CriticalPoint)> = None;
    let pointer = response.hover_pos();
    for p in &report.points {
        if p.value.hi() < lo || p.value.lo() > hi {
            continue;
        }
        let (a, b) = (x_of(p.value.lo()), x_of(p.value.hi()));
        let top = match p.place {
            Place::Interior => row.top(),
            Place::Boundary { .. } => row.center().y,
        };
        let tick = egui::Rect::from_min_max(
            egui::pos2(a - 1.5, top),
            egui::pos2(b.max(a) + 1.5, row.bottom()),
        );
        painter.rect_filled(tick, 0.0, colour(p));
        if let Some(pos) = pointer {
            let d = (pos.x - tick.center().x).abs() - 0.5 * tick.width();
            if d < 5.0 && nearest.is_none_or(|(e, _)| d < e) {
                nearest = Some((d, p));
            }
        }
    }
    match nearest {
        Some((_, p)) => {
            let clicked = response.clicked();
            response
                .on_hover_text_at_pointer(format!("{}\nclick: move the slice here", describe(p)));
            (row, clicked.then(|| p.value.midpoint()))
        }
        None => {
            response.on_hover_text(
                "where the slice can change its shape, proved: green, a piece is born; \
                 orange, pieces join or a tunnel opens; blue, a tunnel closes or a piece \
                 splits; red, a piece vanishes; grey, degenerate; magenta, undecided. Short \
                 ticks are on the domain's boundary. Between two ticks the slice keeps its \
                 topology.",
            );
            (row, None)
        }
    }
}
