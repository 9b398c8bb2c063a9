//! The search as steps: the strata to search (the interior and the parts of the domain's
//! boundary), each split once along its free axes into parts; a step searches a batch of
//! parts (as many as threads, in parallel) until its time is up, and a stratum whose parts
//! are all searched is finished (its small clusters searched deeper, its points and
//! clusters reported). A native program runs the steps to the end at once; a page, which
//! has one thread, a slice of each frame.

use std::collections::VecDeque;
use std::ops::Deref;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use web_time::{Duration, Instant};

use crate::eval::Box4;
use crate::formula::CompiledFormula;
use crate::interval::Interval;
use crate::mesh::SliceFrame;
use crate::render::view::Rotation4;
use crate::scene::Scene;
use crate::scene::limits::CRITICAL_LEVELS;

use super::search::{self, Leftover, Outcome, Proved};
use super::system::{Stratum, System};
use super::{CriticalError, CriticalPoint, CriticalReport, CriticalSettings, Place, Status};

/// How many levels below the finest a cluster may be searched, and the most boxes it may
/// have to be (a larger one is a surface of critical points, and would take long).
const DEEPER_LEVELS: usize = 4;
const DEEPER_CLUSTER: usize = 2048;

/// A search under way; `F` holds the formula (a reference, or an `Arc` to keep it across
/// a page's frames).
pub struct CriticalSteps<F: Deref<Target = CompiledFormula>> {
    formula: F,
    params: Vec<f64>,
    normal: [f64; 4],
    domain: Box4,
    centre: [f64; 4],
    finest: [f64; 4],
    strata: Vec<Stratum>,
    /// Parts still to search, as (stratum, box).
    queue: VecDeque<(usize, Box4)>,
    /// Per stratum, its parts' outcomes so far and how many parts are left.
    outcomes: Vec<Vec<Outcome>>,
    left: Vec<usize>,
    budget: AtomicUsize,
    report: CriticalReport,
}

impl<F: Deref<Target = CompiledFormula> + Sync> CriticalSteps<F> {
    /// A search of `formula`'s critical values in `scene`'s view and domain.
    pub fn new(
        formula: F,
        scene: &Scene,
        settings: &CriticalSettings,
    ) -> Result<Self, CriticalError> {
        if !CRITICAL_LEVELS.contains(&settings.max_level) {
            return Err(CriticalError::Level {
                level: settings.max_level,
                lo: *CRITICAL_LEVELS.start(),
                hi: *CRITICAL_LEVELS.end(),
            });
        }
        let params = scene.param_values(&formula.param_names());
        let normal = Rotation4::from_angles(scene.view.angles).row(3);
        let domain = scene.domain.to_box();
        let scale = 0.5f64.powi(settings.max_level as i32);
        let mut strata = vec![Stratum::interior()];
        if settings.boundary {
            strata.extend(boundary_strata(&domain));
        }
        // A face across which n2 has no component is a level set of the height at the end
        // of the slice's range. (Where faces meet or on an edge such a level set can lie
        // anywhere: there no box is excluded by the gradient, λ is not bounded, and the
        // boxes where F may vanish are reported, at that height.)
        strata.retain(|s| !(s.free.len() == 3 && s.free.iter().all(|&i| normal[i].abs() < 1e-9)));
        let mut queue = VecDeque::new();
        let mut left = Vec::new();
        for (k, stratum) in strata.iter().enumerate() {
            let mut start = domain;
            for (axis, v) in stratum.fixed.iter().enumerate() {
                if let Some(v) = v {
                    start[axis] = Interval::point(*v);
                }
            }
            let parts = split_once(start, &stratum.free);
            left.push(parts.len());
            queue.extend(parts.into_iter().map(|b| (k, b)));
        }
        Ok(Self {
            params,
            normal,
            domain,
            centre: scene.domain.center(),
            finest: domain.map(|r| r.width() * scale),
            outcomes: strata.iter().map(|_| Vec::new()).collect(),
            strata,
            queue,
            left,
            budget: AtomicUsize::new(settings.box_budget),
            report: CriticalReport {
                points: Vec::new(),
                visited: 0,
                degenerate_boxes: 0,
                undecided_boxes: 0,
                budget_spent: false,
                // How far from the domain's centre, along n2, the slices meet the domain.
                reach: SliceFrame::new(&scene.domain, &scene.view, 0.0).reach(),
            },
            formula,
        })
    }

    /// Searches for about `time` (whole batches of parts); the report once the search is
    /// done.
    pub fn step(&mut self, time: Duration) -> Option<CriticalReport> {
        let started = Instant::now();
        let batch = 2 * rayon::current_num_threads().max(1);
        loop {
            if self.queue.is_empty() {
                return Some(self.report());
            }
            let parts: Vec<(usize, Box4)> =
                (0..batch).map_while(|_| self.queue.pop_front()).collect();
            let this = &*self;
            let searched: Vec<(usize, Outcome)> = parts
                .into_par_iter()
                .map(|(k, part)| {
                    let mut system = this.system(k);
                    (
                        k,
                        search::search(&mut system, part, this.finest, &this.budget, &[]),
                    )
                })
                .collect();
            for (k, outcome) in searched {
                self.outcomes[k].push(outcome);
                self.left[k] -= 1;
                if self.left[k] == 0 {
                    self.finish(k);
                }
            }
            if started.elapsed() >= time {
                return None;
            }
        }
    }

    fn system(&self, k: usize) -> System<'_> {
        System::new(
            &self.formula,
            &self.params,
            self.normal,
            self.strata[k].clone(),
        )
    }

    /// Stratum `k`'s parts as one; its small smooth clusters searched deeper, a level at a
    /// time (a point beside one proved from a neighbour, or where the enclosures were too
    /// loose at the finest size, is often decided there) while their boxes keep decreasing
    /// (a curve or surface of critical points doubles or quadruples them at each level, and
    /// is left as it is); then its points and clusters reported.
    fn finish(&mut self, k: usize) {
        let outcomes = std::mem::take(&mut self.outcomes[k]);
        let (points, visited) = self.finished(k, outcomes);
        self.report.visited += visited;
        for p in &points {
            match p.status {
                Status::Degenerate => self.report.degenerate_boxes += p.boxes,
                Status::Undecided => self.report.undecided_boxes += p.boxes,
                Status::Proved => {}
            }
        }
        self.report.points.extend(points);
    }

    /// See [`Self::finish`]: the points of stratum `k` from its parts' outcomes, and the
    /// boxes looked at.
    fn finished(&self, k: usize, outcomes: Vec<Outcome>) -> (Vec<CriticalPoint>, usize) {
        let system = self.system(k);
        let mut outcome = search::merge(outcomes, &system);
        let run = |parts: Vec<Box4>, finest: [f64; 4], known: &[Proved]| {
            let outcomes = parts
                .into_par_iter()
                .map(|part| search::search(&mut system.clone(), part, finest, &self.budget, known))
                .collect();
            search::merge(outcomes, &system)
        };
        let mut kept = Vec::new();
        let leftovers = std::mem::take(&mut outcome.leftovers);
        for cluster in search::clusters(&leftovers) {
            let mut boxes: Vec<Leftover> = cluster.iter().map(|&i| leftovers[i].clone()).collect();
            let smooth = boxes.iter().all(|l| l.smooth);
            let mut finer = self.finest;
            for _ in 0..DEEPER_LEVELS {
                if !smooth || boxes.is_empty() || boxes.len() > DEEPER_CLUSTER {
                    break;
                }
                finer = finer.map(|f| f / 2.0);
                let again = run(
                    boxes.iter().map(|l| l.space).collect(),
                    finer,
                    &outcome.proved,
                );
                outcome.visited += again.visited;
                let shrank = again.leftovers.len() < boxes.len();
                boxes = again.leftovers;
                for p in again.proved {
                    if !outcome
                        .proved
                        .iter()
                        .any(|q| search::same(q, &p, system.dim()))
                    {
                        outcome.proved.push(p);
                    }
                }
                if !shrank {
                    break;
                }
            }
            kept.extend(boxes);
        }
        outcome.leftovers = kept;
        (self.points(&system, &outcome), outcome.visited)
    }

    /// The points a stratum's search proved (those that may lie in the domain: a region of
    /// uniqueness can reach past it), and its clusters of boxes left over.
    fn points(&self, system: &System, outcome: &Outcome) -> Vec<CriticalPoint> {
        let place = match system.stratum.free.len() {
            4 => Place::Interior,
            _ => Place::Boundary {
                fixed: system.stratum.fixed,
            },
        };
        let height = |b: &Box4| {
            (0..4).fold(Interval::ZERO, |acc, i| {
                let d = b[i].sub(Interval::point(self.centre[i]));
                acc.add(d.mul(Interval::point(self.normal[i])))
            })
        };
        let domain = &self.domain;
        let mut points: Vec<CriticalPoint> = outcome
            .proved
            .iter()
            .map(|p| system.space_box(&p.tight))
            .zip(outcome.proved.iter().map(|p| p.index))
            .filter(|(e, _)| {
                (0..4).all(|i| e[i].hi() >= domain[i].lo() && e[i].lo() <= domain[i].hi())
            })
            .map(|(enclosure, index)| CriticalPoint {
                value: height(&enclosure),
                enclosure,
                index,
                status: Status::Proved,
                place,
                boxes: 1,
            })
            .collect();
        for cluster in search::clusters(&outcome.leftovers) {
            let boxes: Vec<&Leftover> = cluster.iter().map(|&i| &outcome.leftovers[i]).collect();
            let hull = |a: Box4, b: Box4| std::array::from_fn(|i| a[i].hull(b[i]));
            points.push(CriticalPoint {
                value: boxes
                    .iter()
                    .map(|l| height(&l.space))
                    .reduce(Interval::hull)
                    .expect("a box"),
                enclosure: boxes.iter().map(|l| l.space).reduce(hull).expect("a box"),
                index: None,
                status: if boxes.iter().all(|l| l.smooth) {
                    Status::Degenerate
                } else {
                    Status::Undecided
                },
                place,
                boxes: boxes.len(),
            });
        }
        points
    }

    /// The report, its points in increasing order of their enclosures' middles.
    fn report(&self) -> CriticalReport {
        let mut report = self.report.clone();
        report.budget_spent = self.budget.load(Ordering::Relaxed) == 0;
        report
            .points
            .sort_by(|a, b| a.value.midpoint().total_cmp(&b.value.midpoint()));
        report
    }
}

/// The parts of the domain's boundary, faces first, then where two faces meet, then the
/// edges (the corners matter only at the ends of the slice's range, where the slice
/// first and last meets the domain).
fn boundary_strata(domain: &Box4) -> Vec<Stratum> {
    let mut strata = Vec::new();
    for count in 1..=3 {
        for mask in (1u32..16).filter(|m| m.count_ones() == count) {
            let axes: Vec<usize> = (0..4).filter(|&a| mask >> a & 1 == 1).collect();
            for sides in 0..1u32 << count {
                let mut fixed = [None; 4];
                for (k, &a) in axes.iter().enumerate() {
                    let r = domain[a];
                    fixed[a] = Some(if sides >> k & 1 == 1 { r.hi() } else { r.lo() });
                }
                strata.push(Stratum::boundary(fixed));
            }
        }
    }
    strata
}

/// The 2^k boxes of `b` halved along each of the k `free` axes.
fn split_once(b: Box4, free: &[usize]) -> Vec<Box4> {
    free.iter().fold(vec![b], |boxes, &axis| {
        boxes
            .into_iter()
            .flat_map(|b| search::halves(b, axis))
            .collect()
    })
}
