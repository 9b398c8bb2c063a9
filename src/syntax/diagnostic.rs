//! One way to show a problem in a formula: the formula, a caret line under the span, what
//! went wrong and, where one helps, a hint. Used by every stage that reports on user text.

use codespan_reporting::diagnostic::{Diagnostic, Label};
use codespan_reporting::files::SimpleFile;
use codespan_reporting::term::{self, Config};

use super::ast::Span;

/// A located problem in a formula (or in a scene file's text).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct SourceError {
    /// What went wrong, one line.
    pub message: String,
    /// Where, as a byte range of the source.
    pub span: Span,
    /// What the caret line says under the span.
    pub label: String,
    /// How to fix it, if we can tell.
    pub hint: Option<String>,
}

impl SourceError {
    pub fn new(message: impl Into<String>, span: Span, label: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            span,
            label: label.into(),
            hint: None,
        }
    }

    pub fn with_hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(hint.into());
        self
    }

    /// Renders the error with the source it points into, as plain text with a caret line.
    pub fn render(&self, source_name: &str, source: &str) -> String {
        let start = floor_char_boundary(source, self.span.start.min(source.len()));
        let end = floor_char_boundary(source, self.span.end.clamp(start, source.len()));
        // A long one-line formula is shown as a window around the problem.
        let (shown, start, end) = if source.len() > WINDOW * 3 && !source.contains('\n') {
            let from = floor_char_boundary(source, start.saturating_sub(WINDOW));
            let to = floor_char_boundary(source, (end.max(start + 1) + WINDOW).min(source.len()));
            let to = to.max(from);
            let prefix = if from > 0 { "…" } else { "" };
            let suffix = if to < source.len() { "…" } else { "" };
            let end = end.min(to);
            (
                format!("{prefix}{}{suffix}", &source[from..to]),
                start - from + prefix.len(),
                end - from + prefix.len(),
            )
        } else {
            (source.to_string(), start, end)
        };
        let file = SimpleFile::new(source_name, shown.as_str());
        let mut diagnostic = Diagnostic::error()
            .with_message(&self.message)
            .with_labels(vec![
                Label::primary((), start..end).with_message(&self.label),
            ]);
        if let Some(hint) = &self.hint {
            diagnostic = diagnostic.with_notes(vec![format!("hint: {hint}")]);
        }
        let config = Config::default();
        term::emit_into_string(&config, &file, &diagnostic)
            .unwrap_or_else(|_| format!("error: {} (at bytes {:?})", self.message, self.span))
    }
}

/// Characters shown on each side of the problem in a long formula.
const WINDOW: usize = 60;

fn floor_char_boundary(text: &str, mut index: usize) -> usize {
    while index > 0 && !text.is_char_boundary(index) {
        index -= 1;
    }
    index
}
