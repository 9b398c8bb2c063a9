//! The formula editor: the text with the grammar's own colours and its error underlined, the
//! caret message under it, the language's reference, and a slider per parameter.

use eframe::egui;
use egui::{Color32, RichText, TextFormat, text::LayoutJob};

use fourfold::syntax::SourceError;
use fourfold::syntax::parser::{TokenKind, tokens};

use super::FourfoldApp;

impl FourfoldApp {
    /// The formula editor and its error; returns nothing, edits the session.
    pub(crate) fn formula_editor(&mut self, ui: &mut egui::Ui) {
        let label = ui.label("Formula  F(x, y, z, w)  or  lhs = rhs");
        let mut text = self.session.text.clone();
        let dark = ui.visuals().dark_mode;
        // The error's span is underlined while the text is the one it is about.
        let error_span = self.session.error_at.as_ref().map(|e| e.span.clone());
        let error_text = self.session.text.clone();
        let mut layouter = |ui: &egui::Ui, buf: &dyn egui::TextBuffer, wrap: f32| {
            let span = error_span.clone().filter(|_| buf.as_str() == error_text);
            let mut job = highlight(buf.as_str(), dark, span);
            job.wrap.max_width = wrap;
            ui.fonts_mut(|f| f.layout_job(job))
        };
        let response = ui.add(
            egui::TextEdit::multiline(&mut text)
                .id_salt("formula")
                .code_editor()
                .desired_rows(2)
                .desired_width(f32::INFINITY)
                .layouter(&mut layouter),
        );
        let response = response.labelled_by(label.id);
        self.editor_rect = Some(response.rect);
        if response.changed() && text != self.session.text {
            self.session.set_text(&text, self.gpu.as_ref());
        }
        match (&self.session.error_at, &self.session.error) {
            (Some(at), _) => caret_message(ui, at, &self.session.text),
            (None, Some(error)) => {
                ui.label(RichText::new(error).color(ERROR_COLOR));
            }
            (None, None) => {
                if let Some(p) = &self.session.program {
                    ui.label(
                        RichText::new(format!("F = {}", p.formula.f_text()))
                            .small()
                            .weak(),
                    );
                }
            }
        }
        egui::CollapsingHeader::new("Help: how to write F")
            .id_salt("fourfold formula help")
            .show(ui, |ui| {
                for line in FORMULA_HELP {
                    ui.label(RichText::new(*line).small());
                }
            });
    }

    pub(crate) fn parameter_sliders(&mut self, ui: &mut egui::Ui) -> bool {
        let names = self.session.param_names();
        if names.is_empty() {
            return false;
        }
        let mut changed = false;
        ui.heading("Parameters");
        for name in names {
            let value = self.session.scene.params.entry(name.clone()).or_insert(1.0);
            let range = self.ui.ranges.entry(name.clone()).or_insert_with(|| {
                let span = value.abs().max(1.0) * 2.0;
                (-span, span)
            });
            let (lo, hi) = *range;
            changed |= ui
                .add(
                    egui::Slider::new(value, lo.min(hi)..=hi.max(lo))
                        .clamping(egui::SliderClamping::Never)
                        .text(RichText::new(&name).monospace().strong()),
                )
                .changed();
            ui.horizontal(|ui| {
                ui.label("range");
                ui.add(egui::DragValue::new(&mut range.0).speed(0.1));
                ui.add(egui::DragValue::new(&mut range.1).speed(0.1));
                if range.0 >= range.1 {
                    range.1 = range.0 + 1.0;
                }
            });
            if !value.is_finite() {
                *value = 1.0;
            }
        }
        changed
    }
}

/// Syntax colouring from the grammar's own tokens, with the bytes `error` underlined.
pub fn highlight(text: &str, dark: bool, error: Option<std::ops::Range<usize>>) -> LayoutJob {
    let mut job = LayoutJob::default();
    let font = egui::FontId::monospace(14.0);
    let plain = if dark {
        Color32::from_gray(220)
    } else {
        Color32::from_gray(30)
    };
    let color = |k: TokenKind| match k {
        TokenKind::Number => Color32::from_rgb(120, 200, 255),
        TokenKind::Variable => Color32::from_rgb(255, 200, 90),
        TokenKind::Function => Color32::from_rgb(200, 140, 255),
        TokenKind::Constant => Color32::from_rgb(120, 230, 180),
        TokenKind::Parameter => Color32::from_rgb(130, 230, 110),
        TokenKind::Operator => Color32::from_gray(160),
        TokenKind::Bracket => Color32::from_gray(140),
    };
    // Pieces of the text with their colours, cut where the error's span starts and ends.
    let mut pieces: Vec<(std::ops::Range<usize>, Color32)> = Vec::new();
    let mut at = 0;
    for t in tokens(text) {
        if t.start < at
            || t.end > text.len()
            || !text.is_char_boundary(t.start)
            || !text.is_char_boundary(t.end)
        {
            continue;
        }
        if t.start > at {
            pieces.push((at..t.start, plain));
        }
        pieces.push((t.start..t.end, color(t.kind)));
        at = t.end;
    }
    if at < text.len() {
        pieces.push((at..text.len(), plain));
    }
    let error = error.filter(|e| {
        e.start < e.end && text.is_char_boundary(e.start) && text.is_char_boundary(e.end)
    });
    for (range, color) in pieces {
        let mut cuts = vec![range.start, range.end];
        if let Some(e) = &error {
            cuts.extend([e.start, e.end].into_iter().filter(|c| range.contains(c)));
        }
        cuts.sort_unstable();
        cuts.dedup();
        for pair in cuts.windows(2) {
            let mut format = TextFormat::simple(font.clone(), color);
            if error
                .as_ref()
                .is_some_and(|e| e.start <= pair[0] && pair[1] <= e.end)
            {
                format.underline = egui::Stroke::new(2.0, ERROR_COLOR);
            }
            job.append(&text[pair[0]..pair[1]], 0.0, format);
        }
    }
    job
}

/// The colour of error messages.
pub const ERROR_COLOR: Color32 = Color32::from_rgb(255, 110, 100);

/// The formula reference under the editor.
const FORMULA_HELP: &[&str] = &[
    "Variables x y z w; numbers 2, 2.5, 1e-3; constants pi, tau, e.",
    "Operators + - * / ^ (^ binds tighter than unary minus: -x^2 is -(x^2)); |x| is the absolute value.",
    "Multiply by writing side by side: 2x, xy, 3 sin(w), (x+1)(x-1), R(x + 1).",
    "lhs = rhs means F = lhs - rhs.",
    "Functions: sin cos tan asin acos atan sinh cosh tanh exp ln log sqrt cbrt abs sign step, min(a,b) max(a,b) pow(a,b) atan2(y,x).",
    "Any other name (R, r, a1) is a parameter with a slider below.",
];

/// A formula's error under the editor: the message, the part of the formula around the
/// problem cut to the panel's width with the caret under it, and the hint. Cut, not
/// scrolled, so the caret and its label are always in view.
fn caret_message(ui: &mut egui::Ui, error: &SourceError, text: &str) {
    let font = egui::FontId::monospace(13.0);
    let char_width = ui.fonts_mut(|f| f.glyph_width(&font, '0')).max(1.0);
    let columns = (ui.available_width() / char_width).floor() as usize;
    let window = error.caret_window(text, columns.saturating_sub(1));
    ui.label(RichText::new(format!("error: {}", error.message)).color(ERROR_COLOR));
    // The source and its carets are cut to the panel's width and must not wrap (the carets
    // would leave their place); the label on a line of its own wraps, so that a long one
    // does not widen the panel and shrink the picture.
    let line = |ui: &mut egui::Ui, text: &str, color: Option<Color32>, wrap| {
        let mut rich = RichText::new(text).font(font.clone());
        if let Some(c) = color {
            rich = rich.color(c);
        }
        ui.add(egui::Label::new(rich).wrap_mode(wrap));
    };
    ui.scope(|ui| {
        ui.spacing_mut().item_spacing.y = 0.0;
        line(ui, &window.source, None, egui::TextWrapMode::Extend);
        line(
            ui,
            &window.carets,
            Some(ERROR_COLOR),
            egui::TextWrapMode::Extend,
        );
        if let Some(label) = &window.label {
            line(ui, label, Some(ERROR_COLOR), egui::TextWrapMode::Wrap);
        }
    });
    if let Some(hint) = &error.hint {
        ui.label(RichText::new(format!("hint: {hint}")).small());
    }
}
