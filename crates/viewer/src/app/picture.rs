//! The picture: what the ray casters have drawn, painted over the central panel (beside a
//! slice, the projection with the slice's place), turned and zoomed by the mouse, with its
//! legend and build state; and each frame's share of ray casting.

use std::sync::Arc;

use eframe::{egui, egui_wgpu};
use egui::Color32;
use web_time::Instant;

use fourfold::render::Shader;
use fourfold::render::twin::viridis;
use fourfold::render::view::{rotate_view, scene_hidden_range};
use fourfold::scene::limits::ZOOM;
use fourfold::scene::{ColorBy, Scene};

use super::FourfoldApp;
use super::inset::{InsetBuild, InsetCaster};
use crate::job::CasterPlan;
use crate::notice::Notice;
use crate::platform;
use crate::progressive::{Progressive, Subject};

/// Ray casting for the projection beside a slice gets at least this much of a UI frame.
const RAY_FLOOR_MS: f64 = 2.0;

/// The largest side of the picture in the window, in pixels.
const MAX_WINDOW_PICTURE: u32 = 4096;

impl FourfoldApp {
    /// The picture: turns and zooms it by the mouse, draws what the ray caster has made,
    /// and lets it make more; true while more frames are wanted.
    pub(crate) fn picture(&mut self, ui: &mut egui::Ui) -> bool {
        let rect = ui.available_rect_before_wrap();
        self.picture_rect = Some(rect);
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        if self.turn_and_zoom(ui, &response) {
            self.pacing.interacted();
        }
        self.keep_inset_caster();
        // Side by side: the slice on the left, the projection with the slice's place on
        // the right.
        let (main, inset) = if self.side_by_side() {
            let (left, right) = rect.split_left_right_at_fraction(0.5);
            (
                left.shrink2(egui::vec2(2.0, 0.0)),
                Some(right.shrink2(egui::vec2(2.0, 0.0))),
            )
        } else {
            (rect, None)
        };
        let painter = ui.painter_at(rect);
        paint_layers(&self.progressive, &self.session.scene, &painter, main);
        if let Some(inset) = inset {
            paint_layers(&self.inset, &self.session.scene, &painter, inset);
            let c = self.session.scene.view.slice.unwrap_or(0.0);
            let font = egui::FontId::proportional(13.0);
            let label = |at: egui::Rect, text: String| {
                painter.text(
                    at.center_top() + egui::vec2(0.0, 8.0),
                    egui::Align2::CENTER_TOP,
                    text,
                    font.clone(),
                    Color32::LIGHT_GRAY,
                );
            };
            label(main, format!("slice at n2 = {c:.2}"));
            label(inset, "projection: the slice's place in orange".to_string());
        }
        self.paint_build_state(&painter, main);
        self.paint_legend(&painter, main);
        let ppp = ui.ctx().pixels_per_point();
        self.picture_size = pixels(main, ppp);
        let more = self.cast_rays(self.picture_size, inset.map(|r| pixels(r, ppp)));
        self.note_edit_latency();
        more || self.pacing.interacting()
    }

    /// Whether the slice is shown beside the projection.
    pub fn side_by_side(&self) -> bool {
        self.ui.side_by_side && self.session.scene.view.slice.is_some()
    }

    /// Keeps a second ray caster for the projection beside a slice: made for the session's
    /// shader off the window's frames (the projection waits for it), given each new
    /// hierarchy, dropped when not shown.
    pub(crate) fn keep_inset_caster(&mut self) {
        if !self.side_by_side() {
            self.inset_caster = None;
            self.inset_build = None;
            return;
        }
        let Some(shader) = self.session.program.as_ref().map(|p| p.shader.clone()) else {
            return;
        };
        self.take_inset_build(&shader);
        let (Some(gpu), Some(hierarchy)) = (&self.gpu, &self.session.hierarchy) else {
            return;
        };
        let generation = self.session.picture_generation;
        if let Some(inset) = &mut self.inset_caster
            && Arc::ptr_eq(&inset.shader, &shader)
        {
            if inset.generation != generation {
                match inset.caster.set_hierarchy(gpu, hierarchy) {
                    Ok(()) => inset.generation = generation,
                    Err(e) => {
                        self.message = Some(Notice::error(e.to_string()));
                        self.inset_caster = None;
                    }
                }
            }
            return;
        }
        // Another formula's caster draws no more; this one's is built, or being built.
        self.inset_caster = None;
        if self
            .inset_build
            .as_ref()
            .is_some_and(|b| Arc::ptr_eq(&b.shader, &shader))
        {
            return;
        }
        let projection = projection_beside(&self.session.scene);
        let plan = CasterPlan::new(shader.clone(), &projection, projection.render.brute_force);
        let (gpu, hierarchy) = (gpu.clone(), hierarchy.clone());
        let work = platform::Background::start("fourfold inset", move || {
            plan.build(&gpu, &hierarchy, platform::warm_up)
        });
        self.inset_build = Some(InsetBuild {
            shader,
            generation,
            work,
        });
    }

    /// Takes the inset caster built beside the window once it is there (and still for
    /// `shader`).
    fn take_inset_build(&mut self, shader: &Arc<Shader>) {
        let Some(build) = &mut self.inset_build else {
            return;
        };
        if !Arc::ptr_eq(&build.shader, shader) {
            self.inset_build = None;
            return;
        }
        let Some(done) = build.work.poll() else {
            return;
        };
        let (shader, generation) = (build.shader.clone(), build.generation);
        self.inset_build = None;
        match done {
            Some(Ok(caster)) => {
                self.inset_caster = Some(InsetCaster {
                    caster,
                    shader,
                    generation,
                });
            }
            Some(Err(e)) => self.message = Some(Notice::error(e)),
            None => self.message = Some(Notice::error("the projection's ray caster was lost")),
        }
    }

    /// Drag = rotate in the view's own planes; middle or alt drag = pan; scroll = zoom. True
    /// if the view changed.
    pub(crate) fn turn_and_zoom(&mut self, ui: &egui::Ui, response: &egui::Response) -> bool {
        let mut changed = false;
        let mods = ui.input(|i| i.modifiers);
        let d = response.drag_delta();
        let panning = response.dragged_by(egui::PointerButton::Middle)
            || (response.dragged_by(egui::PointerButton::Primary) && mods.alt);
        if panning {
            // World units per point: the camera's pixel size at this picture's size.
            let [w, h] = self.picture_size;
            let view = &mut self.session.scene.view;
            let shorter = f64::from(w.min(h).max(1));
            let per_point = 2.0 * self.session.scene.domain.half_diagonal() / shorter / view.zoom
                * f64::from(ui.ctx().pixels_per_point());
            view.pan[0] -= f64::from(d.x) * per_point;
            view.pan[1] += f64::from(d.y) * per_point;
            self.fit_pending = false;
            changed = true;
        } else if response.dragged_by(egui::PointerButton::Primary) {
            let k = 0.01;
            let angles = self.session.scene.view.angles;
            let angles = if mods.ctrl || mods.command {
                rotate_view(angles, 0, 1, f64::from(d.x) * k)
            } else {
                let n = if mods.shift { 3 } else { 2 };
                let a = rotate_view(angles, 0, n, f64::from(d.x) * k);
                rotate_view(a, 1, n, -f64::from(d.y) * k)
            };
            self.session.scene.view.angles = angles;
            changed = true;
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                let z = &mut self.session.scene.view.zoom;
                *z = (*z * (1.0 + f64::from(scroll) * 0.002)).clamp(*ZOOM.start(), *ZOOM.end());
                self.fit_pending = false;
                changed = true;
            }
        }
        changed
    }

    /// With colour by the hidden direction: the colour map and the n2 values its ends stand
    /// for, at the picture's bottom left.
    pub(crate) fn paint_legend(&self, painter: &egui::Painter, rect: egui::Rect) {
        let scene = &self.session.scene;
        let Some(hierarchy) = self
            .session
            .hierarchy
            .as_ref()
            .filter(|_| scene.render.color_by == ColorBy::Hidden)
        else {
            return;
        };
        let [lo, hi] = scene_hidden_range(hierarchy, scene);
        let (width, height) = (160.0, 12.0);
        let origin = rect.left_bottom() + egui::vec2(12.0, -34.0);
        let steps = 32;
        for k in 0..steps {
            let t = (k as f32 + 0.5) / steps as f32;
            let [r, g, b] = viridis(t).map(|c| (c * 255.0).round() as u8);
            let x = origin.x + width * k as f32 / steps as f32;
            painter.rect_filled(
                egui::Rect::from_min_size(
                    egui::pos2(x, origin.y),
                    egui::vec2(width / steps as f32 + 0.5, height),
                ),
                0.0,
                Color32::from_rgb(r, g, b),
            );
        }
        let font = egui::FontId::proportional(12.0);
        let below = origin + egui::vec2(0.0, height + 2.0);
        painter.text(
            below,
            egui::Align2::LEFT_TOP,
            format!("n2 = {lo:.2}"),
            font.clone(),
            Color32::LIGHT_GRAY,
        );
        painter.text(
            below + egui::vec2(width, 0.0),
            egui::Align2::RIGHT_TOP,
            format!("{hi:.2}"),
            font,
            Color32::LIGHT_GRAY,
        );
    }

    /// "building…" over the picture while a tree is built, or a word where there is nothing
    /// to see.
    pub(crate) fn paint_build_state(&self, painter: &egui::Painter, rect: egui::Rect) {
        if self.session.building() {
            let nodes = self.session.build_progress().unwrap_or(0);
            painter.text(
                rect.left_top() + egui::vec2(8.0, 8.0),
                egui::Align2::LEFT_TOP,
                format!("building… {nodes} nodes"),
                egui::FontId::proportional(14.0),
                Color32::from_rgb(255, 210, 90),
            );
        } else if self.session.stats.as_ref().is_some_and(|s| s.leaves == 0) {
            painter.text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "no surface in this domain",
                egui::FontId::proportional(18.0),
                Color32::from_rgb(255, 210, 90),
            );
        } else if let Some(note) =
            (self.session.stats.as_ref()).and_then(fourfold::render::verdict::touching_note)
        {
            // (Wrapped to the picture: the note is long.)
            let galley = painter.layout(
                note,
                egui::FontId::proportional(13.0),
                Color32::from_rgb(255, 210, 90),
                (rect.width() - 16.0).max(80.0),
            );
            painter.galley(
                rect.left_top() + egui::vec2(8.0, 8.0),
                galley,
                Color32::WHITE,
            );
        }
    }

    /// Lets the ray caster draw for this frame's budget; true while it has more to do.
    pub(crate) fn cast_rays(&mut self, size: [u32; 2], inset: Option<[u32; 2]>) -> bool {
        // A picture about to be replaced is not refined further: where the build runs in
        // the window's own frames (the web page), that would slow the build replacing it.
        if self.session.building()
            && self.progressive.first_frame_of == Some(self.session.picture_generation)
        {
            return false;
        }
        let interacting = self.pacing.interacting();
        let budget_ms = if platform::WAITS_FOR_GPU {
            self.pacing.ray_budget_ms()
        } else {
            self.pacing.gpu_run_ms()
        };
        let started = Instant::now();
        let mut more = false;
        // Whether every picture with more to draw waits for the GPU to wake the window.
        let mut waits = true;
        if let (Some(gpu), Some(renderer)) = (&self.gpu, &self.renderer) {
            let mut renderer = renderer.write();
            let s = &mut self.session;
            // (A pipeline the scene now needs is built beside the window: the picture on
            // screen stays until it is there.)
            let ready = s.ready_to_draw(Some(gpu));
            more |= !ready;
            let Some(hierarchy) = &s.hierarchy else {
                return false;
            };
            let certifier_pending = s.certified_pipeline_pending();
            let cpu_previewed = (s.program.as_ref())
                .filter(|_| s.previews_on_cpu)
                .map(|p| p.formula.as_ref());
            if let Some(caster) = s.caster.as_mut().filter(|_| ready) {
                let subject = Subject {
                    caster,
                    hierarchy,
                    certifying: s.certifying.as_ref(),
                    certifier_pending,
                    params: &s.tree_params,
                    formula: cpu_previewed,
                    scene: &s.scene,
                    generation: s.picture_generation,
                };
                more = self.progressive.step(
                    gpu,
                    &mut renderer,
                    subject,
                    size,
                    interacting,
                    budget_ms,
                );
                waits &= !more || self.progressive.waiting();
            }
            if let (Some(size), Some(inset)) = (inset, &mut self.inset_caster) {
                let scene = projection_beside(&s.scene);
                let subject = Subject {
                    caster: &mut inset.caster,
                    hierarchy,
                    certifying: s.certifying.as_ref(),
                    certifier_pending: false,
                    params: &s.tree_params,
                    formula: cpu_previewed,
                    scene: &scene,
                    generation: s.picture_generation,
                };
                let left = budget_ms - started.elapsed().as_secs_f64() * 1e3;
                let inset_more = self.inset.step(
                    gpu,
                    &mut renderer,
                    subject,
                    size,
                    interacting,
                    left.max(RAY_FLOOR_MS),
                );
                waits &= !inset_more || self.inset.waiting();
                more |= inset_more;
            }
        }
        if self.inset_build.is_some() {
            // Its caster is built on a thread, which wakes no one: look again next frame.
            more = true;
            waits = false;
        }
        self.picture_waits = more && waits;
        let took_ms = started.elapsed().as_secs_f64() * 1e3;
        self.pacing.rays_took(took_ms);
        if std::env::var_os("FOURFOLD_TRACE").is_some() {
            eprintln!(
                "ui frame {:.1} ms, ray casting {:.1} ms (budget {:.1}), throughput {:.0} rays/ms, \
                 last binning {:.0} ms, stage/square {:?}",
                self.pacing.ui_frame_ms,
                took_ms,
                budget_ms,
                self.progressive.throughput(),
                self.progressive.binner.binning_ms.unwrap_or(0.0),
                self.progressive.position()
            );
        }
        more
    }

    /// Once the first frame of an edit's picture is on screen: the edit's latency.
    pub(crate) fn note_edit_latency(&mut self) {
        if let Some(g) = self.progressive.first_frame_of
            && g != self.latency_generation
            && g == self.session.picture_generation
        {
            self.latency_generation = g;
            if let Some(t) = self.session.edit_started.take() {
                self.edit_latency_ms = Some(t.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
}

/// Paints the ray caster's textures over `rect` (the background until there are any).
fn paint_layers(
    progressive: &Progressive,
    scene: &Scene,
    painter: &egui::Painter,
    rect: egui::Rect,
) {
    let layers = progressive.paint().layers;
    if layers.is_empty() {
        painter.rect_filled(rect, 0.0, {
            let [r, g, b] = scene.render.background.0;
            Color32::from_rgb(r, g, b)
        });
    }
    for layer in layers {
        let Some(t) = progressive.texture(layer.texture) else {
            continue;
        };
        let [x, y, w, h] = layer.rect;
        let (tw, th) = (t.width as f32, t.height as f32);
        let uv = egui::Rect::from_min_max(
            egui::pos2(x as f32 / tw, y as f32 / th),
            egui::pos2((x + w) as f32 / tw, (y + h) as f32 / th),
        );
        let screen = egui::Rect::from_min_max(
            rect.min + egui::vec2(uv.min.x * rect.width(), uv.min.y * rect.height()),
            rect.min + egui::vec2(uv.max.x * rect.width(), uv.max.y * rect.height()),
        );
        match &t.blit {
            Some(bind_group) => {
                painter.add(egui_wgpu::Callback::new_paint_callback(
                    screen,
                    crate::blit::Layer {
                        bind_group: bind_group.clone(),
                        full: rect,
                    },
                ));
            }
            None => {
                painter.image(t.id, screen, uv, Color32::WHITE);
            }
        }
    }
}

/// The size in pixels of a picture filling `rect` at `ppp` pixels per point.
fn pixels(rect: egui::Rect, ppp: f32) -> [u32; 2] {
    [rect.width(), rect.height()]
        .map(|side| ((side * ppp).round() as u32).clamp(1, MAX_WINDOW_PICTURE))
}

/// The projection shown beside a slice: the whole observer plane, with the slice's place
/// marked.
fn projection_beside(scene: &Scene) -> Scene {
    let mut projection = scene.clone();
    projection.view.mark = projection.view.slice.take();
    projection
}
