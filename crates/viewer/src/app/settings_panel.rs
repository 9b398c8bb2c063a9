//! The folded settings: the domain and the tree's levels (a change rebuilds the tree), and how
//! the picture is drawn (rays, hits, sampling, colour, certified pixels, lighting,
//! highlights).

use eframe::egui;
use egui::RichText;

use fourfold::scene::limits::{
    CERT_BUDGET, DOMAIN_BOUND, HITS, NODE_BUDGET, RAYS, STEPS, TOLERANCE, TREE_LEVELS, UNIT,
};
use fourfold::scene::{AxisRange, Color, ColorBy, Sampling, Undecided};

use super::FourfoldApp;
use crate::notice::Notice;

impl FourfoldApp {
    /// Domain and tree settings; true when the tree must be rebuilt.
    pub(crate) fn tree_controls(&mut self, ui: &mut egui::Ui) -> bool {
        let mut changed = false;
        ui.label(RichText::new("Domain").strong());
        let scene = &mut self.session.scene;
        let mut axes = scene.domain.axes();
        for (axis, name) in axes.iter_mut().zip(["x", "y", "z", "w"]) {
            ui.horizontal(|ui| {
                ui.label(name);
                let (mut lo, mut hi) = (axis.lo, axis.hi);
                let a = ui.add(
                    egui::DragValue::new(&mut lo)
                        .speed(0.05)
                        .range(-DOMAIN_BOUND..=DOMAIN_BOUND),
                );
                let b = ui.add(
                    egui::DragValue::new(&mut hi)
                        .speed(0.05)
                        .range(-DOMAIN_BOUND..=DOMAIN_BOUND),
                );
                if a.changed() || b.changed() {
                    match AxisRange::new(lo, hi) {
                        Ok(r) => {
                            *axis = r;
                            changed = true;
                        }
                        Err(e) => {
                            self.message = Some(Notice::error(format!("domain {name}: {e}")));
                        }
                    }
                }
            });
        }
        scene.domain = fourfold::scene::Domain::from_axes(axes);
        ui.label(RichText::new("Tree").strong());
        let t = &mut scene.tree;
        changed |= ui
            .add(egui::Slider::new(&mut t.max_level, TREE_LEVELS).text("max level"))
            .changed();
        changed |= ui
            .add(egui::Slider::new(&mut t.min_level, TREE_LEVELS).text("min level"))
            .changed();
        if t.min_level > t.max_level {
            t.min_level = t.max_level;
        }
        changed |= ui
            .add(
                egui::Slider::new(&mut t.node_budget, NODE_BUDGET)
                    .logarithmic(true)
                    .text("node budget"),
            )
            .changed();
        changed
    }

    pub(crate) fn render_controls(&mut self, ui: &mut egui::Ui) {
        let r = &mut self.session.scene.render;
        ui.add(
            egui::Slider::new(&mut r.rays, RAYS)
                .logarithmic(true)
                .text("rays"),
        );
        ui.add(egui::Slider::new(&mut r.hits, HITS).text("hits kept"));
        ui.add(egui::Slider::new(&mut r.alpha, UNIT).text("α"));
        ui.add(egui::Slider::new(&mut r.steps, STEPS).text("steps per leaf"));
        ui.horizontal(|ui| {
            ui.label("sampling");
            ui.radio_value(&mut r.sampling, Sampling::Stratified, "stratified");
            ui.radio_value(&mut r.sampling, Sampling::Random, "random");
        });
        ui.horizontal(|ui| {
            ui.label("colour by");
            ui.radio_value(&mut r.color_by, ColorBy::Surface, "surface");
            ui.radio_value(&mut r.color_by, ColorBy::Hidden, "hidden n2")
                .on_hover_text(
                    "each hit's place along the hidden direction n2, from dark blue to yellow \
                     (the legend gives the values)",
                );
        });
        // Applied when a pipeline warmed up for it is ready (see Session::set_brute_force).
        let mut brute = self.session.pending_brute_force.unwrap_or(r.brute_force);
        let toggled = ui
            .checkbox(&mut brute, "brute force (march the whole domain)")
            .on_hover_text(
                "March every ray across the domain with the finest leaves' step instead of \
                 the tree's boxes: the same picture, faster on some scenes and shallow trees",
            )
            .changed();
        ui.checkbox(&mut r.certified, "certified pixels")
            .on_hover_text(
                "Prove each pixel: hit (F changes sign on its observer plane), empty (F has no \
                 zero there), or undecided once the budget of cells is spent, drawn magenta \
                 where no ray found a hit. The counts are under the picture.",
            );
        if r.certified {
            ui.horizontal(|ui| {
                ui.label("cells per pixel");
                ui.add(egui::DragValue::new(&mut r.cert_budget).range(CERT_BUDGET));
                ui.radio_value(&mut r.undecided, Undecided::Marker, "magenta");
                ui.radio_value(&mut r.undecided, Undecided::Hatch, "hatched");
            });
        }
        ui.horizontal(|ui| {
            ui.label("background");
            color_edit(ui, &mut r.background);
        });
        ui.checkbox(&mut r.lighting.enabled, "lighting (4D Phong)");
        if r.lighting.enabled {
            ui.horizontal(|ui| {
                ui.label("light (v1 v2 n1 n2)");
                for c in r.lighting.direction.iter_mut() {
                    ui.add(egui::DragValue::new(c).speed(0.02));
                }
            });
            if r.lighting.direction.iter().all(|c| *c == 0.0) {
                r.lighting.direction[0] = 1.0;
            }
            ui.horizontal(|ui| {
                ui.label("surface");
                color_edit(ui, &mut r.lighting.color);
            });
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut r.silhouette.enabled, "silhouette");
            ui.add(
                egui::DragValue::new(&mut r.silhouette.tolerance)
                    .speed(0.005)
                    .range(TOLERANCE),
            );
            color_edit(ui, &mut r.silhouette.color);
        });
        ui.horizontal(|ui| {
            ui.checkbox(&mut r.border.enabled, "border");
            ui.add(
                egui::DragValue::new(&mut r.border.tolerance)
                    .speed(0.002)
                    .range(TOLERANCE),
            );
            color_edit(ui, &mut r.border.color);
        });
        if toggled {
            self.session.set_brute_force(brute, self.gpu.as_ref());
        }
        if let Some(gpu) = self.gpu.as_ref().filter(|_| crate::platform::INTERPRETS) {
            let mut on = self.session.interprets_new_formulas(gpu);
            let changed = ui
                .checkbox(&mut on, "interpreted first frames")
                .on_hover_text(
                    "Draw a new formula at once with a shader that interprets any formula, \
                     while its own shader compiles (about half a second on a GPU); its own \
                     takes over, and certifies the picture. On by default on a GPU; off on a \
                     CPU's software adapter, where the interpreter draws 24-52 times slower.",
                )
                .changed();
            if changed {
                self.session.interpret_new_formulas(on);
                self.ui.interpret = Some(on);
            }
        }
    }
}

fn color_edit(ui: &mut egui::Ui, c: &mut Color) {
    let mut rgb = c.0;
    if ui.color_edit_button_srgb(&mut rgb).changed() {
        c.0 = rgb;
    }
}
