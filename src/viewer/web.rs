//! The web page's edge: starting the viewer in a canvas with the browser's WebGPU, the share
//! link in the address bar, and files as uploads and downloads. Everything else is the
//! desktop viewer's code.

use std::cell::RefCell;
use std::rc::Rc;

use eframe::egui;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;
use web_time::{Duration, Instant};

use super::FourfoldApp;
use super::app::default_scene;
use super::files::Notice;
use crate::scene::Scene;

/// What the page says when the browser has no WebGPU (index.html says it first, before the
/// download; this is for a browser that has `navigator.gpu` but no adapter).
const NO_WEBGPU: &str = "fourfold draws with WebGPU, and this browser did not give it a GPU \
     adapter. Use a browser with WebGPU enabled: Chrome or Edge 113+, Safari 26+, or Firefox \
     141+ on Windows; on Linux, Chrome with chrome://flags/#enable-unsafe-webgpu.";

/// The address bar is rewritten at most this often (browsers throttle faster rewrites).
const ADDRESS_EVERY: Duration = Duration::from_millis(500);

thread_local! {
    /// The running viewer: dropping it would stop the page.
    static RUNNER: RefCell<Option<eframe::WebRunner>> = const { RefCell::new(None) };
    /// The fragment the page last wrote into the address bar, and when.
    static ADDRESS: RefCell<(String, Option<Instant>)> = const { RefCell::new((String::new(), None)) };
}

/// Starts the viewer in the canvas with id `canvas_id`, on the scene of the page's link
/// (or the last scene, or the default one).
pub async fn start(canvas_id: &str) -> Result<(), JsValue> {
    let window = web_sys::window().ok_or("fourfold needs a browser window")?;
    let document = window.document().ok_or("fourfold needs a document")?;
    let canvas = document
        .get_element_by_id(canvas_id)
        .ok_or_else(|| format!("the page has no element with id `{canvas_id}`"))?
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|_| format!("`{canvas_id}` is not a canvas"))?;
    let hash = window.location().hash().unwrap_or_default();
    let linked = crate::scene::link::is_link(&hash).then(|| {
        let (scene, mut problems) = Scene::from_link(&hash, &default_scene());
        problems.extend(certified_left_off(&scene));
        (scene, problems)
    });
    let mut wgpu_options = eframe::egui_wgpu::WgpuConfiguration::default();
    if let eframe::egui_wgpu::WgpuSetup::CreateNew(setup) = &mut wgpu_options.wgpu_setup {
        // WebGL2 has no storage buffers, which the ray caster reads.
        setup.instance_descriptor.backends = eframe::wgpu::Backends::BROWSER_WEBGPU;
    }
    let options = eframe::WebOptions {
        wgpu_options,
        dithering: false,
        ..Default::default()
    };
    let runner = eframe::WebRunner::new();
    runner
        .start(
            canvas,
            options,
            Box::new(move |cc| {
                let (scene, problems) = match linked {
                    Some((scene, problems)) => (Some(scene), problems),
                    None => (None, Vec::new()),
                };
                let from_link = scene.is_some();
                let mut app = FourfoldApp::new(cc, scene);
                // A link shows the view it carries, as its sender saw it.
                app.fit_pending = !from_link;
                if app.gpu().is_none() {
                    return Err(NO_WEBGPU.into());
                }
                if !problems.is_empty() {
                    let said: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
                    app.message = Some(Notice::error(format!(
                        "{} (left at the default)",
                        said.join("; ")
                    )));
                }
                ADDRESS.with(|a| a.borrow_mut().0 = hash);
                Ok(Box::new(app))
            }),
        )
        .await
        .map_err(|e| {
            let detail = e.as_string().unwrap_or_else(|| format!("{e:?}"));
            JsValue::from_str(&format!("{NO_WEBGPU}\n({detail})"))
        })?;
    RUNNER.with(|r| *r.borrow_mut() = Some(runner));
    Ok(())
}

/// Keeps the address bar a share link of the scene on screen, and opens a link typed or
/// pasted into it (the page does not reload when only its `#…` part changes).
pub fn sync_address(app: &mut FourfoldApp) {
    let Some(window) = web_sys::window() else {
        return;
    };
    let hash = window.location().hash().unwrap_or_default();
    ADDRESS.with(|address| {
        let (written, at) = &mut *address.borrow_mut();
        if hash != *written && crate::scene::link::is_link(&hash) {
            *written = hash.clone();
            let (scene, mut problems) = Scene::from_link(&hash, &app.session.scene);
            problems.extend(certified_left_off(&scene));
            app.open(scene, false);
            if !problems.is_empty() {
                let said: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
                app.message = Some(Notice::error(said.join("; ")));
            }
            return;
        }
        if at.is_some_and(|t| t.elapsed() < ADDRESS_EVERY) {
            return;
        }
        let link = format!("#{}", app.link_fragment());
        if link == *written {
            return;
        }
        if let Ok(history) = window.history() {
            let _ = history.replace_state_with_url(&JsValue::NULL, "", Some(&link));
        }
        // As the browser spells it, so that it is not taken for a new link next frame.
        *written = window.location().hash().unwrap_or(link);
        *at = Some(Instant::now());
    });
}

/// The page's address without its `#…` part, for "Copy link".
pub fn page_address() -> String {
    web_sys::window()
        .and_then(|w| w.location().href().ok())
        .map(|href| href.split('#').next().unwrap_or_default().to_string())
        .unwrap_or_default()
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

/// The page's state for scripts and tests, as JSON: the picture's generation and when its
/// first frame was drawn, the last edit's latency and its stages, the editor's text, the formula on screen,
/// the error shown, whether a build runs or the picture is still being drawn, the UI's
/// frame time, where the
/// editor, the controls' panel and the picture are (CSS pixels), and a panic if one happened.
pub fn status() -> String {
    RUNNER.with(|runner| {
        let runner = runner.borrow();
        let Some(runner) = runner.as_ref() else {
            return serde_json::json!({ "started": false }).to_string();
        };
        let panic = runner.panic_summary().map(|p| p.message());
        let Some(app) = runner.app_mut::<FourfoldApp>() else {
            return serde_json::json!({ "started": true, "panic": panic }).to_string();
        };
        serde_json::json!({
            "started": true,
            "panic": panic,
            "generation": app.session.picture_generation,
            "first_frame_of": app.progressive.first_frame_of,
            "edit_latency_ms": app.edit_latency_ms,
            "edit_stages_ms": {
                "compile": app.session.times.compile_ms,
                "codegen": app.session.times.codegen_ms,
                "tree": app.session.times.tree_ms,
                "pipeline": app.session.times.pipeline_ms,
                "ready": app.session.times.ready_ms,
            },
            "text": app.session.text,
            "formula": app.session.scene.formula,
            "error": app.session.error,
            "building": app.session.building(),
            "notice": app.message.as_ref().map(|m| m.text.clone()),
            "drawing": app.drawing,
            "ui_frame_ms": app.pacing.ui_frame_ms,
            "editor": app.editor_rect.map(|r| [r.min.x, r.min.y, r.max.x, r.max.y]),
            "controls": app.controls_rect.map(|r| [r.min.x, r.min.y, r.max.x, r.max.y]),
            "picture": app.picture_rect.map(|r| [r.min.x, r.min.y, r.max.x, r.max.y]),
            "link": app.share_link(),
        })
        .to_string()
    })
}

/// Every example scene as `[name, link fragment]`, as JSON (for the page's tests).
pub fn example_links() -> String {
    let links: Vec<(&str, String)> = crate::scene::EXAMPLES
        .iter()
        .filter_map(|(name, _)| Some((*name, Scene::example(name)?.to_link())))
        .collect();
    serde_json::to_string(&links).unwrap_or_default()
}

/// A PNG of the scene on screen, drawn at its own size on the page's GPU and read back over
/// the next frames (a page cannot wait for the GPU), then handed over as a download.
pub struct PngDownload {
    pending: crate::render::gpu::PendingRgba,
    /// Kept until the read-back is done: the frame was drawn with it.
    _caster: crate::render::RayCaster,
    started: Instant,
}

impl PngDownload {
    /// Draws the session's scene at `width`×`height` with a ray caster of its own (the
    /// viewer's keeps its tile lists for the picture on screen).
    pub fn start(
        gpu: &crate::render::Gpu,
        session: &super::Session,
        [width, height]: [u32; 2],
    ) -> Result<Self, String> {
        use crate::render::{Camera, FrameOptions, RayCaster, Target, Uniforms};
        let (Some(hierarchy), Some(shader)) = (&session.hierarchy, &session.shader) else {
            return Err("no picture yet: wait for the tree to be built".into());
        };
        let scene = &session.scene;
        let mut caster = RayCaster::with_target(gpu, shader, hierarchy, Target::OFFSCREEN)
            .map_err(|e| e.to_string())?;
        let camera = Camera::new(&scene.domain, &scene.view, width, height);
        let uniforms = Uniforms::new(
            &camera,
            &scene.render,
            &scene.domain,
            hierarchy,
            &session.tree_params,
            FrameOptions::default(),
        );
        let certifying = session.certifying.as_deref();
        crate::render::pipeline::bin_view(
            gpu,
            &mut caster,
            hierarchy,
            certifying,
            &camera,
            &uniforms,
        );
        let pending = caster
            .start_rgba(gpu, &uniforms)
            .map_err(|e| e.to_string())?;
        Ok(Self {
            pending,
            _caster: caster,
            started: Instant::now(),
        })
    }

    /// The outcome once the picture is back and downloaded, else None.
    pub fn poll(&self, gpu: &crate::render::Gpu) -> Option<Notice> {
        let mut rgba = match self.pending.poll(gpu)? {
            Ok(rgba) => rgba,
            Err(e) => return Some(Notice::error(e.to_string())),
        };
        let [width, height] = self.pending.size();
        let cut = crate::render::pipeline::take_cut_pixels(&mut rgba).len();
        let mut png = Vec::new();
        let encoded = image::ImageEncoder::write_image(
            image::codecs::png::PngEncoder::new(&mut png),
            &rgba,
            width,
            height,
            image::ExtendedColorType::Rgba8,
        );
        if let Err(e) = encoded {
            return Some(Notice::error(format!("could not encode the PNG: {e}")));
        }
        let ms = self.started.elapsed().as_secs_f64() * 1e3;
        Some(match download("fourfold.png", "image/png", &png) {
            Ok(()) if cut > 0 => Notice::error(format!(
                "fourfold.png downloaded ({width}x{height}, {ms:.0} ms); the GPU cut {cut} \
                 pixels short: lower the rays or steps"
            )),
            Ok(()) => Notice::done(format!(
                "fourfold.png downloaded ({width}x{height}, {ms:.0} ms)"
            )),
            Err(e) => Notice::error(e),
        })
    }
}

/// What the page says of a linked scene that asks for certified pixels, which it draws plain
/// (see `viewer::CERTIFIED_PIXELS`).
fn certified_left_off(scene: &Scene) -> Option<crate::scene::LinkProblem> {
    scene.render.certified.then(|| crate::scene::LinkProblem {
        key: "render.certified".into(),
        message: "certified pixels are drawn by the desktop viewer and `fourfold render \
                  --certified`, not yet in the browser"
            .into(),
    })
}
