//! Undo and redo over what the user sets: the formula text and the scene (parameters,
//! angles, zoom, domain, tree and render settings). A change becomes a step once it has
//! settled (no further change for a moment, no drag in progress), so a slider's drag or a
//! typed word is one step, not one per frame.

use web_time::{Duration, Instant};

use fourfold::scene::Scene;

/// Steps kept; older ones are forgotten.
const LIMIT: usize = 200;
/// How long a state must stay unchanged to become a step.
pub const SETTLE: Duration = Duration::from_millis(400);

/// What one step restores.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    pub scene: Scene,
    /// The editor's text (it may not compile; the scene's formula is the last that did).
    pub text: String,
}

/// The undo and redo stacks.
#[derive(Debug, Default)]
pub struct History {
    undo: Vec<Snapshot>,
    redo: Vec<Snapshot>,
    /// The state the last step left (what an undo of the next change returns to).
    settled: Option<Snapshot>,
    /// The state seen at the last frame, and since when it has not changed.
    last: Option<(Snapshot, Instant)>,
}

impl History {
    /// Sees the current state, once per frame; `busy` while the user holds a drag.
    pub fn observe(&mut self, now: &Snapshot, busy: bool) {
        let Some(settled) = &self.settled else {
            self.settled = Some(now.clone());
            return;
        };
        match &self.last {
            Some((last, _)) if last == now => {}
            _ => self.last = Some((now.clone(), Instant::now())),
        }
        let quiet = self
            .last
            .as_ref()
            .is_some_and(|(_, t)| t.elapsed() >= SETTLE);
        if settled != now && quiet && !busy {
            let previous = self.settled.replace(now.clone()).expect("checked above");
            self.push_undo(previous);
            self.redo.clear();
        }
    }

    /// A change the program made on the user's behalf right after theirs (framing a scene
    /// just opened): it joins the step before it instead of becoming one.
    pub fn amend(&mut self, now: &Snapshot) {
        self.settled = Some(now.clone());
        self.last = Some((now.clone(), Instant::now()));
    }

    /// The state to go back to from `current`, if any.
    pub fn undo(&mut self, current: &Snapshot) -> Option<Snapshot> {
        let settled = self.settled.clone()?;
        let target = if &settled != current {
            // A change not yet settled: undo it first.
            settled
        } else {
            self.undo.pop()?
        };
        self.redo.push(current.clone());
        self.amend(&target);
        Some(target)
    }

    /// The state undone last, if any.
    pub fn redo(&mut self, current: &Snapshot) -> Option<Snapshot> {
        let target = self.redo.pop()?;
        self.push_undo(current.clone());
        self.amend(&target);
        Some(target)
    }

    pub fn can_undo(&self, current: &Snapshot) -> bool {
        !self.undo.is_empty() || self.settling(current)
    }

    /// The state the last step left.
    pub fn settled(&self) -> Option<&Snapshot> {
        self.settled.as_ref()
    }

    /// Whether `current` is a change that has not become a step yet.
    pub fn settling(&self, current: &Snapshot) -> bool {
        self.settled.as_ref().is_some_and(|s| s != current)
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    fn push_undo(&mut self, snapshot: Snapshot) {
        if self.undo.len() == LIMIT {
            self.undo.remove(0);
        }
        self.undo.push(snapshot);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(formula: &str) -> Snapshot {
        Snapshot {
            scene: Scene::from_formula(formula),
            text: formula.to_string(),
        }
    }

    /// Observes `s` until it settles.
    fn settle(h: &mut History, s: &Snapshot) {
        h.observe(s, false);
        std::thread::sleep(SETTLE + Duration::from_millis(20));
        h.observe(s, false);
    }

    #[test]
    fn settled_changes_are_steps_that_undo_and_redo_walk() {
        let mut h = History::default();
        let (a, b, c) = (state("x"), state("y"), state("z"));
        settle(&mut h, &a);
        settle(&mut h, &b);
        settle(&mut h, &c);
        assert_eq!(h.undo(&c), Some(b.clone()));
        assert_eq!(h.undo(&b), Some(a.clone()));
        assert_eq!(h.undo(&a), None);
        assert_eq!(h.redo(&a), Some(b.clone()));
        assert_eq!(h.redo(&b), Some(c.clone()));
        assert!(!h.can_redo());
    }

    #[test]
    fn a_drag_or_a_quick_run_of_changes_is_one_step() {
        let mut h = History::default();
        let a = state("x");
        settle(&mut h, &a);
        // Many states while busy, none of them settled.
        for k in 0..5 {
            h.observe(&state(&format!("x + {k}")), true);
        }
        let end = state("x + 9");
        settle(&mut h, &end);
        assert_eq!(h.undo(&end), Some(a.clone()));
        assert_eq!(h.undo(&a), None);
    }

    #[test]
    fn an_unsettled_change_is_undone_first_and_a_new_change_clears_redo() {
        let mut h = History::default();
        let (a, b) = (state("x"), state("y"));
        settle(&mut h, &a);
        h.observe(&b, false);
        assert!(h.can_undo(&b));
        assert_eq!(h.undo(&b), Some(a.clone()));
        assert!(h.can_redo());
        settle(&mut h, &state("w"));
        assert!(!h.can_redo());
    }
}
