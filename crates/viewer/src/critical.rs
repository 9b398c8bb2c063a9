//! The slice sweep's critical values for the scene on screen (the library's
//! `critical_values`), searched in the background once the formula, parameters, domain and
//! angles have been still for a moment, and kept until one of them changes.

use std::sync::Arc;

use web_time::{Duration, Instant};

use fourfold::CompiledFormula;
use fourfold::critical::{CriticalReport, CriticalSettings, CriticalSteps};
use fourfold::scene::Scene;

use crate::platform::{CRITICAL_BOX_BUDGET, CriticalWork};

/// How long the view must stay still before a search starts (a turn changes n2 at every
/// frame; searching each would be wasted).
const SETTLE: Duration = Duration::from_millis(300);

/// What a report depends on: the formula's text, the parameters, the domain and n2 (the
/// angles), as their bits.
#[derive(Debug, Clone, PartialEq)]
struct Key {
    formula: String,
    params: Vec<(String, u64)>,
    domain: [u64; 8],
    angles: [u64; 6],
}

impl Key {
    fn of(formula: &CompiledFormula, scene: &Scene) -> Self {
        let axes = scene.domain.axes();
        Self {
            formula: formula.source.clone(),
            params: scene
                .params
                .iter()
                .map(|(k, v)| (k.clone(), v.to_bits()))
                .collect(),
            domain: std::array::from_fn(|i| {
                let r = axes[i / 2];
                if i % 2 == 0 { r.lo } else { r.hi }.to_bits()
            }),
            angles: scene.view.angles.map(f64::to_bits),
        }
    }
}

/// The critical values of the slice on screen, and the search under way.
#[derive(Default)]
pub struct Critical {
    /// The last search's report, or why there is none.
    held: Option<(Key, Result<Arc<CriticalReport>, String>)>,
    searching: Option<(Key, CriticalWork)>,
    /// The key last seen and since when, to wait for the view to settle.
    seen: Option<(Key, Instant)>,
}

impl Critical {
    /// Looks at the scene on screen: starts a search once it has settled on values that
    /// have none, drops one for values no longer shown, works on the one under way for
    /// about `budget` (where the platform searches in the window's frames) and takes it
    /// once done. True while one is pending (to keep frames coming).
    pub fn poll(
        &mut self,
        formula: &Arc<CompiledFormula>,
        scene: &Scene,
        budget: Duration,
    ) -> bool {
        let key = Key::of(formula, scene);
        if self.searching.as_ref().is_some_and(|(k, _)| *k != key) {
            self.searching = None;
        }
        if let Some((k, search)) = &mut self.searching
            && let Some(done) = search.poll(budget)
        {
            let k = k.clone();
            self.searching = None;
            // A search that failed (its thread lost) is not retried until an edit.
            let report = done
                .map(Arc::new)
                .ok_or_else(|| "the search for critical values stopped".to_string());
            self.held = Some((k, report));
        }
        if self.held.as_ref().is_some_and(|(k, _)| *k == key) {
            return false;
        }
        if self.searching.as_ref().is_some_and(|(k, _)| *k == key) {
            return true;
        }
        match &self.seen {
            Some((k, since)) if *k == key => {
                if since.elapsed() >= SETTLE {
                    let settings = CriticalSettings {
                        box_budget: CRITICAL_BOX_BUDGET,
                        ..CriticalSettings::default()
                    };
                    // The default settings' level is valid: no error to show.
                    let Ok(steps) = CriticalSteps::new(formula.clone(), scene, &settings) else {
                        return false;
                    };
                    let search = CriticalWork::start(steps);
                    self.searching = Some((key, search));
                }
            }
            _ => self.seen = Some((key, Instant::now())),
        }
        true
    }

    /// The report for the scene on screen (or why it has none), once its search is done.
    pub fn report(
        &self,
        formula: &CompiledFormula,
        scene: &Scene,
    ) -> Option<Result<&CriticalReport, &str>> {
        let (k, report) = self.held.as_ref()?;
        (*k == Key::of(formula, scene)).then(|| match report {
            Ok(r) => Ok(r.as_ref()),
            Err(e) => Err(e.as_str()),
        })
    }
}
