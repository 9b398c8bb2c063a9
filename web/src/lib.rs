//! The web page's entry: the same viewer as `fourfold view`, in a canvas, drawn with the
//! browser's WebGPU. Everything it does lives in the `fourfold` library; `web/build.sh`
//! turns this crate into `web/dist/`.

#[cfg(target_arch = "wasm32")]
use wasm_bindgen::prelude::*;

/// Starts the viewer in the canvas with id `canvas_id`; rejects with a message a person can
/// act on when the browser cannot run it.
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen]
pub async fn start(canvas_id: String) -> Result<(), JsValue> {
    fourfold::viewer::web::start(&canvas_id).await
}

/// The page's state as JSON (see `fourfold::viewer::web::status`), for scripts and tests.
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen]
pub fn status() -> String {
    fourfold::viewer::web::status()
}

/// Every example scene as `[name, link fragment]`, as JSON.
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen]
pub fn example_links() -> String {
    fourfold::viewer::web::example_links()
}
