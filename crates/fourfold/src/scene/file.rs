//! Scene files: TOML text to a checked scene, with every problem reported at its line (a
//! caret message), and back.

use std::path::Path;

use crate::syntax::SourceError;

use super::keys::{Speaker, locate};
use super::settings::Scene;

/// A scene file that could not be read, with its text for rendering the error.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{}", .error.render(.path, .text))]
    Invalid {
        path: String,
        text: String,
        error: Box<SourceError>,
    },
}

impl Scene {
    /// Parses scene text; `path` names it in errors.
    pub fn parse(text: &str, path: &str) -> Result<Self, SceneError> {
        let invalid = |error: SourceError| SceneError::Invalid {
            path: path.to_string(),
            text: text.to_string(),
            error: Box::new(error),
        };
        let scene: Scene = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            let message = e.message().to_string();
            let hint = if message.contains("unknown field") {
                Some("check the spelling against the keys the message lists")
            } else if message.contains("missing field `formula`") {
                Some("add a line such as formula = \"x^2 + y^2 + z^2 + w^2 = 1\"")
            } else {
                None
            };
            let mut error = SourceError::new(message, span, "here");
            if let Some(h) = hint {
                error = error.with_hint(h);
            }
            invalid(error)
        })?;
        scene.check().map_err(|problem| {
            let span = locate(text, &problem.key);
            invalid(SourceError::new(
                problem.message(Speaker::File),
                span,
                "here",
            ))
        })?;
        Ok(scene)
    }

    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text, &path.display().to_string())
    }

    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).expect("a scene always serialises")
    }
}
