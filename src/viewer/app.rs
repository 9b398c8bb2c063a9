//! The window: formula editor, sliders and settings on the left, the picture in the middle,
//! the status line at the bottom. Thin over [`Session`] (what is drawn) and [`Progressive`]
//! (how it reaches the screen).

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::time::Instant;

use eframe::{egui, egui_wgpu};
use egui::{Color32, RichText, TextFormat, text::LayoutJob};

use crate::render::camera::rotate_view;
use crate::render::{Gpu, MAX_PICTURE_SIDE};
use crate::scene::{
    AxisRange, Color, EXAMPLES, MAX_HITS, MAX_RAYS, MAX_STEPS, MAX_TREE_LEVEL, Sampling, Scene,
    Speaker,
};
use crate::syntax::parser::{TokenKind, tokens};

use super::files::{self, Notice, PngExport};
use super::pacing::Pacing;
use super::progressive::{Progressive, ViewKey};
use super::session::Session;

/// Storage keys (eframe persistence).
const KEY_SCENE: &str = "fourfold.scene";
const KEY_UI: &str = "fourfold.ui";

/// The largest side of the picture in the window, in pixels.
const MAX_WINDOW_PICTURE: u32 = 4096;

/// UI settings that survive a restart besides the scene.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct UiSettings {
    /// Slider range of each parameter.
    pub ranges: BTreeMap<String, (f64, f64)>,
    pub auto_rotate: bool,
    /// Which angles auto-rotation turns.
    pub rotate_angles: [bool; 6],
    /// Radians per second.
    pub rotate_speed: f64,
    pub scene_path: String,
    pub png_path: String,
    pub wgsl_path: String,
    pub export_size: [u32; 2],
}

impl Default for UiSettings {
    fn default() -> Self {
        Self {
            ranges: BTreeMap::new(),
            auto_rotate: false,
            rotate_angles: [false, false, true, false, false, false],
            rotate_speed: 0.3,
            scene_path: "scene.toml".into(),
            png_path: "fourfold.png".into(),
            wgsl_path: "fourfold.wgsl".into(),
            export_size: [1024, 1024],
        }
    }
}

/// The viewer application.
pub struct FourfoldApp {
    pub session: Session,
    pub progressive: Progressive,
    pub ui: UiSettings,
    gpu: Option<Gpu>,
    renderer: Option<std::sync::Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>>,
    /// A short message after an action ("saved …", or what went wrong).
    pub message: Option<Notice>,
    export: Option<PngExport>,
    pub pacing: Pacing,
    /// Edit latency of the last edit: text change to the first frame of its picture, ms.
    pub edit_latency_ms: Option<f64>,
    latency_generation: u64,
    /// The preset chosen last (for the explanation line).
    pub preset: Option<&'static str>,
}

impl FourfoldApp {
    /// Builds the app; `scene` (from the command line) wins over the stored one.
    pub fn new(cc: &eframe::CreationContext<'_>, scene: Option<Scene>) -> Self {
        let stored_scene = cc
            .storage
            .and_then(|s| eframe::get_value::<String>(s, KEY_SCENE))
            .and_then(|text| Scene::parse(&text, "stored scene").ok());
        let ui: UiSettings = cc
            .storage
            .and_then(|s| eframe::get_value(s, KEY_UI))
            .unwrap_or_default();
        let scene = scene.or(stored_scene).unwrap_or_else(default_scene);
        let (gpu, renderer) = match &cc.wgpu_render_state {
            Some(rs) => {
                let info = rs.adapter.get_info();
                if let Some(blit) = super::blit::Blit::new(&rs.device, rs.target_format) {
                    rs.renderer.write().callback_resources.insert(blit);
                }
                (
                    Some(Gpu::from_parts(
                        rs.device.clone(),
                        rs.queue.clone(),
                        format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type),
                    )),
                    Some(rs.renderer.clone()),
                )
            }
            None => (None, None),
        };
        let mut app = Self {
            session: Session::new(scene.clone()),
            progressive: Progressive::default(),
            ui,
            gpu,
            renderer,
            message: None,
            export: None,
            pacing: Pacing::default(),
            edit_latency_ms: None,
            latency_generation: 0,
            preset: None,
        };
        if app.gpu.is_none() {
            app.message = Some(Notice::error(
                "no GPU renderer: the viewer needs wgpu (on Linux without a GPU: apt-get install -y mesa-vulkan-drivers)",
            ));
        }
        app.session.load_scene(scene, app.gpu.as_ref());
        app
    }

    /// The GPU the viewer draws with.
    pub fn gpu(&self) -> Option<&Gpu> {
        self.gpu.as_ref()
    }

    /// Loads one of the embedded example scenes by name.
    pub fn load_preset(&mut self, name: &'static str) {
        if let Some((_, text)) = EXAMPLES.iter().find(|(n, _)| *n == name) {
            match Scene::parse(text, name) {
                Ok(scene) => {
                    self.session.load_scene(scene, self.gpu.as_ref());
                    self.preset = Some(name);
                }
                Err(e) => self.message = Some(Notice::error(e.to_string())),
            }
        }
    }

    fn poll_export(&mut self) {
        if let Some(notice) = self.export.as_ref().and_then(PngExport::poll) {
            self.message = Some(notice);
            self.export = None;
        }
    }

    fn export_png(&mut self) {
        let [w, h] = self.ui.export_size;
        let path = self.ui.png_path.clone();
        self.message = Some(Notice::done(format!("rendering {w}x{h} to {path}…")));
        self.export = Some(PngExport::start(self.session.scene.clone(), w, h, path));
    }

    fn open_scene(&mut self) {
        let path = self.ui.scene_path.clone();
        match files::open_scene(&path) {
            Ok(scene) => {
                self.session.load_scene(scene, self.gpu.as_ref());
                self.preset = None;
                self.message = Some(Notice::done(format!("opened {path}")));
            }
            Err(notice) => self.message = Some(notice),
        }
    }

    fn export_wgsl(&mut self) {
        let path = &self.ui.wgsl_path;
        self.message = Some(match &self.session.shader {
            Some(shader) => files::export_wgsl(&shader.source, path),
            None => Notice::error("no valid shader yet"),
        });
    }

    fn top_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.label(RichText::new("fourfold").strong());
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
            ui.separator();
            ui.add(egui::TextEdit::singleline(&mut self.ui.scene_path).desired_width(140.0))
                .on_hover_text("scene file path (TOML, as for the command line)");
            if ui.button("Open").clicked() {
                self.open_scene();
            }
            if ui.button("Save").clicked() {
                self.message = Some(files::save_scene(&self.session.scene, &self.ui.scene_path));
            }
            ui.separator();
            ui.add(egui::TextEdit::singleline(&mut self.ui.png_path).desired_width(120.0));
            ui.add(
                egui::DragValue::new(&mut self.ui.export_size[0])
                    .range(1..=MAX_PICTURE_SIDE)
                    .suffix(" w"),
            );
            ui.add(
                egui::DragValue::new(&mut self.ui.export_size[1])
                    .range(1..=MAX_PICTURE_SIDE)
                    .suffix(" h"),
            );
            if ui
                .add_enabled(self.export.is_none(), egui::Button::new("Export PNG"))
                .clicked()
            {
                self.export_png();
            }
            ui.separator();
            ui.add(egui::TextEdit::singleline(&mut self.ui.wgsl_path).desired_width(120.0));
            if ui.button("Export WGSL").clicked() {
                self.export_wgsl();
            }
            if ui.button("Copy formula").clicked() {
                ui.ctx().copy_text(self.session.text.clone());
                self.message = Some(Notice::done("formula copied"));
            }
        });
        let description = &self.session.scene.description;
        if !description.is_empty() {
            ui.label(RichText::new(description).italics());
        }
    }

    /// The formula editor and its error; returns nothing, edits the session.
    fn formula_editor(&mut self, ui: &mut egui::Ui) {
        let label = ui.label("Formula  F(x, y, z, w)  or  lhs = rhs");
        let mut text = self.session.text.clone();
        let dark = ui.visuals().dark_mode;
        let mut layouter = |ui: &egui::Ui, buf: &dyn egui::TextBuffer, wrap: f32| {
            let mut job = highlight(buf.as_str(), dark);
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
        if response.changed() && text != self.session.text {
            self.session.set_text(&text, self.gpu.as_ref());
        }
        if let Some(error) = &self.session.error {
            // Unwrapped (scrolled sideways where wider than the panel), so that the caret
            // and its label stay under the part of the formula they point at.
            egui::ScrollArea::horizontal()
                .id_salt("formula error")
                .show(ui, |ui| {
                    ui.add(
                        egui::Label::new(
                            RichText::new(error)
                                .monospace()
                                .color(Color32::from_rgb(255, 110, 100)),
                        )
                        .wrap_mode(egui::TextWrapMode::Extend),
                    );
                });
        } else if let Some(f) = &self.session.formula {
            ui.label(RichText::new(format!("F = {}", f.f_text())).small().weak());
        }
    }

    fn parameter_sliders(&mut self, ui: &mut egui::Ui) -> bool {
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

    fn view_controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("View");
        let names = ["θ1 xy", "θ2 yz", "θ3 zw", "θ4 xy", "θ5 yz", "θ6 xy"];
        for (a, name) in self.session.scene.view.angles.iter_mut().zip(names) {
            ui.add(egui::Slider::new(a, -PI..=PI).text(name));
        }
        ui.add(
            egui::Slider::new(&mut self.session.scene.view.zoom, 0.1..=20.0)
                .logarithmic(true)
                .text("zoom"),
        );
        ui.horizontal(|ui| {
            if ui.button("Reset view").clicked() {
                self.session.scene.view = Default::default();
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
            RichText::new("drag: v1/v2 against n1 · shift+drag: against n2 · ctrl+drag: spin in the view · scroll: zoom")
                .small()
                .weak(),
        );
    }

    /// Domain and tree settings; true when the tree must be rebuilt.
    fn tree_controls(&mut self, ui: &mut egui::Ui) -> bool {
        let mut changed = false;
        ui.label(RichText::new("Domain").strong());
        let scene = &mut self.session.scene;
        let mut axes = scene.domain.axes();
        for (axis, name) in axes.iter_mut().zip(["x", "y", "z", "w"]) {
            ui.horizontal(|ui| {
                ui.label(name);
                let (mut lo, mut hi) = (axis.lo, axis.hi);
                let a = ui.add(egui::DragValue::new(&mut lo).speed(0.05).range(-1e6..=1e6));
                let b = ui.add(egui::DragValue::new(&mut hi).speed(0.05).range(-1e6..=1e6));
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
        scene.domain = crate::scene::Domain::from_axes(axes);
        ui.label(RichText::new("Tree").strong());
        let t = &mut scene.tree;
        changed |= ui
            .add(egui::Slider::new(&mut t.max_level, 1..=MAX_TREE_LEVEL).text("max level"))
            .changed();
        changed |= ui
            .add(egui::Slider::new(&mut t.min_level, 0..=MAX_TREE_LEVEL).text("min level"))
            .changed();
        if t.min_level > t.max_level {
            t.min_level = t.max_level;
        }
        changed |= ui
            .add(
                egui::Slider::new(&mut t.node_budget, 16..=20_000_000)
                    .logarithmic(true)
                    .text("node budget"),
            )
            .changed();
        changed
    }

    fn render_controls(&mut self, ui: &mut egui::Ui) {
        let r = &mut self.session.scene.render;
        ui.add(
            egui::Slider::new(&mut r.rays, 1..=MAX_RAYS)
                .logarithmic(true)
                .text("rays"),
        );
        ui.add(egui::Slider::new(&mut r.hits, 1..=MAX_HITS).text("hits kept"));
        ui.add(egui::Slider::new(&mut r.alpha, 0.0..=1.0).text("α"));
        ui.add(egui::Slider::new(&mut r.steps, 1..=MAX_STEPS).text("steps per leaf"));
        ui.horizontal(|ui| {
            ui.label("sampling");
            ui.radio_value(&mut r.sampling, Sampling::Stratified, "stratified");
            ui.radio_value(&mut r.sampling, Sampling::Random, "random");
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
        ui.horizontal(|ui| {
            ui.label("background");
            color_edit(ui, &mut r.background);
        });
        ui.checkbox(&mut r.lighting.enabled, "lighting (4D Phong)");
        if r.lighting.enabled {
            ui.horizontal(|ui| {
                ui.label("light (v1 v2 n1 n2)");
                for c in r.lighting.direction.iter_mut() {
                    ui.add(egui::DragValue::new(c).speed(0.02).range(-10.0..=10.0));
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
                    .range(0.0..=1.0),
            );
            color_edit(ui, &mut r.silhouette.color);
        });
        ui.horizontal(|ui| {
            ui.checkbox(&mut r.border.enabled, "border");
            ui.add(
                egui::DragValue::new(&mut r.border.tolerance)
                    .speed(0.002)
                    .range(0.0..=1.0),
            );
            color_edit(ui, &mut r.border.color);
        });
        if toggled {
            self.session.set_brute_force(brute, self.gpu.as_ref());
        }
    }

    fn status_line(&self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            let adapter = self.gpu.as_ref().map_or("no GPU", |g| g.adapter.as_str());
            ui.label(RichText::new(adapter).small());
            ui.separator();
            ui.label(RichText::new(self.session.tree_summary()).small());
            ui.separator();
            let p = &self.progressive;
            let mut frame = String::new();
            if let Some(ms) = p.preview_ms {
                frame.push_str(&format!("preview {ms:.0} ms"));
            }
            if let Some(ms) = p.full_ms {
                frame.push_str(&format!(", full picture {:.2} s", ms / 1e3));
            }
            if !p.converged() {
                frame.push_str(&format!(" · refining {:.0}%", 100.0 * p.fraction()));
            }
            ui.label(RichText::new(frame).small());
            ui.separator();
            ui.label(RichText::new(format!("UI {:.0} fps", self.pacing.fps())).small());
            if let Some(ms) = self.edit_latency_ms {
                ui.separator();
                ui.label(RichText::new(format!("edit to picture {ms:.0} ms")).small());
            }
            if let Some(Notice { text, is_error }) = &self.message {
                ui.separator();
                let color = if *is_error {
                    Color32::from_rgb(255, 110, 100)
                } else {
                    Color32::LIGHT_GREEN
                };
                ui.label(RichText::new(text).small().color(color));
            }
        });
    }

    /// The picture: turns and zooms it by the mouse, draws what the ray caster has made,
    /// and lets it make more; true while more frames are wanted.
    fn picture(&mut self, ui: &mut egui::Ui) -> bool {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        if self.turn_and_zoom(ui, &response) {
            self.pacing.interacted();
        }
        let painter = ui.painter_at(rect);
        self.paint_layers(&painter, rect);
        self.paint_build_state(&painter, rect);
        let ppp = ui.ctx().pixels_per_point();
        let size = [rect.width(), rect.height()]
            .map(|side| ((side * ppp).round() as u32).clamp(1, MAX_WINDOW_PICTURE));
        let more = self.cast_rays(size);
        self.note_edit_latency();
        more || self.pacing.interacting()
    }

    /// Drag = rotate in the view's own planes; scroll = zoom. True if the view changed.
    fn turn_and_zoom(&mut self, ui: &egui::Ui, response: &egui::Response) -> bool {
        let mut changed = false;
        if response.dragged() {
            let d = response.drag_delta();
            let mods = ui.input(|i| i.modifiers);
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
                *z = (*z * (1.0 + f64::from(scroll) * 0.002)).clamp(0.05, 50.0);
                changed = true;
            }
        }
        changed
    }

    /// Paints the ray caster's textures over `rect` (the background until there are any).
    fn paint_layers(&self, painter: &egui::Painter, rect: egui::Rect) {
        let layers = self.progressive.paint().layers;
        if layers.is_empty() {
            painter.rect_filled(rect, 0.0, {
                let [r, g, b] = self.session.scene.render.background.0;
                Color32::from_rgb(r, g, b)
            });
        }
        for layer in layers {
            let Some(t) = self.progressive.texture(layer.texture) else {
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
                        super::blit::Layer {
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

    /// "building…" over the picture while a tree is built, or a word where there is nothing
    /// to see.
    fn paint_build_state(&self, painter: &egui::Painter, rect: egui::Rect) {
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
        }
    }

    /// Lets the ray caster draw for this frame's budget; true while it has more to do.
    fn cast_rays(&mut self, size: [u32; 2]) -> bool {
        let key = ViewKey::new(&self.session.scene, size);
        let interacting = self.pacing.interacting();
        let budget_ms = self.pacing.ray_budget_ms();
        let started = Instant::now();
        let mut more = false;
        if let (Some(gpu), Some(renderer)) = (&self.gpu, &self.renderer) {
            let mut renderer = renderer.write();
            more = self.progressive.step(
                gpu,
                &mut renderer,
                &mut self.session,
                key,
                interacting,
                budget_ms,
            );
        }
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
                self.progressive.binning_ms.unwrap_or(0.0),
                self.progressive.position()
            );
        }
        more
    }

    /// Once the first frame of an edit's picture is on screen: the edit's latency.
    fn note_edit_latency(&mut self) {
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

    /// Turns the chosen angles by the auto-rotation's speed over `dt_ms`.
    fn auto_rotate(&mut self, dt_ms: f64) {
        let step = self.ui.rotate_speed * dt_ms.min(100.0) / 1e3;
        let angles = self.session.scene.view.angles.iter_mut();
        for (a, on) in angles.zip(self.ui.rotate_angles) {
            if on {
                *a = (*a + step + PI).rem_euclid(2.0 * PI) - PI;
            }
        }
    }
}

impl eframe::App for FourfoldApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        if let Some(dt_ms) = self.pacing.begin_frame()
            && self.ui.auto_rotate
        {
            self.auto_rotate(dt_ms);
        }
        let gpu = self.gpu.clone();
        self.session.poll(gpu.as_ref());
        self.poll_export();

        // The panels leave their background to the frame's clear colour (clear_color below):
        // egui's shader filling them costs ~25 ms per frame on a software GPU, a clear nothing.
        let bare = egui::Frame::side_top_panel(ui.style()).fill(Color32::TRANSPARENT);
        egui::Panel::top("fourfold top")
            .frame(bare)
            .show(ui, |ui| self.top_bar(ui));
        egui::Panel::bottom("fourfold status")
            .frame(bare)
            .show(ui, |ui| self.status_line(ui));
        let mut rebuild = false;
        egui::Panel::left("fourfold controls")
            .default_size(380.0)
            .frame(bare)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    self.formula_editor(ui);
                    ui.separator();
                    rebuild |= self.parameter_sliders(ui);
                    ui.separator();
                    self.view_controls(ui);
                    ui.separator();
                    // Closed at first: every widget on screen costs egui's shader per pixel
                    // (a few ms per section on a software GPU), and these are set less often.
                    egui::CollapsingHeader::new(RichText::new("Domain and tree").heading())
                        .id_salt("fourfold domain and tree")
                        .show(ui, |ui| rebuild |= self.tree_controls(ui));
                    egui::CollapsingHeader::new(RichText::new("Rendering").heading())
                        .id_salt("fourfold rendering")
                        .show(ui, |ui| self.render_controls(ui));
                });
            });
        if rebuild {
            match self.session.scene.check() {
                Ok(()) => self.session.rebuild_tree(gpu.as_ref()),
                Err(problem) => {
                    self.message = Some(Notice::error(problem.message(Speaker::File)));
                }
            }
        }
        let mut more = false;
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| {
                more = self.picture(ui);
            });
        if more || self.session.building() || self.export.is_some() || self.ui.auto_rotate {
            ui.ctx().request_repaint();
        } else {
            self.pacing.idle();
        }
    }

    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, KEY_SCENE, &self.session.scene.to_toml());
        eframe::set_value(storage, KEY_UI, &self.ui);
    }
}

/// The scene the viewer opens with when none is given or stored: the chapter's figure.
pub fn default_scene() -> Scene {
    Scene::example("fig-3-9-left")
        .unwrap_or_else(|| Scene::from_formula("x^2 + y^2 + z^2 + w^2 - 1"))
}

fn color_edit(ui: &mut egui::Ui, c: &mut Color) {
    let mut rgb = c.0;
    if ui.color_edit_button_srgb(&mut rgb).changed() {
        c.0 = rgb;
    }
}

/// Syntax colouring from the grammar's own tokens.
pub fn highlight(text: &str, dark: bool) -> LayoutJob {
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
            job.append(
                &text[at..t.start],
                0.0,
                TextFormat::simple(font.clone(), plain),
            );
        }
        job.append(
            &text[t.start..t.end],
            0.0,
            TextFormat::simple(font.clone(), color(t.kind)),
        );
        at = t.end;
    }
    if at < text.len() {
        job.append(&text[at..], 0.0, TextFormat::simple(font, plain));
    }
    job
}
