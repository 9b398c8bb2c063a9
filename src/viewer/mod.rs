//! The live viewer (eframe + wgpu): type a formula, see the manifold, rotate it in 4D.
//! `session` holds what is drawn, `progressive` how it reaches the screen without blocking
//! the window, `pacing` how much of each UI frame it may take, `files` the file actions,
//! `history` undo and redo, `gallery` the example scenes as pictures, and `app` the widgets. The picture is made by the same ray caster as
//! `fourfold render`.

pub mod app;
mod blit;
pub mod files;
pub mod gallery;
pub mod history;
pub mod pacing;
pub mod progressive;
pub mod session;

pub use app::FourfoldApp;
pub use session::Session;

#[cfg(target_arch = "wasm32")]
pub mod web;

/// Whether this viewer draws certified pixels (docs/method.md §5.9). Not in the browser yet:
/// Chromium on SwiftShader compiles the certified shader for longer than its GPU watchdog
/// allows and loses the page, so a web scene that asks for them is drawn plain, with a
/// notice (`web::certified_left_off`).
pub const CERTIFIED_PIXELS: bool = cfg!(not(target_arch = "wasm32"));

/// Opens the viewer window on `scene` (or the last scene, or the default one); `frame`
/// fits the picture to it once its tree is ready (a share link keeps its own view).
#[cfg(not(target_arch = "wasm32"))]
pub fn run(scene: Option<crate::scene::Scene>, frame: bool) -> Result<(), String> {
    use eframe::egui;
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("fourfold")
            .with_inner_size([1280.0, 800.0]),
        renderer: eframe::Renderer::Wgpu,
        // Dithering costs a noise function per pixel of the window: on a software GPU that
        // is a visible share of each UI frame, and the picture has no banding to hide.
        dithering: false,
        ..Default::default()
    };
    eframe::run_native(
        "fourfold",
        options,
        Box::new(move |cc| {
            let mut app = FourfoldApp::new(cc, scene);
            app.fit_pending = frame;
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| {
        format!(
            "the viewer window could not open: {e}\n(it needs a display and a GPU driver; on Linux \
             without a GPU: apt-get install -y mesa-vulkan-drivers; headless: use `fourfold render`)"
        )
    })
}
