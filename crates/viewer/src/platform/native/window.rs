//! The desktop's window: eframe's native runner on wgpu.

use eframe::egui;

use fourfold::scene::Scene;

use crate::app::FourfoldApp;

/// Opens the viewer window on `scene` (or the last scene, or the default one); `frame`
/// fits the picture to it once its tree is ready (a share link keeps its own view).
pub fn run(scene: Option<Scene>, frame: bool) -> Result<(), String> {
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
