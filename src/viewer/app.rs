//! The window: formula editor, sliders and settings on the left, the picture in the middle,
//! the status line at the bottom. Thin over [`Session`] (what is drawn) and [`Progressive`]
//! (how it reaches the screen).

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::sync::Arc;
use web_time::Instant;

use eframe::{egui, egui_wgpu};
use egui::{Color32, RichText, TextFormat, text::LayoutJob};

use crate::render::animation::{Animation, MAX_FRAMES, Sweep, Turn, parse_range};
use crate::render::camera::rotate_view;
use crate::render::cpu::viridis;
use crate::render::framing::{self, ZOOM_RANGE};
use crate::render::uniforms::hidden_range;
use crate::render::{Camera, Gpu, RayCaster, Shader};
use crate::scene::{
    AxisRange, Color, ColorBy, EXAMPLES, MAX_CERT_BUDGET, MAX_HITS, MAX_RAYS, MAX_STEPS,
    MAX_TREE_LEVEL, Sampling, Scene, Speaker, Undecided,
};
use crate::syntax::SourceError;
use crate::syntax::parser::{TokenKind, tokens};

use super::files::{AnimationExport, Notice, PngExport};
use super::gallery::Gallery;
use super::history::{History, Snapshot};
use super::pacing::Pacing;
use super::progressive::{Progressive, Subject};
use super::session::Session;
use super::session::VIEW_TARGET;

/// Storage keys (eframe persistence).
const KEY_SCENE: &str = "fourfold.scene";
const KEY_UI: &str = "fourfold.ui";

/// A second ray caster, for the projection beside a slice: the shader it was made for and
/// the session's picture generation whose hierarchy it holds.
struct InsetCaster {
    caster: RayCaster,
    shader: Arc<Shader>,
    generation: u64,
}

/// Ray casting for the projection beside a slice gets at least this much of a UI frame.
const RAY_FLOOR_MS: f64 = 2.0;

/// The largest side of the picture in the window, in pixels.
const MAX_WINDOW_PICTURE: u32 = 4096;

/// UI settings that survive a restart besides the scene.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(default)]
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
    pub animation: AnimationChoice,
    /// Show a slice beside the projection, with the slice's place marked there.
    pub side_by_side: bool,
}

/// What "Export animation" makes, as the user last set it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct AnimationChoice {
    pub path: String,
    pub motion: Motion,
    /// The plane or angle that turns (as `animate --turn` takes it), and how many turns.
    pub plane: String,
    pub turns: f64,
    /// The parameter swept, from and to.
    pub param: String,
    pub range: (f64, f64),
    /// Where the moving slice starts and ends along n2.
    pub slice_range: (f64, f64),
    pub frames: u32,
    pub fps: f64,
    pub fit: bool,
}

impl Default for AnimationChoice {
    fn default() -> Self {
        Self {
            path: "fourfold.gif".into(),
            motion: Motion::Turn,
            plane: "xw".into(),
            turns: 1.0,
            param: String::new(),
            range: (0.5, 1.5),
            slice_range: (-1.0, 1.0),
            frames: 60,
            fps: 24.0,
            fit: true,
        }
    }
}

/// What moves in an exported animation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Motion {
    /// The manifold turns in a plane.
    Turn,
    /// A parameter sweeps.
    Sweep,
    /// A slice moves along n2.
    Slice,
}

/// The planes and angles "Export animation" offers.
const TURN_PLANES: [&str; 12] = [
    "xy", "yz", "zw", "xz", "xw", "yw", "θ1", "θ2", "θ3", "θ4", "θ5", "θ6",
];

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
            animation: AnimationChoice::default(),
            side_by_side: true,
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
    animation_export: Option<AnimationExport>,
    pub pacing: Pacing,
    /// Edit latency of the last edit: text change to the first frame of its picture, ms.
    pub edit_latency_ms: Option<f64>,
    latency_generation: u64,
    /// The preset chosen last (for the explanation line).
    pub preset: Option<&'static str>,
    /// Frame the manifold once the tree of a scene just opened is ready.
    pub fit_pending: bool,
    /// The picture's size in pixels at the last frame.
    pub picture_size: [u32; 2],
    pub history: History,
    gallery: Gallery,
    pub gallery_open: bool,
    /// The projection drawn beside a slice, and the ray caster it draws with.
    pub inset: Progressive,
    inset_caster: Option<InsetCaster>,
    /// A scene file the browser is reading (the page's "Open…"), and a PNG on its way back
    /// from the GPU.
    #[cfg(target_arch = "wasm32")]
    upload: super::web::Upload,
    #[cfg(target_arch = "wasm32")]
    png_download: Option<super::web::PngDownload>,
    /// Where the formula editor and the picture were at the last frame (the web page's
    /// tests type into the one and read the other).
    pub editor_rect: Option<egui::Rect>,
    pub picture_rect: Option<egui::Rect>,
    /// The picture was still being drawn (or a tree built) at the last frame.
    pub drawing: bool,
    /// Where the controls panel was at the last frame (tests check that the formula's
    /// error stays inside it).
    pub controls_rect: Option<egui::Rect>,
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
        // The preset list names the scene when it is one of the examples.
        let preset = EXAMPLES.iter().map(|(name, _)| *name).find(|name| {
            Scene::example(name)
                .is_some_and(|e| e.formula == scene.formula && e.description == scene.description)
        });
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
            animation_export: None,
            pacing: Pacing::default(),
            edit_latency_ms: None,
            latency_generation: 0,
            preset,
            fit_pending: true,
            picture_size: [0, 0],
            history: History::default(),
            gallery: Gallery::default(),
            gallery_open: false,
            controls_rect: None,
            editor_rect: None,
            picture_rect: None,
            drawing: true,
            inset: Progressive::default(),
            inset_caster: None,
            #[cfg(target_arch = "wasm32")]
            upload: Default::default(),
            #[cfg(target_arch = "wasm32")]
            png_download: None,
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

    /// Opens `scene` in place of the one on screen; `frame` fits the picture to it once its
    /// tree is ready (a share link keeps the view it carries).
    pub fn open(&mut self, scene: Scene, frame: bool) {
        self.session.load_scene(scene, self.gpu.as_ref());
        self.preset = None;
        self.fit_pending = frame;
    }

    /// Loads one of the embedded example scenes by name.
    pub fn load_preset(&mut self, name: &'static str) {
        if let Some((_, text)) = EXAMPLES.iter().find(|(n, _)| *n == name) {
            match Scene::parse(text, name) {
                Ok(scene) => {
                    self.session.load_scene(scene, self.gpu.as_ref());
                    self.preset = Some(name);
                    self.fit_pending = true;
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
        if let Some(notice) = self
            .animation_export
            .as_ref()
            .and_then(AnimationExport::poll)
        {
            self.message = Some(notice);
            self.animation_export = None;
        }
    }

    /// The animation "Export animation" is set to make, or why it cannot be made.
    fn chosen_animation(&self) -> Result<Animation, String> {
        let c = &self.ui.animation;
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
        Ok(Animation {
            turn,
            sweep,
            slice_sweep,
            frames: c.frames.clamp(1, MAX_FRAMES),
            fps: c.fps.clamp(1.0, 100.0),
        })
    }

    fn export_animation(&mut self) {
        match self.chosen_animation() {
            Ok(animation) => {
                let [w, h] = self.ui.export_size;
                let path = self.ui.animation.path.clone();
                self.message = Some(Notice::done(format!(
                    "drawing {} frames of {w}x{h} into {path}…",
                    animation.frames
                )));
                self.animation_export = Some(AnimationExport::start(
                    self.session.scene.clone(),
                    animation,
                    w,
                    h,
                    self.ui.animation.fit,
                    path,
                ));
            }
            Err(e) => self.message = Some(Notice::error(e)),
        }
    }

    /// The "Export animation" section: what moves, how many frames, where to.
    fn animation_controls(&mut self, ui: &mut egui::Ui) {
        let params = self.session.param_names();
        let c = &mut self.ui.animation;
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
                        for p in &params {
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
                        .range(-10.0..=10.0)
                        .suffix(" turns"),
                );
            });
        }
        ui.horizontal(|ui| {
            ui.add(
                egui::DragValue::new(&mut c.frames)
                    .range(1..=MAX_FRAMES)
                    .suffix(" frames"),
            );
            ui.add(
                egui::DragValue::new(&mut c.fps)
                    .range(1.0..=100.0)
                    .suffix(" fps"),
            );
            ui.checkbox(&mut c.fit, "fit")
                .on_hover_text("frame the manifold in every frame");
        });
        ui.horizontal(|ui| {
            ui.add(egui::TextEdit::singleline(&mut self.ui.animation.path).desired_width(150.0))
                .on_hover_text("a .gif, an animated .png, or a folder for numbered PNGs; the size is the PNG export's");
            match &self.animation_export {
                Some(export) => {
                    let (done, all) = (export.drawn(), export.frames);
                    ui.add(
                        egui::ProgressBar::new(done as f32 / all.max(1) as f32)
                            .desired_width(90.0)
                            .text(format!("{done}/{all}")),
                    );
                    if ui.button("Cancel").clicked() {
                        export.cancel();
                    }
                }
                None => {
                    if ui.button("Export animation").clicked() {
                        self.export_animation();
                    }
                }
            }
        });
    }

    /// Zooms and pans so that the manifold fills the picture (the tree's boxes, at the
    /// current angles); false if there is nothing to frame yet.
    pub fn fit(&mut self) -> bool {
        let Some(hierarchy) = &self.session.hierarchy else {
            return false;
        };
        let [w, h] = self.picture_size;
        let scene = &mut self.session.scene;
        match framing::fit(hierarchy, &scene.domain, &scene.view, w, h) {
            Some(view) => {
                scene.view = view;
                true
            }
            None => false,
        }
    }

    /// Frames a scene just opened once its tree is ready, as part of opening it.
    fn fit_when_ready(&mut self) {
        if !self.fit_pending || self.session.building() || self.picture_size[0] == 0 {
            return;
        }
        self.fit_pending = false;
        if self.fit() {
            self.history.amend(&self.snapshot());
        }
    }

    /// Shows this frame's state to the history. Auto-rotation's turning is not a change the
    /// user made, so while it runs the angles are left out.
    fn record_history(&mut self, ctx: &egui::Context) {
        let mut now = self.snapshot();
        if self.ui.auto_rotate
            && let Some(settled) = self.history.settled()
        {
            now.scene.view.angles = settled.scene.view.angles;
        }
        let dragging = ctx.input(|i| i.pointer.any_down());
        self.history.observe(&now, dragging);
        if self.history.settling(&now) {
            // Come back when the change has settled, even if nothing else happens.
            ctx.request_repaint_after(super::history::SETTLE);
        }
    }

    /// What undo and redo restore.
    fn snapshot(&self) -> Snapshot {
        Snapshot {
            scene: self.session.scene.clone(),
            text: self.session.text.clone(),
        }
    }

    /// Goes back to `to`: only what changed is rebuilt (a new formula compiles again; new
    /// parameters, domain or tree settings rebuild the tree; the rest is the view).
    fn restore(&mut self, to: Snapshot) {
        let gpu = self.gpu.clone();
        let s = &mut self.session;
        if to.text == s.text && to.scene.formula == s.scene.formula {
            let rebuild = to.scene.params != s.scene.params
                || to.scene.domain != s.scene.domain
                || to.scene.tree != s.scene.tree;
            let brute_force = to.scene.render.brute_force;
            let current_brute_force = s.scene.render.brute_force;
            s.scene = to.scene;
            // Brute force switches once its pipeline is warm (Session::set_brute_force).
            s.scene.render.brute_force = current_brute_force;
            if rebuild {
                s.rebuild_tree(gpu.as_ref());
            }
            s.set_brute_force(brute_force, gpu.as_ref());
        } else {
            s.load_scene(to.scene, gpu.as_ref());
            if to.text != s.text {
                s.set_text(&to.text, gpu.as_ref());
            }
        }
        self.fit_pending = false;
    }

    pub fn undo(&mut self) {
        let now = self.snapshot();
        if let Some(to) = self.history.undo(&now) {
            self.restore(to);
        }
    }

    pub fn redo(&mut self) {
        let now = self.snapshot();
        if let Some(to) = self.history.redo(&now) {
            self.restore(to);
        }
    }

    /// The keys that act on the whole window, when no text field has the keyboard: F fits,
    /// Ctrl+Z undoes, Ctrl+Shift+Z and Ctrl+Y redo.
    fn shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        use egui::{Key, KeyboardShortcut, Modifiers};
        let redo = KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        let redo_y = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
        let undo = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
        let fit = KeyboardShortcut::new(Modifiers::NONE, Key::F);
        let (redo, undo, fit) = ctx.input_mut(|i| {
            let redo = i.consume_shortcut(&redo) || i.consume_shortcut(&redo_y);
            (redo, i.consume_shortcut(&undo), i.consume_shortcut(&fit))
        });
        if redo {
            self.redo();
        } else if undo {
            self.undo();
        }
        if fit {
            self.fit();
        }
    }

    fn top_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.label(RichText::new("fourfold").strong());
            // (The gallery draws on a thread of its own, which a web page does not have.)
            if cfg!(not(target_arch = "wasm32"))
                && ui
                    .selectable_label(self.gallery_open, "Gallery")
                .on_hover_text("every example scene, as pictures")
                .clicked()
            {
                self.gallery_open = !self.gallery_open;
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
            self.file_actions(ui);
            if ui
                .button("Copy link")
                .on_hover_text("a link that opens this scene in the web page (fourfold view LINK opens it here)")
                .clicked()
            {
                ui.ctx().copy_text(self.share_link());
                self.message = Some(Notice::done("link copied"));
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

    /// The exported picture's width and height.
    fn export_size_fields(&mut self, ui: &mut egui::Ui) {
        for (side, suffix) in self.ui.export_size.iter_mut().zip([" w", " h"]) {
            ui.add(
                egui::DragValue::new(side)
                    .range(1..=crate::render::MAX_PICTURE_SIDE)
                    .suffix(suffix),
            );
        }
    }

    /// The share link of the scene on screen: the page's address in the browser, a
    /// relative one on the desktop.
    pub fn share_link(&self) -> String {
        #[cfg(target_arch = "wasm32")]
        let page = super::web::page_address();
        #[cfg(not(target_arch = "wasm32"))]
        let page = "index.html".to_string();
        format!("{page}#{}", self.link_fragment())
    }

    /// The share link's `#…` part: the scene on screen, with only the parameters its formula
    /// has (the scene keeps the values of earlier formulas' parameters, for undo).
    pub fn link_fragment(&self) -> String {
        let names = self.session.param_names();
        let mut scene = self.session.scene.clone();
        if self.session.formula.is_some() {
            scene.params.retain(|name, _| names.contains(name));
        }
        scene.to_link()
    }

    /// The formula editor and its error; returns nothing, edits the session.
    fn formula_editor(&mut self, ui: &mut egui::Ui) {
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
                if let Some(f) = &self.session.formula {
                    ui.label(RichText::new(format!("F = {}", f.f_text())).small().weak());
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
                egui::Slider::new(
                    &mut self.session.scene.view.zoom,
                    ZOOM_RANGE.0..=ZOOM_RANGE.1,
                )
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
    fn section_controls(&mut self, ui: &mut egui::Ui) {
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
            ui.checkbox(&mut self.ui.side_by_side, "beside the projection")
                .on_hover_text("the projection on the right, where the slice cuts in orange");
        }
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
        ui.add_enabled(
            super::CERTIFIED_PIXELS,
            egui::Checkbox::new(&mut r.certified, "certified pixels"),
        )
        .on_disabled_hover_text(
            "Certified pixels are drawn by the desktop viewer and `fourfold render \
             --certified`, not yet in the browser.",
        )
        .on_hover_text(
            "Prove each pixel: hit (F changes sign on its observer plane), empty (F has no \
                 zero there), or undecided once the budget of cells is spent, drawn magenta \
                 where no ray found a hit. The counts are under the picture.",
        );
        if r.certified {
            ui.horizontal(|ui| {
                ui.label("cells per pixel");
                ui.add(egui::DragValue::new(&mut r.cert_budget).range(1..=MAX_CERT_BUDGET));
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

    /// The certified pixels' counts, on a line of their own: as the status line wraps, a
    /// longer text would shrink the picture and start its (slow) certified frame again.
    fn certified_line(&self, ui: &mut egui::Ui) {
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
        let label = ui.label(RichText::new(text).small().color(color));
        if undecided {
            let continuous = self.session.hierarchy.as_ref().is_none_or(|h| h.continuous);
            label.on_hover_text(format!(
                "Undecided pixels are marked in magenta where no ray found a hit; {}.",
                crate::render::certify::undecided_advice(
                    continuous,
                    "budget (cells per pixel, under Rendering)"
                )
            ));
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
    /// shader, given each new hierarchy, dropped when not shown.
    fn keep_inset_caster(&mut self) {
        let s = &self.session;
        let (Some(gpu), Some(shader), Some(hierarchy)) = (&self.gpu, &s.shader, &s.hierarchy)
        else {
            return;
        };
        if !self.side_by_side() {
            self.inset_caster = None;
            return;
        }
        let generation = s.picture_generation;
        if let Some(inset) = &mut self.inset_caster
            && Arc::ptr_eq(&inset.shader, shader)
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
        match RayCaster::with_target(gpu, shader, hierarchy, VIEW_TARGET) {
            Ok(caster) => {
                self.inset_caster = Some(InsetCaster {
                    caster,
                    shader: shader.clone(),
                    generation,
                });
            }
            Err(e) => self.message = Some(Notice::error(e.to_string())),
        }
    }

    /// Drag = rotate in the view's own planes; middle or alt drag = pan; scroll = zoom. True
    /// if the view changed.
    fn turn_and_zoom(&mut self, ui: &egui::Ui, response: &egui::Response) -> bool {
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
                *z = (*z * (1.0 + f64::from(scroll) * 0.002)).clamp(0.05, 50.0);
                self.fit_pending = false;
                changed = true;
            }
        }
        changed
    }

    /// With colour by the hidden direction: the colour map and the n2 values its ends stand
    /// for, at the picture's bottom left.
    fn paint_legend(&self, painter: &egui::Painter, rect: egui::Rect) {
        let scene = &self.session.scene;
        let Some(hierarchy) = self
            .session
            .hierarchy
            .as_ref()
            .filter(|_| scene.render.color_by == ColorBy::Hidden)
        else {
            return;
        };
        let [w, h] = self.picture_size;
        let camera = Camera::new(&scene.domain, &scene.view, w, h);
        let [lo, hi] = hidden_range(hierarchy, &scene.domain, &camera);
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
    fn cast_rays(&mut self, size: [u32; 2], inset: Option<[u32; 2]>) -> bool {
        // A picture about to be replaced is not refined further: where the build runs in
        // the window's own frames (the web page), that would slow the build replacing it.
        if self.session.building()
            && self.progressive.first_frame_of == Some(self.session.picture_generation)
        {
            return false;
        }
        let interacting = self.pacing.interacting();
        let budget_ms = self.pacing.ray_budget_ms();
        let started = Instant::now();
        let mut more = false;
        if let (Some(gpu), Some(renderer)) = (&self.gpu, &self.renderer) {
            let mut renderer = renderer.write();
            let s = &mut self.session;
            let Some(hierarchy) = &s.hierarchy else {
                return false;
            };
            if let Some(caster) = &mut s.caster {
                let subject = Subject {
                    caster,
                    hierarchy,
                    certifying: s.certifying.as_ref(),
                    params: &s.tree_params,
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
            }
            if let (Some(size), Some(inset)) = (inset, &mut self.inset_caster) {
                // The projection, with the slice's place marked.
                let mut scene = s.scene.clone();
                scene.view.mark = scene.view.slice.take();
                let subject = Subject {
                    caster: &mut inset.caster,
                    hierarchy,
                    certifying: s.certifying.as_ref(),
                    params: &s.tree_params,
                    scene: &scene,
                    generation: s.picture_generation,
                };
                let left = budget_ms - started.elapsed().as_secs_f64() * 1e3;
                more |= self.inset.step(
                    gpu,
                    &mut renderer,
                    subject,
                    size,
                    interacting,
                    left.max(RAY_FLOOR_MS),
                );
            }
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

/// The file actions of the desktop: paths typed in, files written beside the picture.
#[cfg(not(target_arch = "wasm32"))]
impl FourfoldApp {
    /// Open, save and export, with paths typed in.
    fn file_actions(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        ui.add(egui::TextEdit::singleline(&mut self.ui.scene_path).desired_width(140.0))
            .on_hover_text("scene file path (TOML, as for the command line)");
        if ui.button("Open").clicked() {
            self.open_scene();
        }
        if ui.button("Save").clicked() {
            self.message = Some(super::files::save_scene(
                &self.session.scene,
                &self.ui.scene_path,
            ));
        }
        ui.separator();
        ui.add(egui::TextEdit::singleline(&mut self.ui.png_path).desired_width(120.0));
        self.export_size_fields(ui);
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
        ui.separator();
    }

    fn export_png(&mut self) {
        let [w, h] = self.ui.export_size;
        let path = self.ui.png_path.clone();
        self.message = Some(Notice::done(format!("rendering {w}x{h} to {path}…")));
        self.export = Some(PngExport::start(self.session.scene.clone(), w, h, path));
    }

    fn open_scene(&mut self) {
        let path = self.ui.scene_path.clone();
        match super::files::open_scene(&path) {
            Ok(scene) => {
                self.open(scene, true);
                self.message = Some(Notice::done(format!("opened {path}")));
            }
            Err(notice) => self.message = Some(notice),
        }
    }

    fn export_wgsl(&mut self) {
        let path = &self.ui.wgsl_path;
        self.message = Some(match &self.session.shader {
            Some(shader) => super::files::export_wgsl(&shader.source, path),
            None => Notice::error("no valid shader yet"),
        });
    }
}

/// The file actions of the web page: uploads and downloads.
#[cfg(target_arch = "wasm32")]
impl FourfoldApp {
    /// Open as an upload; save and export as downloads.
    fn file_actions(&mut self, ui: &mut egui::Ui) {
        use super::web;
        ui.separator();
        if ui
            .button("Open…")
            .on_hover_text("a scene file (.toml)")
            .clicked()
            && let Err(e) = self.upload.choose(".toml,text/plain", ui.ctx())
        {
            self.message = Some(Notice::error(e));
        }
        match self.upload.take() {
            Some(Ok((name, text))) => match Scene::parse(&text, &name) {
                Ok(scene) => {
                    self.open(scene, true);
                    self.message = Some(Notice::done(format!("opened {name}")));
                }
                Err(e) => self.message = Some(Notice::error(e.to_string())),
            },
            Some(Err(e)) => self.message = Some(Notice::error(e)),
            None => {}
        }
        if ui.button("Save scene").clicked() {
            let toml = self.session.scene.to_toml();
            self.message = Some(
                match web::download("scene.toml", "application/toml", toml.as_bytes()) {
                    Ok(()) => Notice::done("scene.toml downloaded"),
                    Err(e) => Notice::error(e),
                },
            );
        }
        self.export_size_fields(ui);
        if ui
            .add_enabled(self.png_download.is_none(), egui::Button::new("Export PNG"))
            .clicked()
            && let Some(gpu) = &self.gpu
        {
            match web::PngDownload::start(gpu, &self.session, self.ui.export_size) {
                Ok(download) => {
                    self.png_download = Some(download);
                    self.message = Some(Notice::done("drawing the PNG…"));
                }
                Err(e) => self.message = Some(Notice::error(e)),
            }
        }
        if let (Some(download), Some(gpu)) = (&self.png_download, &self.gpu) {
            match download.poll(gpu) {
                Some(notice) => {
                    self.message = Some(notice);
                    self.png_download = None;
                }
                None => ui.ctx().request_repaint(),
            }
        }
        if ui.button("Export WGSL").clicked() {
            self.message = Some(match &self.session.shader {
                Some(shader) => {
                    match web::download("fourfold.wgsl", "text/plain", shader.source.as_bytes()) {
                        Ok(()) => Notice::done("fourfold.wgsl downloaded"),
                        Err(e) => Notice::error(e),
                    }
                }
                None => Notice::error("no valid shader yet"),
            });
        }
        ui.separator();
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
        let (least, most) = super::session::SLICE_BUDGET.into_inner();
        self.session.slice_budget =
            web_time::Duration::try_from_secs_f64(self.pacing.ui_frame_ms / 1e3)
                .unwrap_or(least)
                .clamp(least, most);
        self.session.poll(gpu.as_ref());
        self.poll_export();
        self.fit_when_ready();
        self.shortcuts(ui.ctx());

        // The panels leave their background to the frame's clear colour (clear_color below):
        // egui's shader filling them costs ~25 ms per frame on a software GPU, a clear nothing.
        let bare = egui::Frame::side_top_panel(ui.style()).fill(Color32::TRANSPARENT);
        egui::Panel::top("fourfold top")
            .frame(bare)
            .show(ui, |ui| self.top_bar(ui));
        egui::Panel::bottom("fourfold status")
            .frame(bare)
            .show(ui, |ui| self.status_line(ui));
        if self.session.scene.render.certified {
            egui::Panel::bottom("fourfold certified")
                .frame(bare)
                .show(ui, |ui| self.certified_line(ui));
        }
        let mut rebuild = false;
        let controls = egui::Panel::left("fourfold controls")
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
                    // (Animations are drawn on a thread of their own, which a web page does not
                    // have.)
                    if cfg!(not(target_arch = "wasm32")) {
                        egui::CollapsingHeader::new(RichText::new("Export animation").heading())
                            .id_salt("fourfold animation")
                            .show(ui, |ui| self.animation_controls(ui));
                    }
                });
            });
        self.controls_rect = Some(controls.response.rect);
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
        if let Some(name) = self.gallery.show(ui.ctx(), &mut self.gallery_open) {
            self.load_preset(name);
            self.gallery_open = false;
        }
        if self.session.building() {
            // An edit made in this frame starts building now, not a frame later (a frame
            // is long on a software GPU, and the page builds in its frames).
            self.session.poll(gpu.as_ref());
        }
        self.record_history(ui.ctx());
        #[cfg(target_arch = "wasm32")]
        super::web::sync_address(self);
        let busy = self.session.building()
            || self.export.is_some()
            || self.animation_export.is_some()
            || self.gallery.busy();
        self.drawing = more || self.session.building();
        if more || busy || self.ui.auto_rotate {
            ui.ctx().request_repaint();
        } else {
            self.pacing.idle();
        }
    }

    /// (The web page reads the app's state for its scripts through this.)
    #[cfg(target_arch = "wasm32")]
    fn as_any_mut(&mut self) -> Option<&mut dyn std::any::Any> {
        Some(self)
    }

    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, KEY_SCENE, &self.session.scene.to_toml());
        eframe::set_value(storage, KEY_UI, &self.ui);
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

/// The size in pixels of a picture filling `rect` at `ppp` pixels per point.
fn pixels(rect: egui::Rect, ppp: f32) -> [u32; 2] {
    [rect.width(), rect.height()]
        .map(|side| ((side * ppp).round() as u32).clamp(1, MAX_WINDOW_PICTURE))
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
const ERROR_COLOR: Color32 = Color32::from_rgb(255, 110, 100);

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
    let line = |ui: &mut egui::Ui, text: &str, color: Option<Color32>| {
        let mut rich = RichText::new(text).font(font.clone());
        if let Some(c) = color {
            rich = rich.color(c);
        }
        ui.add(egui::Label::new(rich).wrap_mode(egui::TextWrapMode::Extend));
    };
    ui.scope(|ui| {
        ui.spacing_mut().item_spacing.y = 0.0;
        line(ui, &window.source, None);
        line(ui, &window.carets, Some(ERROR_COLOR));
        if let Some(label) = &window.label {
            line(ui, label, Some(ERROR_COLOR));
        }
    });
    if let Some(hint) = &error.hint {
        ui.label(RichText::new(format!("hint: {hint}")).small());
    }
}
