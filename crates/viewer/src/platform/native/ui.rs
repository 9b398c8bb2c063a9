//! The desktop's part of the window: the exports running beside it.

use eframe::egui;

use crate::outcome::{Outcome, Window};

use super::{animation, files};

/// Whether the window offers an embed code: only a page has an address an iframe can show.
pub const EMBEDS: bool = false;

/// The share link's page, relative: the desktop has no address of its own.
pub fn page_address() -> String {
    "index.html".to_string()
}

/// The desktop's part of the window: the exports running beside it.
#[derive(Default)]
pub struct State {
    png: Option<files::Export>,
    mesh: Option<files::Export>,
    animation: Option<animation::AnimationExport>,
}

impl State {
    /// Whether the window shows the picture alone: a web page's embed mode, never here.
    pub fn embedded(&self) -> bool {
        false
    }

    /// Whether something runs in the background that the window should keep polling.
    pub fn busy(&self) -> bool {
        self.png.is_some() || self.mesh.is_some() || self.animation.is_some()
    }
}

/// The sections of the controls that only the desktop has: "Export animation" (drawn on a
/// thread of its own).
pub fn sections(state: &mut State, ui: &mut egui::Ui, window: Window<'_>) -> Outcome {
    egui::CollapsingHeader::new(egui::RichText::new("Export animation").heading())
        .id_salt("fourfold animation")
        .show(ui, |ui| {
            animation::section(&mut state.animation, ui, window)
        })
        .body_returned
        .unwrap_or_default()
}

/// Open, save and export, with paths typed in.
pub fn file_actions(state: &mut State, ui: &mut egui::Ui, window: Window<'_>) -> Outcome {
    files::actions(&mut state.png, &mut state.mesh, ui, window)
}

/// At the end of each frame: the exports' outcomes.
pub fn end_frame(state: &mut State, _ctx: &egui::Context, _window: Window<'_>) -> Outcome {
    let mut outcome = Outcome::default();
    for export in [&mut state.png, &mut state.mesh] {
        if let Some(notice) = export.as_ref().and_then(files::Export::poll) {
            outcome.notice = Some(notice);
            *export = None;
        }
    }
    let animation = state.animation.as_ref();
    if let Some(notice) = animation.and_then(animation::AnimationExport::poll) {
        outcome.notice = Some(notice);
        state.animation = None;
    }
    outcome
}
