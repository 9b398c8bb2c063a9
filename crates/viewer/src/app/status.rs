//! The lines around the picture: the top bar (gallery, undo, presets, files, links), the
//! status line (adapter, tree, times), the notice line and the certified pixels' counts.

use eframe::egui;
use egui::{Color32, RichText};

use fourfold::scene::EXAMPLES;

use super::FourfoldApp;
use crate::notice::Notice;
use crate::outcome::Window;
use crate::platform;

impl FourfoldApp {
    pub(crate) fn top_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.label(RichText::new("fourfold").strong());
            let gallery = ui
                .selectable_label(self.gallery.open, "Gallery")
                .on_hover_text("every example scene, as pictures");
            self.gallery.button = Some(gallery.rect);
            if gallery.clicked() {
                self.gallery.open = !self.gallery.open;
            }
            let now = self.snapshot();
            if ui
                .add_enabled(self.history.can_undo(&now), egui::Button::new("Undo"))
                .on_hover_text("Ctrl+Z")
                .clicked()
            {
                self.undo();
            }
            if ui
                .add_enabled(self.history.can_redo(), egui::Button::new("Redo"))
                .on_hover_text("Ctrl+Shift+Z")
                .clicked()
            {
                self.redo();
            }
            let current = self.preset.unwrap_or("choose…");
            egui::ComboBox::from_label("Preset")
                .selected_text(current)
                .show_ui(ui, |ui| {
                    for (name, _) in EXAMPLES {
                        if ui
                            .selectable_label(self.preset == Some(name), *name)
                            .clicked()
                        {
                            self.load_preset(name);
                        }
                    }
                });
            let window = Window {
                session: &self.session,
                settings: &mut self.ui,
                gpu: self.gpu.as_ref(),
            };
            let outcome = platform::file_actions(&mut self.platform, ui, window);
            self.apply(outcome);
            if ui
                .button("Copy link")
                .on_hover_text("a link that opens this scene in the web page (fourfold view LINK opens it here)")
                .clicked()
            {
                ui.ctx().copy_text(self.share_link());
                self.message = Some(Notice::done("link copied"));
            }
            if platform::EMBEDS
                && ui
                    .button("Copy embed code")
                .on_hover_text(
                    "an <iframe> showing this picture alone (drag turns it) for a course page \
                     or slides",
                )
                .clicked()
            {
                ui.ctx().copy_text(self.embed_code());
                self.message = Some(Notice::done("embed code copied"));
            }
            if ui.button("Copy formula").clicked() {
                ui.ctx().copy_text(self.session.text.clone());
                self.message = Some(Notice::done("formula copied"));
            }
        });
        // The line stays when empty: the picture keeps its size (and what it shows) when an
        // edit clears the explanation.
        ui.label(RichText::new(&self.session.scene.description).italics());
    }

    /// The share link of the scene on screen: the page's address in the browser, a
    /// relative one on the desktop.
    pub fn share_link(&self) -> String {
        format!(
            "{}#{}",
            platform::page_address(),
            self.session.link_fragment()
        )
    }

    /// The certified pixels' counts, on a line of their own (the status line is cut to one
    /// line, and these must be seen whole), itself cut only in a window too narrow for it:
    /// a wrapped line would shrink the picture and start the certified pass again.
    pub(crate) fn certified_line(&self, ui: &mut egui::Ui) {
        let verdicts = self.progressive.verdicts;
        let text = match verdicts {
            Some(c) => format!(
                "certified: {} hit · {} empty · {} undecided",
                c.hit, c.empty, c.undecided
            ),
            None => "certifying pixels…".to_string(),
        };
        let undecided = verdicts.is_some_and(|c| c.undecided > 0);
        let color = if undecided {
            Color32::from_rgb(255, 120, 255)
        } else {
            ui.visuals().text_color()
        };
        let label = ui.add(egui::Label::new(RichText::new(text).small().color(color)).truncate());
        if undecided {
            let continuous = self.session.hierarchy.as_ref().is_none_or(|h| h.continuous);
            let touching = (self.session.stats.as_ref())
                .map_or(fourfold::tree::Touching::Nowhere, |s| s.touching());
            label.on_hover_text(format!(
                "Undecided pixels are marked in magenta where no ray found a hit; {}.",
                fourfold::render::verdict::undecided_advice(
                    continuous,
                    touching,
                    "budget (cells per pixel, under Rendering)"
                )
            ));
        }
    }

    /// Adapter, tree, frame times and pace on one line that never wraps (what does not fit
    /// is cut): its text changes as the picture refines, and a second line would shrink the
    /// picture and start it again (in a small window on a software GPU, seconds of certified
    /// frame at every change).
    pub(crate) fn status_line(&self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.style_mut().wrap_mode = Some(egui::TextWrapMode::Truncate);
            let adapter = self.gpu.as_ref().map_or("no GPU", |g| g.adapter.as_str());
            ui.label(RichText::new(adapter).small());
            ui.separator();
            ui.label(RichText::new(self.session.tree_summary()).small());
            ui.separator();
            let p = &self.progressive;
            let mut frame = String::new();
            if let Some(ms) = p.preview_ms {
                frame.push_str(&format!("preview {ms:.0} ms"));
                if p.preview_from_cpu {
                    frame.push_str(" on the CPU");
                }
            }
            if let Some(ms) = p.full_ms {
                frame.push_str(&format!(", full picture {:.2} s", ms / 1e3));
            }
            if !p.converged() {
                frame.push_str(&format!(" · refining {:.0}%", 100.0 * p.fraction()));
            }
            if self.session.interpreting() {
                frame.push_str(" · interpreted while its shader compiles");
            }
            ui.label(RichText::new(frame).small());
            ui.separator();
            ui.label(RichText::new(format!("UI {:.0} fps", self.pacing.fps())).small());
            if let Some(ms) = self.edit_latency_ms {
                ui.separator();
                ui.label(RichText::new(format!("edit to picture {ms:.0} ms")).small());
            }
        });
    }

    /// The last notice (what was done, or what went wrong) on a line of its own, kept when
    /// empty and cut to one line, so that the picture keeps its size as notices come and go.
    pub(crate) fn notice_line(&self, ui: &mut egui::Ui) {
        let Some(Notice { text, is_error }) = &self.message else {
            ui.label(RichText::new(" ").small());
            return;
        };
        let color = if *is_error {
            Color32::from_rgb(255, 110, 100)
        } else {
            Color32::LIGHT_GREEN
        };
        // (egui shows the whole text of a cut label on hover.)
        ui.add(egui::Label::new(RichText::new(text).small().color(color)).truncate());
    }
}
