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
        // A control character has no width: the caret under it would vanish.
        let shown: String = shown
            .chars()
            .map(|c| {
                if c.is_ascii_control() && !matches!(c, '\n' | '\r' | '\t') {
                    ' '
                } else {
                    c
                }
            })
            .collect();
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

/// The line of the source around an error's span, cut to fit a given number of columns,
/// with the caret line under it: what a narrow panel shows so that the caret and its label
/// are always in view (see [`SourceError::caret_window`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CaretWindow {
    /// The part of the source line shown, with "…" where it was cut.
    pub source: String,
    /// Spaces, then a '^' under each character of the span, then the label where it fits.
    pub carets: String,
    /// The label on a line of its own, where it does not fit after the carets.
    pub label: Option<String>,
}

impl SourceError {
    /// The source line around the span and a caret line under it, each at most `columns`
    /// characters wide (at least 12): the window keeps the span in view, with some of what
    /// comes before it.
    pub fn caret_window(&self, source: &str, columns: usize) -> CaretWindow {
        let columns = columns.max(12);
        let start = floor_char_boundary(source, self.span.start.min(source.len()));
        let end = floor_char_boundary(source, self.span.end.clamp(start, source.len()));
        let line_start = source[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = source[start..]
            .find('\n')
            .map_or(source.len(), |i| start + i);
        let line: Vec<char> = source[line_start..line_end]
            .chars()
            .map(|c| if c.is_control() { ' ' } else { c })
            .collect();
        // Columns of the span in the line (one caret at least, maybe just past its end).
        let s = source[line_start..start].chars().count();
        let e = (s + source[start..end.min(line_end)].chars().count()).max(s + 1);
        let (from, to) = if line.len() < columns {
            (0, line.len())
        } else {
            // Room for a "…" on each side; a third of it before the span, if the span fits.
            let room = columns - 2;
            let mut from = s.saturating_sub(room / 3);
            if e > from + room {
                from = e.saturating_sub(room).min(s);
            }
            let from = from.min(line.len().saturating_sub(room));
            (from, (from + room).min(line.len()))
        };
        let prefix = if from > 0 { "…" } else { "" };
        let suffix = if to < line.len() { "…" } else { "" };
        let shown: String = line[from..to].iter().collect();
        let caret_col = s - from + prefix.chars().count();
        let carets_len = e.min(to.max(s + 1)) - s;
        let mut carets = format!("{}{}", " ".repeat(caret_col), "^".repeat(carets_len));
        let label_len = self.label.chars().count();
        let label = if caret_col + carets_len + 1 + label_len <= columns {
            carets.push(' ');
            carets.push_str(&self.label);
            None
        } else {
            let indent = caret_col.min(columns.saturating_sub(label_len));
            Some(format!("{}{}", " ".repeat(indent), self.label))
        };
        CaretWindow {
            source: format!("{prefix}{shown}{suffix}"),
            carets,
            label,
        }
    }
}
