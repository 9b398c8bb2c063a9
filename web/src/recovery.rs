//! A lost GPU device (the browser's `device.lost`: a driver reset, a watchdog, the tab
//! moved to another GPU) is recovered by restarting the page on the scene on screen, whose
//! share link is kept in the address. The restarted page says what happened; a device lost
//! again soon after is not restarted in a loop but said, with what to do.

use eframe::wgpu;
use wasm_bindgen::JsCast;
use web_time::{SystemTime, UNIX_EPOCH};

/// Where the page keeps, for its next start, when and why the device was lost.
const LOST_KEY: &str = "fourfold-device-lost";
/// A device lost again within this long of a restart is not restarted again.
const AGAIN_WITHIN_MS: f64 = 30_000.0;

/// Restarts the page when `device` is lost; `link` gives the address's fragment that
/// reopens the scene on screen (None: leave the address as it is).
pub fn restart_when_lost(device: &wgpu::Device, link: fn() -> Option<String>) {
    device.set_device_lost_callback(move |reason, message| {
        let why = if message.is_empty() {
            format!("{reason:?}")
        } else {
            format!("{reason:?}: {message}")
        };
        restart(&why, link());
    });
}

/// What the page says at its start when it was restarted after a lost device, if it was
/// (a reload by hand a while later is not such a restart).
pub fn restarted_after_loss() -> Option<String> {
    let (at, why) = last_loss()?;
    if now_ms() - at > AGAIN_WITHIN_MS {
        return None;
    }
    Some(format!(
        "the GPU device was lost ({why}); the page restarted on the scene you had"
    ))
}

/// Saves when and why, puts the scene's link in the address and reloads the page; or, when
/// the device was lost again soon after a restart, says so instead.
fn restart(why: &str, link: Option<String>) {
    let Some(window) = web_sys::window() else {
        return;
    };
    let now = now_ms();
    if last_loss().is_some_and(|(at, _)| now - at < AGAIN_WITHIN_MS) {
        say(&format!(
            "The GPU device was lost again ({why}).\nReload the page to try once more: the \
             scene is kept in its address. If it keeps happening, lower the rays or the \
             tree's levels in the link, or use another browser."
        ));
        return;
    }
    if let Ok(Some(storage)) = window.session_storage() {
        let _ = storage.set_item(LOST_KEY, &format!("{now} {why}"));
    }
    if let (Some(link), Ok(history)) = (link, window.history()) {
        let _ = history.replace_state_with_url(&wasm_bindgen::JsValue::NULL, "", Some(&link));
    }
    if window.location().reload().is_err() {
        say(&format!(
            "The GPU device was lost ({why}).\nReload the page: the scene is kept in its address."
        ));
    }
}

/// When (ms since the epoch) and why the device was last lost, as this tab remembers it.
fn last_loss() -> Option<(f64, String)> {
    let storage = web_sys::window()?.session_storage().ok()??;
    let saved = storage.get_item(LOST_KEY).ok()??;
    let (at, why) = saved.split_once(' ')?;
    Some((at.parse().ok()?, why.to_string()))
}

fn now_ms() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64() * 1e3)
        .unwrap_or_default()
}

/// Shows `text` over the page (index.html's message), as an error.
fn say(text: &str) {
    let element = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id("message"))
        .and_then(|e| e.dyn_into::<web_sys::HtmlElement>().ok());
    if let Some(element) = element {
        element.set_text_content(Some(text));
        element.set_class_name("error");
        element.set_hidden(false);
    }
}
