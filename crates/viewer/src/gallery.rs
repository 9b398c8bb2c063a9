//! The gallery: every example scene as a small picture with its name and explanation line.
//! The pictures are made once, framed, by the platform's `Thumbnails` (natively on a thread
//! and a GPU device of their own, in a page over the window's frames on its device), and
//! kept as textures for the rest of the session.

use std::sync::Arc;

use eframe::egui;

use fourfold::CompiledFormula;
use fourfold::render::view::framing;
use fourfold::render::{Device, FrameOptions, Gpu, Painter, PendingPicture, Prepared, shader};
use fourfold::scene::{EXAMPLES, Scene};

use crate::platform::Thumbnails;

/// The side of a gallery picture, in pixels.
pub const THUMB: u32 = 120;
/// Rays per pixel of a gallery picture: enough for a small picture, quick on a software GPU.
const THUMB_RAYS: u32 = 8;

/// A gallery picture: RGBA8 rows of THUMB² pixels, or why it could not be made.
pub type Thumbnail = Result<Vec<u8>, String>;

/// The example scenes' pictures, made once, and whether the gallery's window is open.
#[derive(Default)]
pub struct Gallery {
    /// Per example (in [`EXAMPLES`]' order): its texture once rendered, or the reason it
    /// was not.
    pictures: Vec<Option<Result<egui::TextureHandle, String>>>,
    making: Option<Thumbnails>,
    pub open: bool,
    /// Where the Gallery button and each example's name were at the last frame (the page's
    /// tests click them).
    pub button: Option<egui::Rect>,
    pub names: Vec<(&'static str, egui::Rect)>,
}

impl Gallery {
    /// Starts making the pictures, the first time only.
    fn start(&mut self, gpu: Option<&Gpu>) {
        if !self.pictures.is_empty() {
            return;
        }
        self.pictures = EXAMPLES.iter().map(|_| None).collect();
        self.making = Some(Thumbnails::start(gpu));
    }

    /// Takes the pictures made since the last frame.
    fn poll(&mut self, ctx: &egui::Context, gpu: Option<&Gpu>) {
        let Some(making) = &mut self.making else {
            return;
        };
        let (made, done) = making.poll(gpu);
        for (i, picture) in made {
            let texture = picture.map(|rgba| {
                let size = [THUMB as usize, THUMB as usize];
                let image = egui::ColorImage::from_rgba_unmultiplied(size, &rgba);
                ctx.load_texture(
                    format!("gallery {}", EXAMPLES[i].0),
                    image,
                    egui::TextureOptions::LINEAR,
                )
            });
            self.pictures[i] = Some(texture);
        }
        if done {
            self.making = None;
        }
    }

    /// Whether pictures are still being made while the window is open.
    pub fn busy(&self) -> bool {
        self.open && self.making.is_some()
    }

    /// How many pictures are drawn so far (the page's tests wait for one).
    pub fn made(&self) -> usize {
        self.pictures
            .iter()
            .filter(|p| matches!(p, Some(Ok(_))))
            .count()
    }

    /// Shows the gallery's window while it is open; returns the example the user picked
    /// (and closes the window then).
    pub fn show(&mut self, ctx: &egui::Context, gpu: Option<&Gpu>) -> Option<&'static str> {
        if !self.open {
            return None;
        }
        self.start(gpu);
        self.poll(ctx, gpu);
        let mut picked = None;
        let mut open = true;
        self.names.clear();
        egui::Window::new("Gallery")
            .open(&mut open)
            .default_size([4.0 * (THUMB as f32 + 24.0), 520.0])
            .scroll([false, true])
            .show(ctx, |ui| {
                ui.label("Click a picture to open its scene.");
                egui::Grid::new("gallery grid")
                    .spacing([12.0, 12.0])
                    .show(ui, |ui| {
                        for (i, (name, text)) in EXAMPLES.iter().enumerate() {
                            let (clicked, at) = self.cell(ui, i, name, text);
                            if clicked {
                                picked = Some(*name);
                            }
                            self.names.push((name, at));
                            if i % 4 == 3 {
                                ui.end_row();
                            }
                        }
                    });
            });
        self.open = open && picked.is_none();
        picked
    }

    /// One example: its picture, name and explanation; whether it was clicked, and where
    /// its name is.
    fn cell(
        &self,
        ui: &mut egui::Ui,
        i: usize,
        name: &'static str,
        text: &str,
    ) -> (bool, egui::Rect) {
        let side = THUMB as f32;
        let description = Scene::parse(text, name)
            .map(|s| s.description)
            .unwrap_or_default();
        ui.vertical(|ui| {
            ui.set_width(side);
            let clicked = match self.pictures.get(i) {
                Some(Some(Ok(texture))) => ui
                    .add(egui::Button::image(egui::Image::new((
                        texture.id(),
                        egui::vec2(side, side),
                    ))))
                    .on_hover_text(format!("open {name}"))
                    .clicked(),
                Some(Some(Err(e))) => {
                    ui.label(egui::RichText::new(format!("no picture: {e}")).small());
                    false
                }
                _ => {
                    ui.add_sized([side, side], egui::Spinner::new());
                    false
                }
            };
            let link = ui.link(egui::RichText::new(name).strong());
            ui.label(egui::RichText::new(description).small());
            (clicked || link.clicked(), link.rect)
        })
        .inner
    }
}

/// The example `name` as its gallery picture draws it (few rays, plain: a thumbnail is an
/// index of the examples, and the scene it opens settles on a proved picture), and its
/// formula.
pub fn thumbnail_job(name: &str) -> Result<(Scene, Arc<CompiledFormula>), String> {
    let mut scene = Scene::example(name).ok_or_else(|| format!("no example {name}"))?;
    scene.render.rays = scene.render.rays.min(THUMB_RAYS);
    scene.render.certified = false;
    let formula = CompiledFormula::compile(&scene.formula)
        .map_err(|e| e.render("formula", &scene.formula))?;
    Ok((scene, Arc::new(formula)))
}

/// Frames `scene` on its tree as the viewer frames a scene it opens, and starts its
/// THUMB² picture on `gpu`: the painter (keep it until the picture is back) and the
/// picture on its way.
pub fn start_thumbnail(
    gpu: &Gpu,
    mut scene: Scene,
    formula: &CompiledFormula,
    prepared: &Prepared,
) -> Result<(Painter, PendingPicture), String> {
    framing::fit_scene(&mut scene, &prepared.hierarchy, THUMB, THUMB);
    let shader = shader::generate(formula).map_err(|e| e.to_string())?;
    let mut painter = Painter::new(Device::Gpu(gpu), &shader, &prepared.hierarchy, &scene)
        .map_err(|e| e.to_string())?;
    let source = prepared.source(formula, scene.render.certified);
    let pending = painter
        .start(source, &scene, [THUMB, THUMB], FrameOptions::default())
        .map_err(|e| e.to_string())?;
    Ok((painter, pending))
}
