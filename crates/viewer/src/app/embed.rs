//! The picture alone, for an iframe in a course page or slides (the page's `#embed&…`): no
//! editor, no panels; drag to turn, scroll to zoom, as in the full viewer; a small link
//! opens the scene in the full page, and a problem with the link is said over the picture.

use eframe::egui;
use egui::{Align2, Color32, RichText};

use super::FourfoldApp;
use crate::platform;

impl FourfoldApp {
    /// Draws the picture over the whole window; whether it is not complete yet.
    pub(crate) fn embedded_picture(&mut self, ui: &mut egui::Ui) -> bool {
        let mut more = false;
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| {
                more = self.picture(ui);
            });
        let open = format!(
            "{}#{}",
            platform::page_address(),
            self.session.link_fragment()
        );
        egui::Area::new(egui::Id::unique("fourfold embed link"))
            .anchor(Align2::RIGHT_BOTTOM, egui::vec2(-6.0, -4.0))
            .show(ui.ctx(), |ui| {
                let link = ui.add(
                    egui::Hyperlink::from_label_and_url(
                        RichText::new("open in fourfold ↗").small(),
                        open,
                    )
                    .open_in_new_tab(true),
                );
                self.embed_link_rect = Some(link.rect);
            });
        let problem = self.session.error.clone().or_else(|| {
            let notice = self.message.as_ref().filter(|m| m.is_error);
            notice.map(|m| m.text.clone())
        });
        if let Some(text) = problem {
            egui::Area::new(egui::Id::unique("fourfold embed problem"))
                .anchor(Align2::LEFT_TOP, egui::vec2(6.0, 4.0))
                .show(ui.ctx(), |ui| {
                    ui.set_max_width(ui.ctx().content_rect().width() - 12.0);
                    ui.label(
                        RichText::new(text)
                            .small()
                            .color(Color32::from_rgb(255, 180, 168)),
                    );
                });
        }
        more
    }

    /// An `<iframe>` that shows the scene on screen alone (the page's embed mode), for a
    /// course page or slides.
    pub fn embed_code(&self) -> String {
        let src = format!(
            "{}#embed&{}",
            platform::page_address(),
            self.session.link_fragment()
        );
        format!(
            "<iframe src=\"{}\" width=\"640\" height=\"480\" style=\"border:0\" \
             title=\"fourfold: {}\" loading=\"lazy\"></iframe>",
            escape(&src),
            escape(&self.session.scene.formula)
        )
    }
}

/// `text` as HTML attribute text.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    #[test]
    fn attribute_text_is_escaped() {
        assert_eq!(
            super::escape(r#"a<b & "c">"#),
            "a&lt;b &amp; &quot;c&quot;&gt;"
        );
    }
}
