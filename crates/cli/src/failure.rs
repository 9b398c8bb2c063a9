//! A command's failure as the user sees it: the text printed and the exit code (2 for a
//! usage error: a bad flag, formula or scene; 1 for anything else).

/// A user-facing failure: the text to print and the exit code.
#[derive(Debug)]
pub struct Failure {
    pub message: String,
    pub code: i32,
}

impl Failure {
    pub fn usage(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: 2,
        }
    }
    pub fn runtime(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            code: 1,
        }
    }
}
