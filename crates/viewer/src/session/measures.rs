//! What the session measures of its edits and counts of its work.

/// Milliseconds of each stage of the last edit, from the changed text to the swap.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EditTimes {
    /// Parse and symbolic gradient (one call: `CompiledFormula::compile`).
    pub compile_ms: f64,
    /// WGSL generation and naga validation.
    pub codegen_ms: f64,
    /// Tree build and hierarchy (background).
    pub tree_ms: f64,
    /// Render pipeline creation and its warm-up draw (background; 0 when only the tree
    /// changed).
    pub pipeline_ms: f64,
    /// Of `pipeline_ms`, the warm-up draw.
    pub warm_up_ms: f64,
    /// From the changed text to the new tree and pipeline being ready.
    pub ready_ms: f64,
}

/// The running count of expensive things, for tests and the status line.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Formulas compiled (parse + gradient).
    pub compiles: u64,
    /// Render pipelines created (one per new shader).
    pub pipelines: u64,
    /// Trees built to completion.
    pub trees: u64,
}
