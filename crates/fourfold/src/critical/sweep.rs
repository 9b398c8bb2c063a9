//! A slice sweep's frames placed around the critical values: evenly from one end to the
//! other, except that a frame that would fall on a critical value (or within a twentieth of
//! a step of its enclosure) moves just outside it, so that each change of the slice's
//! topology happens between two frames; and which frames straddle which values.

use crate::formula::CompiledFormula;
use crate::render::animation::Animation;
use crate::scene::Scene;

use super::{CriticalPoint, CriticalReport, CriticalSettings, critical_values};

/// Places a slice sweep's frames around its critical values (searched with the default
/// settings in the scene's view): the report, or None where the animation moves no slice.
/// A turn moves n2 itself, so with one the frames stay even.
pub fn place_frames(
    animation: &mut Animation,
    formula: &CompiledFormula,
    scene: &Scene,
) -> Option<CriticalReport> {
    let (from, to) = animation.slice_sweep?;
    if animation.turn.is_some() || animation.sweep.is_some() {
        return None;
    }
    let report = critical_values(formula, scene, &CriticalSettings::default()).ok()?;
    animation.slice_places = sweep_places(from, to, animation.frames, &report);
    Some(report)
}

/// In words, where each critical value falls among the frames (numbered from 1).
pub fn straddle_lines(places: &[f64], report: &CriticalReport) -> Vec<String> {
    let among = straddles(places, report);
    let mut lines = Vec::new();
    for (i, a) in among.iter().enumerate() {
        let line = match a {
            Among::Between(k, c) => {
                let shared = among
                    .iter()
                    .enumerate()
                    .any(|(j, b)| j != i && matches!(b, Among::Between(m, _) if m == k));
                format!(
                    "frames {} and {} straddle c = {:.6} ({}: {}){}",
                    k + 1,
                    k + 2,
                    c.value.midpoint(),
                    c.status.name(),
                    c.meaning(),
                    if shared {
                        "; more than one change between these frames: more frames would \
                         show each"
                    } else {
                        ""
                    }
                )
            }
            Among::At(k, c) => format!(
                "frame {} lies within the enclosure {} of a critical value ({}: {})",
                k + 1,
                c.value,
                c.status.name(),
                c.meaning()
            ),
        };
        lines.push(line);
    }
    lines
}

/// The slice's place at each of `frames` frames from `from` to `to`.
pub fn sweep_places(from: f64, to: f64, frames: u32, report: &CriticalReport) -> Vec<f64> {
    let n = frames.max(1) as usize;
    let step = if n > 1 {
        (to - from) / (n - 1) as f64
    } else {
        0.0
    };
    let even: Vec<f64> = (0..n).map(|k| from + step * k as f64).collect();
    let margin = 0.05 * step.abs();
    let mut places = even.clone();
    for k in 0..n {
        let p = even[k];
        let Some(hit) = report
            .points
            .iter()
            .find(|c| c.value.lo() - margin <= p && p <= c.value.hi() + margin)
        else {
            continue;
        };
        let (below, above) = (hit.value.lo() - margin, hit.value.hi() + margin);
        // The nearer side first; a frame never passes its neighbours' even places nor lands
        // on another value.
        let mut sides = [below, above];
        if p - below > above - p {
            sides.swap(0, 1);
        }
        // The end frames stay within the sweep asked for.
        let before = if k > 0 { even[k - 1] } else { from };
        let after = if k + 1 < n { even[k + 1] } else { to };
        let (lo, hi) = (before.min(after), before.max(after));
        if let Some(&q) = sides.iter().find(|&&q| {
            lo < q
                && q < hi
                && !report.points.iter().any(|c| {
                    c.value.lo() - margin <= q
                        && q <= c.value.hi() + margin
                        && !std::ptr::eq(c, hit)
                })
        }) {
            places[k] = q;
        }
    }
    places
}

/// Where a critical value falls among the frames.
#[derive(Debug, Clone, PartialEq)]
pub enum Among<'a> {
    /// Between frames k and k + 1 (0-based), strictly: the change happens between them.
    Between(usize, &'a CriticalPoint),
    /// Frame k lies within the value's enclosure (a wide degenerate or undecided one).
    At(usize, &'a CriticalPoint),
}

/// For each critical value within the sweep, the frames around it, in the sweep's order.
pub fn straddles<'a>(places: &[f64], report: &'a CriticalReport) -> Vec<Among<'a>> {
    let mut found = Vec::new();
    for c in &report.points {
        if let Some(k) = places.iter().position(|&p| c.value.contains(p)) {
            found.push(Among::At(k, c));
            continue;
        }
        let k = places.windows(2).position(|w| {
            let (lo, hi) = (w[0].min(w[1]), w[0].max(w[1]));
            lo < c.value.lo() && c.value.hi() < hi
        });
        if let Some(k) = k {
            found.push(Among::Between(k, c));
        }
    }
    let frame = |a: &Among| match a {
        Among::Between(k, _) | Among::At(k, _) => *k,
    };
    found.sort_by_key(frame);
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::critical::{Place, Status};
    use crate::interval::Interval;

    fn report(values: &[(f64, f64)]) -> CriticalReport {
        CriticalReport {
            points: values
                .iter()
                .map(|&(lo, hi)| CriticalPoint {
                    value: Interval::new(lo, hi),
                    enclosure: [Interval::ZERO; 4],
                    index: Some(0),
                    status: Status::Proved,
                    place: Place::Interior,
                    boxes: 1,
                })
                .collect(),
            visited: 0,
            degenerate_boxes: 0,
            undecided_boxes: 0,
            budget_spent: false,
            reach: 2.0,
        }
    }

    #[test]
    fn a_frame_on_a_critical_value_moves_off_it() {
        // Frames at -1, -0.5, 0, 0.5, 1; critical values at 0 and near 0.52.
        let r = report(&[(-1e-15, 1e-15), (0.52, 0.52)]);
        let places = sweep_places(-1.0, 1.0, 5, &r);
        assert_eq!(places.len(), 5);
        assert!(places.windows(2).all(|w| w[0] < w[1]), "{places:?}");
        let among = straddles(&places, &r);
        assert_eq!(among.len(), 2, "{among:?}");
        assert!(matches!(
            among[0],
            Among::Between(1, _) | Among::Between(2, _)
        ));
        assert!(among.iter().all(|a| matches!(a, Among::Between(..))));
        // Frames away from critical values stay where they were.
        assert_eq!(places[0], -1.0);
        assert_eq!(places[4], 1.0);
    }

    #[test]
    fn end_frames_on_critical_values_move_inwards() {
        let r = report(&[(-1.0, -1.0), (1.0, 1.0)]);
        let places = sweep_places(-1.0, 1.0, 3, &r);
        assert!(
            places[0] > -1.0 && places[2] < 1.0 && places[1] == 0.0,
            "{places:?}"
        );
    }

    #[test]
    fn a_backward_sweep_straddles_too() {
        let r = report(&[(0.25, 0.25)]);
        let places = sweep_places(1.0, -1.0, 5, &r);
        assert!(places.windows(2).all(|w| w[0] > w[1]), "{places:?}");
        assert_eq!(straddles(&places, &r), [Among::Between(1, &r.points[0])]);
    }
}
