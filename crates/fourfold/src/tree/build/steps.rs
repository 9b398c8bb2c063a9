//! A tree build in steps, for a caller that cannot wait for the whole of it (the web page has
//! one thread, which also draws the window), and the whole build as those steps run to the
//! end: each step refines at most a given number of boxes, and the same boxes are evaluated
//! in the same order as in one go, so the tree is the same.

use std::sync::atomic::{AtomicBool, Ordering};
use web_time::{Duration, Instant};

use crate::eval::{Box4, Interval, IntervalEvaluator};
use crate::formula::CompiledFormula;

use super::refine::{Refinement, contains_manifold};
use super::region::Region;
use super::tree::{
    BuildError, BuildSettings, Geometry, Progress, Tree16, TreeBox, TreeStats, validate,
};

impl Tree16 {
    /// Builds the tree of `formula` with parameter values `params` over `domain`.
    /// `cancel` is polled often; once it is set the build returns [`BuildError::Cancelled`].
    pub fn build(
        formula: &CompiledFormula,
        params: &[f64],
        domain: &Box4,
        settings: BuildSettings,
        cancel: &AtomicBool,
        progress: Option<Progress<'_>>,
    ) -> Result<Self, BuildError> {
        Self::build_within(formula, params, domain, None, settings, cancel, progress)
    }

    /// As [`Tree16::build`], keeping only the boxes that meet `region` (all where it is
    /// `None`): the tree of a picture that looks at part of the domain.
    pub fn build_within(
        formula: &CompiledFormula,
        params: &[f64],
        domain: &Box4,
        region: Option<Region>,
        settings: BuildSettings,
        cancel: &AtomicBool,
        progress: Option<Progress<'_>>,
    ) -> Result<Self, BuildError> {
        let mut steps = TreeSteps::within(formula, params, domain, region, settings)?;
        loop {
            if cancel.load(Ordering::Relaxed) {
                return Err(BuildError::Cancelled);
            }
            // A whole level per step: all of it is evaluated in parallel.
            let level = steps.level;
            if let Some(tree) = steps.step(formula, params, cancel, usize::MAX)? {
                return Ok(tree);
            }
            if let Some(report) = progress.filter(|_| steps.level > level) {
                report(steps.level, steps.total);
            }
        }
    }
}

/// A tree build in steps, for a caller that cannot wait for the whole of it (the web page has
/// one thread, which also draws the window): each step refines at most a given number of
/// boxes, and the same boxes are evaluated in the same order as in one go, so the tree is
/// the same.
pub struct TreeSteps {
    geometry: Geometry,
    domain: Box4,
    region: Option<Region>,
    settings: BuildSettings,
    stats: TreeStats,
    levels: Vec<Vec<TreeBox>>,
    /// The deepest level built so far, and the nodes so far.
    level: u32,
    total: u64,
    /// The level being refined, when one is under way.
    pending: Option<PendingLevel>,
    /// Time spent in steps (not between them).
    busy: Duration,
    done: bool,
}

/// The refinement of one level, part done.
struct PendingLevel {
    /// Indices of the boxes to refine, and how many of them are done.
    refine: Vec<u32>,
    done: usize,
    gradient: bool,
    mean_value: bool,
    kept: Vec<TreeBox>,
}

impl TreeSteps {
    /// Checks the settings and evaluates the root.
    pub fn new(
        formula: &CompiledFormula,
        params: &[f64],
        domain: &Box4,
        settings: BuildSettings,
    ) -> Result<Self, BuildError> {
        Self::within(formula, params, domain, None, settings)
    }

    /// As [`TreeSteps::new`], for a tree of the boxes that meet `region` (see
    /// [`Tree16::build_within`]).
    pub fn within(
        formula: &CompiledFormula,
        params: &[f64],
        domain: &Box4,
        region: Option<Region>,
        settings: BuildSettings,
    ) -> Result<Self, BuildError> {
        let started = Instant::now();
        validate(settings)?;
        let geometry = Geometry::new(domain);
        let mut stats = TreeStats::default();
        let mut levels: Vec<Vec<TreeBox>> = Vec::new();
        // The root: the component criterion, and the topological one (refining a level
        // sets both on the next).
        let root_box = geometry.box_at(0, [0; 4]);
        let mut eval = IntervalEvaluator::new();
        let root_f = eval.eval(&formula.tape_f, &root_box, params);
        let mut all = [Interval::EMPTY; 5];
        eval.eval_into(&formula.tape_all, &root_box, params, &mut all);
        stats.interval_evaluations += 2;
        let root = TreeBox {
            coords: [0; 4],
            parent: u32::MAX,
            first_child: 0,
            child_count: 0,
            critical: all[1..].iter().all(|g| g.contains_zero()),
            below: root_f.lo() < 0.0,
            above: root_f.hi() > 0.0,
        };
        let mut total: u64 = 0;
        if contains_manifold(root_f) && region.is_none_or(|r| r.meets(&root_box)) {
            levels.push(vec![root]);
            total = 1;
        } else {
            stats.discarded_per_level.push(1);
        }
        Ok(Self {
            geometry,
            domain: *domain,
            region,
            settings,
            stats,
            levels,
            level: 0,
            total,
            pending: None,
            busy: started.elapsed(),
            done: false,
        })
    }

    /// Nodes made so far.
    pub fn nodes(&self) -> u64 {
        self.total
    }

    /// Refines up to `boxes` boxes of the current level (starting the next level when none
    /// is under way); the tree once it is complete. The same `formula` and `params` must be
    /// passed to every step.
    pub fn step(
        &mut self,
        formula: &CompiledFormula,
        params: &[f64],
        cancel: &AtomicBool,
        boxes: usize,
    ) -> Result<Option<Tree16>, BuildError> {
        if self.done {
            return Err(BuildError::InvalidSettings(
                "this tree build is already complete".into(),
            ));
        }
        let started = Instant::now();
        let result = self.advance(formula, params, cancel, boxes);
        self.busy += started.elapsed();
        match result {
            Ok(true) => Ok(Some(self.finish(formula, params))),
            Ok(false) => Ok(None),
            Err(e) => Err(e),
        }
    }

    /// One step; true when the tree is complete.
    fn advance(
        &mut self,
        formula: &CompiledFormula,
        params: &[f64],
        cancel: &AtomicBool,
        boxes: usize,
    ) -> Result<bool, BuildError> {
        let settings = self.settings;
        let level = self.level;
        let Some(current) = self.levels.last_mut() else {
            return Ok(true);
        };
        let step = Refinement {
            formula,
            params,
            geometry: &self.geometry,
            level,
            parents: current,
            region: self.region.as_ref(),
            cancel,
        };
        let mut pending = match self.pending.take() {
            Some(p) => p,
            None => {
                if level >= settings.max_level {
                    return Ok(true);
                }
                let refine: Vec<u32> = current
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| level < settings.min_level || b.critical)
                    .map(|(i, _)| i as u32)
                    .collect();
                if refine.is_empty() {
                    return Ok(true);
                }
                // Fairness: the whole next level fits in the budget, or none of it is made.
                let worst_case = self.total + 16 * refine.len() as u64;
                if worst_case > u64::from(settings.node_budget) {
                    self.stats.budget_hit = true;
                    self.stats.budget_level = Some(level);
                    return Ok(true);
                }
                // From min_level on the topological criterion takes the gradient's
                // enclosure, which the mean-value form needs too: there it costs F at the
                // centre (a build half again as long), so it is used where it discards boxes
                // in a sample of the level.
                let gradient = level + 1 >= settings.min_level;
                let mean_value = gradient && {
                    let (discards, evaluations) = step.mean_value_discards(&refine)?;
                    self.stats.interval_evaluations += evaluations;
                    discards
                };
                PendingLevel {
                    refine,
                    done: 0,
                    gradient,
                    mean_value,
                    kept: Vec::new(),
                }
            }
        };
        let end = pending.done.saturating_add(boxes).min(pending.refine.len());
        let refined = step.children(
            &pending.refine[pending.done..end],
            pending.gradient,
            pending.mean_value,
        )?;
        pending.kept.extend(refined.kept);
        pending.done = end;
        self.stats.interval_evaluations += refined.evaluations;
        self.stats.mean_value_discarded += refined.pruned;
        if pending.done < pending.refine.len() {
            self.pending = Some(pending);
            return Ok(false);
        }
        let children = pending.kept;
        let kept = children.len() as u64;
        let stats = &mut self.stats;
        stats.discarded_per_level.resize(level as usize + 2, 0);
        stats.discarded_per_level[level as usize + 1] = 16 * pending.refine.len() as u64 - kept;
        link_children(current, &children);
        self.total += kept;
        self.level += 1;
        let done = children.is_empty();
        // Pushed even when empty, so that pruning sees this level was built.
        self.levels.push(children);
        Ok(done)
    }

    fn finish(&mut self, formula: &CompiledFormula, params: &[f64]) -> Tree16 {
        let started = Instant::now();
        self.done = true;
        let mut levels = std::mem::take(&mut self.levels);
        prune_childless(&mut levels, self.settings);
        let mut tree = Tree16 {
            domain: self.domain,
            levels,
            stats: std::mem::take(&mut self.stats),
        };
        tree.count(self.settings);
        tree.measure_touching(formula, params);
        tree.stats.build_ms = (self.busy + started.elapsed()).as_secs_f64() * 1e3;
        tree
    }
}

/// Removes refined boxes whose children were all discarded (docs/method.md §2), bottom-up: such
/// a box holds no point of M. Renumbers the parent links and child ranges it touches.
fn prune_childless(levels: &mut Vec<Vec<TreeBox>>, settings: BuildSettings) {
    for l in (0..levels.len()).rev() {
        let next_built = l + 1 < levels.len();
        let was_refined = |b: &TreeBox| {
            next_built
                && (l as u32) < settings.max_level
                && ((l as u32) < settings.min_level || b.critical)
        };
        let keep: Vec<bool> = levels[l]
            .iter()
            .map(|b| !(was_refined(b) && b.child_count == 0))
            .collect();
        if keep.iter().all(|k| *k) {
            continue;
        }
        let mut new_index = vec![u32::MAX; keep.len()];
        for (next, (i, _)) in keep.iter().enumerate().filter(|(_, k)| **k).enumerate() {
            new_index[i] = next as u32;
        }
        let old = std::mem::take(&mut levels[l]);
        levels[l] = old
            .into_iter()
            .zip(&keep)
            .filter_map(|(b, k)| k.then_some(b))
            .collect();
        if next_built {
            for child in &mut levels[l + 1] {
                child.parent = new_index[child.parent as usize];
            }
        }
        if l > 0 {
            let (above, here) = levels.split_at_mut(l);
            link_children(&mut above[l - 1], &here[0]);
        }
    }
    while levels.last().is_some_and(|l| l.is_empty()) {
        levels.pop();
    }
}

/// Sets each parent's child range from its children's parent links (children are grouped by
/// parent, in parent order).
fn link_children(parents: &mut [TreeBox], children: &[TreeBox]) {
    for p in parents.iter_mut() {
        p.child_count = 0;
        p.first_child = 0;
    }
    let mut i = 0;
    while i < children.len() {
        let parent = children[i].parent as usize;
        let start = i;
        while i < children.len() && children[i].parent as usize == parent {
            i += 1;
        }
        parents[parent].first_child = start as u32;
        parents[parent].child_count = (i - start) as u8;
    }
}
