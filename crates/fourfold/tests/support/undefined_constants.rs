//! Issue 38's formulas and the caret count of a refusal, for every front end's test (the
//! CLI's, the viewer's and the fuzzer's include this file with `#[path]`; the browser test
//! reads the same list).

/// The listed formulas, each with the part its refusal underlines (None: it draws).
pub fn undefined_constants() -> Vec<(&'static str, Option<&'static str>)> {
    include_str!("../data/undefined-constants.txt")
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| match l.split_once('\t') {
            Some((formula, culprit)) => (formula, Some(culprit)),
            None => (l, None),
        })
        .collect()
}

/// How many carets an error puts under the formula (after the gutter's bar: the formula's
/// own `^` are on the line above).
#[allow(dead_code)] // the fuzzer's test compares spans, not printed carets
pub fn carets(error: &str) -> usize {
    error
        .lines()
        .filter_map(|l| l.split('│').nth(1))
        .map(str::trim_start)
        .find(|rest| rest.starts_with('^'))
        .map_or(0, |rest| rest.chars().take_while(|c| *c == '^').count())
}
