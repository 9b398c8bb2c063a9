//! The web page's file actions: "Open…" as an upload, scene and shader as downloads, a PNG
//! drawn on the page's own GPU, read back over the next frames (a page cannot wait for the
//! GPU), then downloaded, and the slice's mesh as an STL download.

use std::cell::RefCell;
use std::rc::Rc;

use eframe::egui;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

use fourfold::mesh::MeshFormat;
use fourfold::render::{Device, FrameOptions, Gpu, Painter, PendingPicture, Source};
use fourfold::scene::Scene;

use crate::notice::Notice;
use crate::outcome::{Outcome, Window};
use crate::session::Session;
use crate::settings::export_size_fields;

/// The level of the page's slice meshes: one coarser than the desktop's, since the page
/// meshes on its one thread while the window waits.
const MESH_LEVEL: u32 = fourfold::scene::limits::DEFAULT_MESH_LEVEL - 1;

/// Open as an upload; save and export as downloads; `png` is the PNG on its way back,
/// `mesh_button` where "Export mesh" is drawn.
pub fn actions(
    upload: &mut Upload,
    png: &mut Option<PngDownload>,
    mesh_button: &mut Option<egui::Rect>,
    ui: &mut egui::Ui,
    window: Window<'_>,
) -> Outcome {
    let Window {
        session,
        settings,
        gpu,
    } = window;
    let mut outcome = Outcome::default();
    ui.separator();
    if ui
        .button("Open…")
        .on_hover_text("a scene file (.toml)")
        .clicked()
        && let Err(e) = upload.choose(".toml,text/plain", ui.ctx())
    {
        outcome = Outcome::said(Notice::error(e));
    }
    match upload.take() {
        Some(Ok((name, text))) => {
            outcome = match Scene::parse(&text, &name) {
                Ok(scene) => Outcome {
                    open: Some((scene, true)),
                    ..Outcome::said(Notice::done(format!("opened {name}")))
                },
                Err(e) => Outcome::said(Notice::error(e.to_string())),
            }
        }
        Some(Err(e)) => outcome = Outcome::said(Notice::error(e)),
        None => {}
    }
    if ui.button("Save scene").clicked() {
        let toml = session.scene.to_toml();
        outcome = Outcome::said(
            match download("scene.toml", "application/toml", toml.as_bytes()) {
                Ok(()) => Notice::done("scene.toml downloaded"),
                Err(e) => Notice::error(e),
            },
        );
    }
    export_size_fields(ui, &mut settings.export_size);
    if ui
        .add_enabled(png.is_none(), egui::Button::new("Export PNG"))
        .clicked()
    {
        outcome = Outcome::said(
            match PngDownload::start(session, gpu, settings.export_size) {
                Ok(download) => {
                    *png = Some(download);
                    Notice::done("drawing the PNG…")
                }
                Err(e) => Notice::error(e),
            },
        );
    }
    let slicing = session.scene.view.slice.is_some();
    let button = ui
        .add_enabled(slicing, egui::Button::new("Export mesh"))
        .on_hover_text("the slice shown, as a closed STL mesh in the slice's own units")
        .on_disabled_hover_text("choose \"slice\" in the view to export its mesh");
    *mesh_button = Some(button.rect);
    if button.clicked() {
        let name = "fourfold-slice.stl";
        let made = crate::export::mesh_job(session).and_then(|(formula, scene)| {
            crate::export::slice_mesh(&formula, &scene, MESH_LEVEL, MeshFormat::Stl)
        });
        outcome = Outcome::said(match made {
            Ok((bytes, said)) => match download(name, "model/stl", &bytes) {
                Ok(()) => Notice::done(format!("{name} downloaded: {said}")),
                Err(e) => Notice::error(e),
            },
            Err(e) => Notice::error(e),
        });
    }
    if ui.button("Export WGSL").clicked() {
        outcome = Outcome::said(match &session.program {
            Some(program) => {
                match download(
                    "fourfold.wgsl",
                    "text/plain",
                    program.shader.source.as_bytes(),
                ) {
                    Ok(()) => Notice::done("fourfold.wgsl downloaded"),
                    Err(e) => Notice::error(e),
                }
            }
            None => Notice::error("no valid shader yet"),
        });
    }
    ui.separator();
    outcome
}

/// A PNG of the scene on screen, drawn at its own size on the page's GPU and read back over
/// the next frames, then handed over as a download.
pub struct PngDownload {
    pending: PendingPicture,
    /// Kept until the read-back is done: the frame was drawn with its pipelines.
    _painter: Painter,
}

impl PngDownload {
    /// Draws the session's scene at the export size with a painter of its own (the
    /// viewer's ray caster keeps its tile lists for the picture on screen).
    pub fn start(s: &Session, gpu: Option<&Gpu>, size: [u32; 2]) -> Result<Self, String> {
        let (Some(gpu), Some(program), Some(hierarchy), Some(stats)) =
            (gpu, &s.program, &s.hierarchy, &s.stats)
        else {
            return Err("no picture yet: wait for the tree to be built".into());
        };
        let source = Source {
            formula: &program.formula,
            params: &s.tree_params,
            hierarchy,
            certifying: s.certifying.as_deref(),
            tree: stats,
            build_ms: 0.0,
        };
        let mut painter = Painter::new(Device::Gpu(gpu), &program.shader, hierarchy, &s.scene)
            .map_err(|e| e.to_string())?;
        let pending = painter
            .start(source, &s.scene, size, FrameOptions::default())
            .map_err(|e| e.to_string())?;
        Ok(Self {
            pending,
            _painter: painter,
        })
    }

    /// The outcome once the picture is back and downloaded, else None.
    pub fn poll(&mut self) -> Option<Notice> {
        let picture = match self.pending.poll()? {
            Ok(picture) => picture,
            Err(e) => return Some(Notice::error(e.to_string())),
        };
        let downloaded = picture
            .to_png()
            .and_then(|png| download("fourfold.png", "image/png", &png));
        Some(match downloaded {
            Ok(()) => crate::export::exported(&picture, "fourfold.png downloaded"),
            Err(e) => Notice::error(e),
        })
    }
}

/// Hands `bytes` to the browser as a download called `name`.
pub fn download(name: &str, mime: &str, bytes: &[u8]) -> Result<(), String> {
    let fail = |e: JsValue| format!("the browser refused the download: {e:?}");
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let options = web_sys::BlobPropertyBag::new();
    options.set_type(mime);
    let blob =
        web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(fail)?;
    let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(fail)?;
    let anchor = document
        .create_element("a")
        .map_err(fail)?
        .dyn_into::<web_sys::HtmlAnchorElement>()
        .map_err(|_| "no anchor element".to_string())?;
    anchor.set_href(&url);
    anchor.set_download(name);
    anchor.click();
    let _ = web_sys::Url::revoke_object_url(&url);
    Ok(())
}

/// A file the browser has read: its name and text, or why it could not.
pub type ReadFile = Result<(String, String), String>;

/// A file the user is choosing or the browser is reading: its name and text once read.
#[derive(Default, Clone)]
pub struct Upload {
    slot: Rc<RefCell<Option<ReadFile>>>,
}

impl Upload {
    /// Opens the browser's file chooser for `accept` (as `.toml`); the file's text arrives
    /// later, through [`Upload::take`].
    pub fn choose(&self, accept: &str, ctx: &egui::Context) -> Result<(), String> {
        let document = web_sys::window()
            .and_then(|w| w.document())
            .ok_or("no document")?;
        let input = document
            .create_element("input")
            .map_err(|e| format!("{e:?}"))?
            .dyn_into::<web_sys::HtmlInputElement>()
            .map_err(|_| "no file input".to_string())?;
        input.set_type("file");
        input.set_accept(accept);
        let (slot, ctx, chooser) = (self.slot.clone(), ctx.clone(), input.clone());
        let on_change = Closure::<dyn FnMut()>::new(move || {
            let Some(file) = chooser.files().and_then(|files| files.get(0)) else {
                return;
            };
            let (slot, ctx) = (slot.clone(), ctx.clone());
            wasm_bindgen_futures::spawn_local(async move {
                let name = file.name();
                let text = wasm_bindgen_futures::JsFuture::from(file.text())
                    .await
                    .ok()
                    .and_then(|t| t.as_string())
                    .ok_or_else(|| format!("the browser could not read {name}"));
                *slot.borrow_mut() = Some(text.map(|t| (name, t)));
                ctx.request_repaint();
            });
        });
        input.set_onchange(Some(on_change.as_ref().unchecked_ref()));
        // The input lives until the page ends; one per choice, and choices are few.
        on_change.forget();
        input.click();
        Ok(())
    }

    /// The file read since the last call, if any.
    pub fn take(&self) -> Option<ReadFile> {
        self.slot.borrow_mut().take()
    }
}
