//! The view's controls: the six angles, zoom, the section (projection, slab or slice), fit,
//! reset and auto-rotation.

use std::f64::consts::PI;

use eframe::egui;
use egui::RichText;

use fourfold::scene::limits::ZOOM;

use super::FourfoldApp;

impl FourfoldApp {
    pub(crate) fn view_controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("View");
        let planes = ["xy", "yz", "zw", "xy", "yz", "xy"];
        for (k, (a, plane)) in self
            .session
            .scene
            .view
            .angles
            .iter_mut()
            .zip(planes)
            .enumerate()
        {
            ui.add(egui::Slider::new(a, -PI..=PI).text(format!("θ{} {plane}", k + 1)))
                .on_hover_text(format!(
                    "θ{}: a rotation in the {plane} plane, the {} of the six that turn R⁴ \
                     (A = Rxy(θ1) Ryz(θ2) Rzw(θ3) Rxy(θ4) Ryz(θ5) Rxy(θ6)). The screen shows \
                     the first two rows of A; the last two are the hidden directions.",
                    k + 1,
                    ["first", "second", "third", "fourth", "fifth", "sixth"][k]
                ));
        }
        let zoomed = ui
            .add(
                egui::Slider::new(&mut self.session.scene.view.zoom, ZOOM)
                    .logarithmic(true)
                    .text("zoom"),
            )
            .changed();
        if zoomed {
            self.fit_pending = false;
        }
        self.section_controls(ui);
        ui.horizontal(|ui| {
            if ui
                .button("Fit")
                .on_hover_text("zoom and centre on the manifold (key F)")
                .clicked()
            {
                self.fit();
            }
            if ui
                .button("Reset view")
                .on_hover_text("the angles at 0, the whole domain in view")
                .clicked()
            {
                self.session.scene.view = Default::default();
                self.fit_pending = false;
            }
            ui.checkbox(&mut self.ui.auto_rotate, "auto-rotate");
        });
        if self.ui.auto_rotate {
            ui.horizontal(|ui| {
                for (k, on) in self.ui.rotate_angles.iter_mut().enumerate() {
                    ui.checkbox(on, format!("θ{}", k + 1));
                }
            });
            ui.add(egui::Slider::new(&mut self.ui.rotate_speed, -2.0..=2.0).text("rad/s"));
        }
        ui.label(
            RichText::new(
                "drag: the screen against the hidden n1 · shift+drag: against n2 · \
                 ctrl+drag: spin in the screen · alt+drag or middle drag: pan · scroll: zoom · \
                 F: fit · Ctrl+Z: undo",
            )
            .small()
            .weak(),
        );
    }

    /// What each pixel searches: its whole observer plane (the projection), a band of it
    /// along n2 (a slab), or one line along n1 (a slice, the cut by a hyperplane), with
    /// the band's middle and half width or the slice's place.
    pub(crate) fn section_controls(&mut self, ui: &mut egui::Ui) {
        let reach = self.session.scene.domain.half_diagonal();
        let view = &mut self.session.scene.view;
        let current = match (view.slice, view.slab) {
            (Some(_), _) => 2,
            (None, Some(_)) => 1,
            (None, None) => 0,
        };
        let mut chosen = current;
        ui.horizontal(|ui| {
            ui.radio_value(&mut chosen, 0, "projection")
                .on_hover_text("every point of M that projects onto the pixel");
            ui.radio_value(&mut chosen, 1, "slab").on_hover_text(
                "only the part of M whose coordinate along the hidden n2 lies in a band",
            );
            ui.radio_value(&mut chosen, 2, "slice").on_hover_text(
                "the cut of M by the hyperplane at a place along n2: a surface, seen along n1",
            );
        });
        if chosen != current {
            view.slab = (chosen == 1).then_some([0.0, 0.25 * reach]);
            view.slice = (chosen == 2).then_some(0.0);
        }
        if let Some([c, h]) = &mut view.slab {
            ui.add(egui::Slider::new(c, -reach..=reach).text("slab middle"));
            ui.add(
                egui::Slider::new(h, 0.0..=reach)
                    .logarithmic(true)
                    .text("slab half width"),
            );
        }
        if let Some(c) = &mut view.slice {
            ui.add(egui::Slider::new(c, -reach..=reach).text("slice at"))
                .on_hover_text("where the hyperplane cuts, along n2 from the domain's centre");
            self.critical_controls(ui, (-reach, reach));
            ui.checkbox(&mut self.ui.side_by_side, "beside the projection")
                .on_hover_text("the projection on the right, where the slice cuts in orange");
        }
    }

    /// Turns the chosen angles by the auto-rotation's speed over `dt_ms`.
    pub(crate) fn auto_rotate(&mut self, dt_ms: f64) {
        let step = self.ui.rotate_speed * dt_ms.min(100.0) / 1e3;
        let angles = self.session.scene.view.angles.iter_mut();
        for (a, on) in angles.zip(self.ui.rotate_angles) {
            if on {
                *a = (*a + step + PI).rem_euclid(2.0 * PI) - PI;
            }
        }
    }
}
