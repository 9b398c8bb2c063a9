//! The web page's entry: the same viewer as `fourfold view`, started in a canvas and drawn
//! with the browser's WebGPU, and the page's state for its scripts. Everything else lives in
//! the `fourfold-viewer` and `fourfold` crates; `web/build.sh` turns this crate into
//! `web/dist/`. (Compiled for the browser only: natively this crate is empty.)

#![cfg(target_arch = "wasm32")]

mod recovery;

use std::cell::RefCell;

use eframe::egui;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

use fourfold::scene::Scene;
use fourfold_viewer::FourfoldApp;
use fourfold_viewer::app::default_scene;
use fourfold_viewer::notice::Notice;
use fourfold_viewer::platform::{open_link, split_embed};

/// What the page says when the browser has no WebGPU (index.html says it first, before the
/// download; this is for a browser that has `navigator.gpu` but no adapter).
const NO_WEBGPU: &str = "fourfold draws with WebGPU, and this browser did not give it a GPU \
     adapter. Use a browser with WebGPU enabled: Chrome or Edge 113+, Safari 26+, or Firefox \
     141+ on Windows; on Linux, Chrome with chrome://flags/#enable-unsafe-webgpu.";

thread_local! {
    /// The running viewer: dropping it would stop the page.
    static RUNNER: RefCell<Option<eframe::WebRunner>> = const { RefCell::new(None) };
}

/// The viewer as the page runs it: eframe finds it again for [`status`] through `Any`.
struct Page(FourfoldApp);

impl eframe::App for Page {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.0.ui(ui, frame);
    }

    fn as_any_mut(&mut self) -> Option<&mut dyn std::any::Any> {
        Some(self)
    }

    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        self.0.clear_color(visuals)
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.0.save(storage);
    }
}

/// Starts the viewer in the canvas with id `canvas_id`, on the scene of the page's link (or
/// the last scene, or the default one); rejects with a message a person can act on when the
/// browser cannot run it.
#[wasm_bindgen]
pub async fn start(canvas_id: String) -> Result<(), JsValue> {
    // The library reports what the GPU rejected to the log: the browser's console.
    let _ = eframe::WebLogger::init(log::LevelFilter::Warn);
    let window = web_sys::window().ok_or("fourfold needs a browser window")?;
    let document = window.document().ok_or("fourfold needs a document")?;
    let canvas = document
        .get_element_by_id(&canvas_id)
        .ok_or_else(|| format!("the page has no element with id `{canvas_id}`"))?
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|_| format!("`{canvas_id}` is not a canvas"))?;
    let hash = window.location().hash().unwrap_or_default();
    // `#embed&…` shows the picture alone (an iframe); the rest is the scene's link.
    let (_, link) = split_embed(&hash);
    let linked = fourfold::scene::link::is_link(&link).then(|| open_link(&link, &default_scene()));
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
                let (scene, notice) = match linked {
                    Some((scene, notice)) => (Some(scene), notice),
                    None => (None, None),
                };
                let from_link = scene.is_some();
                let mut app = FourfoldApp::new(cc, scene);
                // A link shows the view it carries, as its sender saw it.
                app.fit_pending = !from_link;
                if app.gpu().is_none() {
                    return Err(NO_WEBGPU.into());
                }
                if let Some(state) = &cc.wgpu_render_state {
                    recovery::restart_when_lost(&state.device, current_link);
                }
                app.message = match (recovery::restarted_after_loss(), notice) {
                    (Some(lost), Some(notice)) => {
                        Some(Notice::error(format!("{lost}; {}", notice.text)))
                    }
                    (Some(lost), None) => Some(Notice::error(lost)),
                    (None, notice) => notice,
                };
                app.platform.opened_with(hash);
                Ok(Box::new(Page(app)))
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

/// The address's fragment that reopens the scene on screen (and keeps embed mode).
fn current_link() -> Option<String> {
    RUNNER.with(|runner| {
        let runner = runner.try_borrow().ok()?;
        let page = runner.as_ref()?.app_mut::<Page>()?;
        let embed = if page.0.platform.embedded() {
            "embed&"
        } else {
            ""
        };
        Some(format!("#{embed}{}", page.0.session.link_fragment()))
    })
}

/// The page's state for scripts and tests, as JSON: the picture's generation and when its
/// first frame was drawn, the last edit's latency and its stages, the editor's text, the
/// formula on screen and the example it is (if one), the error shown, whether a build runs
/// or the picture is still being drawn, whether it is drawn certified and its verdicts'
/// counts once they are in, how far the picture is (its stage, squares, share of stages
/// done and rays per millisecond), the UI's frame time, where the editor, the controls' panel and the picture are (CSS pixels), the slice's
/// place and its critical values with where their ticks are, the gallery (open, its
/// button, pictures drawn, where each example's name is), and a panic if one happened.
#[wasm_bindgen]
pub fn status() -> String {
    RUNNER.with(|runner| {
        let runner = runner.borrow();
        let Some(runner) = runner.as_ref() else {
            return serde_json::json!({ "started": false }).to_string();
        };
        let panic = runner.panic_summary().map(|p| p.message());
        let Some(page) = runner.app_mut::<Page>() else {
            return serde_json::json!({ "started": true, "panic": panic }).to_string();
        };
        let app = &page.0;
        let times = &app.session.times;
        let rect = |r: Option<egui::Rect>| r.map(|r| [r.min.x, r.min.y, r.max.x, r.max.y]);
        let critical = app.session.program.as_ref().and_then(|program| {
            let report = app
                .critical
                .report(&program.formula, &app.session.scene)?
                .ok()?;
            let points: Vec<_> = report
                .points
                .iter()
                .map(|p| {
                    serde_json::json!({
                        "value": [p.value.lo(), p.value.hi()],
                        "index": p.index,
                        "status": p.status,
                    })
                })
                .collect();
            Some(points)
        });
        serde_json::json!({
            "started": true,
            "panic": panic,
            "generation": app.session.picture_generation,
            "first_frame_of": app.progressive.first_frame_of,
            "edit_latency_ms": app.edit_latency_ms,
            "edit_stages_ms": {
                "compile": times.compile_ms,
                "codegen": times.codegen_ms,
                "tree": times.tree_ms,
                "pipeline": times.pipeline_ms,
                "ready": times.ready_ms,
            },
            "text": app.session.text,
            "formula": app.session.scene.formula,
            "preset": app.preset,
            "error": app.session.error,
            "building": app.session.building(),
            "pipelines": app.session.counters.pipelines,
            "notice": app.message.as_ref().map(|m| m.text.clone()),
            "drawing": app.drawing,
            "certified": app.session.scene.render.certified,
            "verdicts": app.progressive.verdicts.map(|c| serde_json::json!({
                "hit": c.hit,
                "empty": c.empty,
                "undecided": c.undecided,
            })),
            "ui_frame_ms": app.pacing.ui_frame_ms,
            "progress": {
                "stage": app.progressive.position().0,
                "square": app.progressive.position().1,
                "fraction": app.progressive.fraction(),
                "rays_per_ms": app.progressive.throughput(),
                "preview_ms": app.progressive.preview_ms,
                "cpu_previews": app.progressive.cpu_previews.drawn,
            },
            "editor": rect(app.editor_rect),
            "controls": rect(app.controls_rect),
            "picture": rect(app.picture_rect),
            "link": app.share_link(),
            "slice": app.session.scene.view.slice,
            "critical": critical,
            "critical_strip": rect(app.critical_strip_rect),
            "mesh_button": rect(app.platform.mesh_button),
            "animation_header": rect(app.platform.animation_header),
            "animation_button": rect(app.platform.animation_button),
            "embed": app.platform.embedded(),
            "embed_link": rect(app.embed_link_rect),
            "gallery": {
                "open": app.gallery.open,
                "button": rect(app.gallery.button),
                "pictures": app.gallery.made(),
                "names": app.gallery.names.iter().map(|(n, r)| (n, rect(Some(*r)))).collect::<Vec<_>>(),
            },
        })
        .to_string()
    })
}

/// Every example scene as `[name, link fragment]`, as JSON (for the page's tests).
#[wasm_bindgen]
pub fn example_links() -> String {
    let links: Vec<(&str, String)> = fourfold::scene::EXAMPLES
        .iter()
        .filter_map(|(name, _)| Some((*name, Scene::example(name)?.to_link())))
        .collect();
    serde_json::to_string(&links).unwrap_or_default()
}
