//! The window: formula editor, sliders and settings on the left, the picture in the middle,
//! the status line at the bottom. Thin over [`Session`] (what is drawn) and [`Progressive`]
//! (how it reaches the screen); each panel is a file of its own, and what only one platform
//! has comes from `crate::platform`.

mod critical_strip;
mod editor;
mod embed;
mod inset;
mod picture;
mod settings_panel;
mod status;
mod undo;
mod view_panel;

use eframe::{egui, egui_wgpu};
use egui::{Color32, RichText};

use fourfold::render::Gpu;
use fourfold::render::view::framing::fit;
use fourfold::scene::{EXAMPLES, Scene, Speaker};

use crate::gallery::Gallery;
use crate::history::History;
use crate::notice::Notice;
use crate::pacing::Pacing;
use crate::platform;
use crate::progressive::Progressive;
use crate::session::{SLICE_BUDGET, Session};

use crate::outcome::{Outcome, Window};
use crate::settings::{KEY_SCENE, KEY_UI, UiSettings};
use inset::{InsetBuild, InsetCaster};

/// The viewer application.
pub struct FourfoldApp {
    pub session: Session,
    pub progressive: Progressive,
    pub ui: UiSettings,
    gpu: Option<Gpu>,
    renderer: Option<std::sync::Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>>,
    /// A short message after an action ("saved …", or what went wrong).
    pub message: Option<Notice>,
    /// What only this platform has (exports, uploads, the address bar).
    pub platform: platform::State,
    /// The example scenes as pictures, in a window of their own.
    pub gallery: Gallery,
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
    /// The slice sweep's critical values, for the slice slider's ticks, and where the
    /// ticks were drawn at the last frame (the web page's tests click them).
    pub critical: crate::critical::Critical,
    pub critical_strip_rect: Option<egui::Rect>,
    /// The projection drawn beside a slice, and the ray caster it draws with.
    pub inset: Progressive,
    inset_caster: Option<InsetCaster>,
    inset_build: Option<InsetBuild>,
    /// Where the formula editor and the picture were at the last frame (the web page's
    /// tests type into the one and read the other).
    pub editor_rect: Option<egui::Rect>,
    pub picture_rect: Option<egui::Rect>,
    /// Where the embedded picture's "open in fourfold" link was at the last frame.
    pub embed_link_rect: Option<egui::Rect>,
    /// The picture was still being drawn (or a tree built) at the last frame.
    pub drawing: bool,
    /// Every picture with more to draw waited for the GPU at the last frame (the queue
    /// wakes the window when a run is done).
    picture_waits: bool,
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
                if let Some(blit) = crate::blit::Blit::new(&rs.device, rs.target_format) {
                    rs.renderer.write().callback_resources.insert(blit);
                }
                (
                    Some(Gpu::from_parts(rs.device.clone(), rs.queue.clone(), &info)),
                    Some(rs.renderer.clone()),
                )
            }
            None => (None, None),
        };
        let mut app = Self {
            session: Session::new(scene.clone()),
            progressive: Progressive::waking(cc.egui_ctx.clone()),
            ui,
            gpu,
            renderer,
            message: None,
            platform: platform::State::default(),
            gallery: Gallery::default(),
            pacing: Pacing::default(),
            edit_latency_ms: None,
            latency_generation: 0,
            preset,
            fit_pending: true,
            picture_size: [0, 0],
            history: History::default(),
            controls_rect: None,
            editor_rect: None,
            picture_rect: None,
            embed_link_rect: None,
            drawing: true,
            picture_waits: false,
            inset: Progressive::waking(cc.egui_ctx.clone()),
            inset_caster: None,
            inset_build: None,
            critical: Default::default(),
            critical_strip_rect: None,
        };
        if app.gpu.is_none() {
            app.message = Some(Notice::error(
                "no GPU renderer: the viewer needs wgpu (on Linux without a GPU: apt-get install -y mesa-vulkan-drivers)",
            ));
        }
        if let Some(on) = app.ui.interpret {
            app.session.interpret_new_formulas(on);
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

    /// Does what a platform's widget asked: says its message, opens its scene.
    fn apply(&mut self, outcome: Outcome) {
        if let Some(notice) = outcome.notice {
            self.message = Some(notice);
        }
        if let Some((scene, frame)) = outcome.open {
            self.open(scene, frame);
        }
        if let Some(name) = outcome.preset {
            self.load_preset(name);
        }
    }

    /// Zooms and pans so that the manifold fills the picture (the tree's boxes, at the
    /// current angles); false if there is nothing to frame yet.
    pub fn fit(&mut self) -> bool {
        let Some(hierarchy) = &self.session.hierarchy else {
            return false;
        };
        let [w, h] = self.picture_size;
        let scene = &mut self.session.scene;
        match fit(hierarchy, &scene.domain, &scene.view, w, h) {
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
}

impl eframe::App for FourfoldApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        if let Some(dt_ms) = self.pacing.begin_frame()
            && self.ui.auto_rotate
        {
            self.auto_rotate(dt_ms);
        }
        let gpu = self.gpu.clone();
        let (least, most) = SLICE_BUDGET.into_inner();
        self.session.slice_budget =
            web_time::Duration::try_from_secs_f64(self.pacing.ui_frame_ms / 1e3)
                .unwrap_or(least)
                .clamp(least, most);
        self.session.poll(gpu.as_ref());
        let searching = match (&self.session.program, self.session.scene.view.slice) {
            (Some(program), Some(_)) => self.critical.poll(
                &program.formula,
                &self.session.scene,
                self.session.slice_budget,
            ),
            _ => false,
        };
        self.fit_when_ready();
        if self.platform.embedded() {
            let more = self.embedded_picture(ui);
            self.finish_frame(ui, gpu.as_ref(), more, searching);
            return;
        }
        self.shortcuts(ui.ctx());

        // The panels leave their background to the frame's clear colour (clear_color below):
        // egui's shader filling them is a large share of a frame on a software GPU, a clear
        // costs nothing.
        let bare = egui::Frame::side_top_panel(ui.style()).fill(Color32::TRANSPARENT);
        egui::Panel::top("fourfold top")
            .frame(bare)
            .show(ui, |ui| self.top_bar(ui));
        egui::Panel::bottom("fourfold status")
            .frame(bare)
            .show(ui, |ui| self.status_line(ui));
        egui::Panel::bottom("fourfold notice")
            .frame(bare)
            .show(ui, |ui| self.notice_line(ui));
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
                    let window = Window {
                        session: &self.session,
                        settings: &mut self.ui,
                        gpu: self.gpu.as_ref(),
                    };
                    let outcome = platform::sections(&mut self.platform, ui, window);
                    self.apply(outcome);
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
        self.finish_frame(ui, gpu.as_ref(), more, searching);
    }

    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        // An embedded picture is someone else's scene: the user's own stays stored.
        if self.platform.embedded() {
            return;
        }
        eframe::set_value(storage, KEY_SCENE, &self.session.scene.to_toml());
        eframe::set_value(storage, KEY_UI, &self.ui);
    }
}

impl FourfoldApp {
    /// The end of every frame: the platform's part, the build started by an edit of this
    /// frame, the undo history, and whether to draw again (`more`: the picture is not
    /// complete; `searching`: critical values are being searched).
    fn finish_frame(&mut self, ui: &mut egui::Ui, gpu: Option<&Gpu>, more: bool, searching: bool) {
        let window = Window {
            session: &self.session,
            settings: &mut self.ui,
            gpu: self.gpu.as_ref(),
        };
        let outcome = platform::end_frame(&mut self.platform, ui.ctx(), window);
        self.apply(outcome);
        if let Some(name) = self.gallery.show(ui.ctx(), gpu) {
            self.load_preset(name);
        }
        if self.session.building() {
            // An edit made in this frame starts building now, not a frame later (a frame
            // is long on a software GPU, and the page builds in its frames).
            self.session.poll(gpu);
        }
        self.record_history(ui.ctx());
        let busy =
            self.session.building() || self.platform.busy() || self.gallery.busy() || searching;
        self.drawing = more || self.session.building();
        // A picture waiting for the GPU is woken by the queue when a run is done: no frame
        // is drawn meanwhile (on a software GPU they would take its time).
        if (more && !self.picture_waits) || busy || self.ui.auto_rotate {
            ui.ctx().request_repaint();
        } else {
            self.pacing.idle();
        }
    }
}

/// The scene the viewer opens with when none is given or stored: the chapter's figure.
pub fn default_scene() -> Scene {
    Scene::example("fig-3-9-left")
        .unwrap_or_else(|| Scene::from_formula("x^2 + y^2 + z^2 + w^2 - 1"))
}
