//! What the platform's widgets see of the window, and what they ask of it: they read the
//! session, change the settings, and hand back a message and the scene to open, which the
//! window applies (so that the platform's code does not know the window's).

use fourfold::render::Gpu;
use fourfold::scene::Scene;

use crate::notice::Notice;
use crate::session::Session;
use crate::settings::UiSettings;

/// The window as the platform's widgets see it.
pub struct Window<'a> {
    pub session: &'a Session,
    pub settings: &'a mut UiSettings,
    pub gpu: Option<&'a Gpu>,
}

/// What the platform's widgets ask the window to do.
#[derive(Debug, Default)]
pub struct Outcome {
    /// A message for the status line.
    pub notice: Option<Notice>,
    /// A scene to open in place of the one on screen, and whether to frame it.
    pub open: Option<(Scene, bool)>,
    /// An example scene to open, by name.
    pub preset: Option<&'static str>,
}

impl Outcome {
    /// Only a message.
    pub fn said(notice: Notice) -> Self {
        Self {
            notice: Some(notice),
            ..Self::default()
        }
    }

    /// Adds what `other` asks (its message wins).
    pub fn and(mut self, other: Outcome) -> Self {
        self.notice = other.notice.or(self.notice);
        self.open = other.open.or(self.open);
        self.preset = other.preset.or(self.preset);
        self
    }
}
