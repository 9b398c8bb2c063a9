//! The page's part of the window: the share link kept in the address bar (and a link pasted
//! there opened), the PNG on its way back, what the page leaves out.

use eframe::egui;
use wasm_bindgen::prelude::*;
use web_time::{Duration, Instant};

use fourfold::scene::{PAGE_LINK_BOUNDS, Scene};

use crate::notice::Notice;
use crate::outcome::{Outcome, Window};

use super::{animation, files};

/// The address bar is rewritten at most this often (browsers throttle faster rewrites).
const ADDRESS_EVERY: Duration = Duration::from_millis(500);

/// The page's part of the window: the scene file being uploaded, the PNG on its way back,
/// and the fragment last written into the address bar, and when.
#[derive(Default)]
pub struct State {
    upload: files::Upload,
    png: Option<files::PngDownload>,
    animation: Option<animation::AnimationDownload>,
    address: (String, Option<Instant>),
    /// Whether the page shows the picture alone (`#embed&…`: an iframe in a course page).
    embed: bool,
    /// Where "Export mesh", the "Export animation" section's header and its button were at
    /// the last frame (the page's tests click them).
    pub mesh_button: Option<egui::Rect>,
    pub animation_header: Option<egui::Rect>,
    pub animation_button: Option<egui::Rect>,
}

impl State {
    /// Whether something runs in the background that the window should keep polling.
    pub fn busy(&self) -> bool {
        self.png.is_some() || self.animation.is_some()
    }

    /// The address's fragment the page opened with (so that the first frame does not take
    /// it for a new link), and whether it asks for the picture alone.
    pub fn opened_with(&mut self, hash: String) {
        self.embed = split_embed(&hash).0;
        self.address.0 = hash;
    }

    /// Whether the page shows the picture alone, for an iframe (`#embed&…`).
    pub fn embedded(&self) -> bool {
        self.embed
    }
}

/// Whether a link asks for the picture alone (its `embed` key: `#embed&formula=…`), and the
/// link without that key (a scene's link: the key is the page's, not the scene's).
pub fn split_embed(hash: &str) -> (bool, String) {
    let fragment = hash.strip_prefix('#').unwrap_or(hash);
    let mut embed = false;
    let rest: Vec<&str> = fragment
        .split('&')
        .filter(|part| {
            let key = part.split('=').next().unwrap_or_default();
            embed |= key == "embed";
            key != "embed"
        })
        .collect();
    (embed, format!("#{}", rest.join("&")))
}

/// The page's own section: "Export animation" (a GIF download, drawn over the window's
/// frames).
pub fn sections(state: &mut State, ui: &mut egui::Ui, window: Window<'_>) -> Outcome {
    let section = egui::CollapsingHeader::new(egui::RichText::new("Export animation").heading())
        .id_salt("fourfold animation")
        .show(ui, |ui| {
            animation::section(
                &mut state.animation,
                &mut state.animation_button,
                ui,
                window,
            )
        });
    state.animation_header = Some(section.header_response.rect);
    section.body_returned.unwrap_or_default()
}

/// Open as an upload; save and export as downloads.
pub fn file_actions(state: &mut State, ui: &mut egui::Ui, window: Window<'_>) -> Outcome {
    files::actions(
        &mut state.upload,
        &mut state.png,
        &mut state.mesh_button,
        ui,
        window,
    )
}

/// At the end of each frame: the PNG's read-back, the animation's next frame, and the
/// address bar.
pub fn end_frame(state: &mut State, ctx: &egui::Context, window: Window<'_>) -> Outcome {
    let mut outcome = Outcome::default();
    let ended = [
        finished(
            &mut state.animation,
            animation::AnimationDownload::poll,
            ctx,
        ),
        finished(&mut state.png, files::PngDownload::poll, ctx),
    ];
    for notice in ended.into_iter().flatten() {
        outcome.notice = Some(notice);
    }
    outcome.and(sync_address(state, window))
}

/// The outcome of the work in `slot` once `poll` says it ended (the slot then emptied);
/// else asks for another frame to poll it in.
fn finished<T>(
    slot: &mut Option<T>,
    poll: impl FnOnce(&mut T) -> Option<Notice>,
    ctx: &egui::Context,
) -> Option<Notice> {
    let notice = poll(slot.as_mut()?);
    match notice {
        Some(_) => *slot = None,
        None => ctx.request_repaint(),
    }
    notice
}

/// Keeps the address bar a share link of the scene on screen, and opens a link typed or
/// pasted into it (the page does not reload when only its `#…` part changes).
fn sync_address(state: &mut State, window: Window<'_>) -> Outcome {
    let Some(page) = web_sys::window() else {
        return Outcome::default();
    };
    let hash = page.location().hash().unwrap_or_default();
    if hash != state.address.0 {
        let (embed, linked) = split_embed(&hash);
        if fourfold::scene::link::is_link(&linked) {
            state.address.0 = hash;
            state.embed = embed;
            let (scene, notice) = open_link(&linked, &window.session.scene);
            return Outcome {
                notice,
                open: Some((scene, false)),
                ..Outcome::default()
            };
        }
    }
    if state.address.1.is_some_and(|t| t.elapsed() < ADDRESS_EVERY) {
        return Outcome::default();
    }
    let embed = if state.embed { "embed&" } else { "" };
    let link = format!("#{embed}{}", window.session.link_fragment());
    if link == state.address.0 {
        return Outcome::default();
    }
    if let Ok(history) = page.history() {
        let _ = history.replace_state_with_url(&JsValue::NULL, "", Some(&link));
    }
    // As the browser spells it, so that it is not taken for a new link next frame.
    state.address = (page.location().hash().unwrap_or(link), Some(Instant::now()));
    Outcome::default()
}

/// Whether the window offers an embed code (Copy embed code): a page has an address.
pub const EMBEDS: bool = true;

/// The page's address without its `#…` part, for "Copy link".
pub fn page_address() -> String {
    web_sys::window()
        .and_then(|w| w.location().href().ok())
        .map(|href| href.split('#').next().unwrap_or_default().to_string())
        .unwrap_or_default()
}

/// The scene a share link opens in the page (`fallback`'s where it names no formula), within
/// the page's bounds on work (`PAGE_LINK_BOUNDS`), and the notice saying what of the link was
/// left out or lowered (None: nothing was).
pub fn open_link(hash: &str, fallback: &Scene) -> (Scene, Option<Notice>) {
    let (mut scene, mut problems) = Scene::from_link(hash, fallback);
    for refused in &mut problems {
        refused.message.push_str(" (left at the default)");
    }
    problems.extend(scene.bounded(&PAGE_LINK_BOUNDS));
    let said: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
    let notice = (!said.is_empty()).then(|| Notice::error(said.join("; ")));
    (scene, notice)
}
