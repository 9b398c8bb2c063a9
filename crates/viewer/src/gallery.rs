//! The gallery: every example scene as a small picture with its name and explanation line.
//! The pictures are rendered once, framed, on a GPU device of their own in the background,
//! and kept as textures for the rest of the session.

use std::sync::mpsc::{Receiver, TryRecvError, channel};

use eframe::egui;

use fourfold::CompiledFormula;
use fourfold::headless::render_prepared;
use fourfold::render::view::framing;
use fourfold::render::{Device, FrameOptions, Gpu, Prepared};
use fourfold::scene::{EXAMPLES, Scene};

/// The side of a gallery picture, in pixels.
const THUMB: u32 = 120;
/// Rays per pixel of a gallery picture: enough for a small picture, quick on a software GPU.
const THUMB_RAYS: u32 = 8;

/// A gallery picture: RGBA8 rows of THUMB² pixels, or why it could not be made.
type Thumbnail = Result<Vec<u8>, String>;

/// The example scenes' pictures, made once.
#[derive(Default)]
pub struct Gallery {
    /// Per example (in [`EXAMPLES`]' order): its texture once rendered, or the reason it
    /// was not.
    pictures: Vec<Option<Result<egui::TextureHandle, String>>>,
    rendering: Option<Receiver<(usize, Thumbnail)>>,
}

impl Gallery {
    /// Starts rendering the pictures, the first time only.
    fn start(&mut self) {
        if !self.pictures.is_empty() {
            return;
        }
        self.pictures = EXAMPLES.iter().map(|_| None).collect();
        let (tx, rx) = channel();
        self.rendering = Some(rx);
        std::thread::spawn(move || {
            let gpu = Gpu::new().map_err(|e| e.to_string());
            for (i, (name, _)) in EXAMPLES.iter().enumerate() {
                let picture = match &gpu {
                    Ok(gpu) => thumbnail(gpu, name),
                    Err(e) => Err(e.clone()),
                };
                if tx.send((i, picture)).is_err() {
                    return;
                }
            }
        });
    }

    /// Takes the pictures rendered since the last frame.
    fn poll(&mut self, ctx: &egui::Context) {
        let Some(rx) = &self.rendering else { return };
        loop {
            match rx.try_recv() {
                Ok((i, picture)) => {
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
                Err(TryRecvError::Empty) => return,
                Err(TryRecvError::Disconnected) => {
                    self.rendering = None;
                    return;
                }
            }
        }
    }

    /// Whether pictures are still being made.
    pub fn busy(&self) -> bool {
        self.rendering.is_some()
    }

    /// Shows the gallery's window while `open`; returns the example the user picked.
    pub fn show(&mut self, ctx: &egui::Context, open: &mut bool) -> Option<&'static str> {
        if !*open {
            return None;
        }
        self.start();
        self.poll(ctx);
        let mut picked = None;
        egui::Window::new("Gallery")
            .open(open)
            .default_size([4.0 * (THUMB as f32 + 24.0), 520.0])
            .scroll([false, true])
            .show(ctx, |ui| {
                ui.label("Click a picture to open its scene.");
                egui::Grid::new("gallery grid")
                    .spacing([12.0, 12.0])
                    .show(ui, |ui| {
                        for (i, (name, text)) in EXAMPLES.iter().enumerate() {
                            if self.cell(ui, i, name, text) {
                                picked = Some(*name);
                            }
                            if i % 4 == 3 {
                                ui.end_row();
                            }
                        }
                    });
            });
        picked
    }

    /// One example: its picture, name and explanation; true when clicked.
    fn cell(&self, ui: &mut egui::Ui, i: usize, name: &'static str, text: &str) -> bool {
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
            let name_clicked = ui.link(egui::RichText::new(name).strong()).clicked();
            ui.label(egui::RichText::new(description).small());
            clicked || name_clicked
        })
        .inner
    }
}

/// The example `name` rendered at THUMB² with few rays, framed as the viewer frames it.
fn thumbnail(gpu: &Gpu, name: &str) -> Thumbnail {
    let mut scene = Scene::example(name).ok_or_else(|| format!("no example {name}"))?;
    scene.render.rays = scene.render.rays.min(THUMB_RAYS);
    let formula = CompiledFormula::compile(&scene.formula)
        .map_err(|e| e.render("formula", &scene.formula))?;
    let prepared = Prepared::new(&formula, &scene).map_err(|e| e.to_string())?;
    framing::fit_scene(&mut scene, &prepared.hierarchy, THUMB, THUMB);
    let picture = render_prepared(
        &scene,
        &formula,
        &prepared,
        THUMB,
        THUMB,
        Device::Gpu(gpu),
        FrameOptions::default(),
    )
    .map_err(|e| e.to_string())?;
    Ok(picture.rgba)
}
