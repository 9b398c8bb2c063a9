//! A tile's slice pixels marched side by side: each of [`LANES`] lanes holds a pixel's
//! march (see `march`), and each round takes the next sample of every lane's at once, by
//! lanes of F's tape (its arithmetic vectorized, a library function run again only in the
//! lanes whose coordinates it reads moved), where a pixel alone takes them one by one
//! through the point evaluator. A pixel's march asks for each sample only after the one before
//! (where it goes next depends on F there), so the pixels' side by side are what can be
//! evaluated together; so is F at the near end of a sign change whose sample a skip left
//! out, in the next round. The samples, the sign changes and the hits are the same as one
//! pixel at a time: the lanes' values are the point evaluator's, bit for bit.

use crate::eval::LANES;
use crate::formula::CompiledFormula;
use crate::render::view::Uniforms;
use crate::tree::Hierarchy;

use super::evals::{Deferred, Evaluators};
use super::march::{Crossing, March, Stretch};
use super::pixel::{Marched, hits_kept, stop_at};
use super::section::Band;
use super::shading::{add, scale};
use super::traced::{PlaneBracket, Start, Traced};
use super::walk::{Kept, boxes_of};

/// A lane: the pixel it marches (None: idle), that pixel's boxes and the next of them to
/// march, the march under way and a sign change of it waiting for F at its near end (which
/// a skip left unsampled: the lane's next point), and the pixel's hits, roots left for
/// later and bracket.
#[derive(Default)]
pub(super) struct Lane {
    start: Option<Start>,
    boxes: Vec<Marched>,
    next_box: usize,
    march: Option<March>,
    waiting: Option<Crossing>,
    hits: Vec<(f32, u32)>,
    deferred: Vec<Deferred>,
    bracket: PlaneBracket,
}

/// The lanes a worker's tiles reuse.
pub(super) fn lanes() -> Vec<Lane> {
    (0..LANES).map(|_| Lane::default()).collect()
}

/// What the lanes work with of a worker's scratch: the lanes, the evaluators, the tile's
/// one-signed stretches, its walk of the rays' hierarchy (the section's band from the
/// rays' origin, the nodes kept), and the tile's hits and roots left for later.
pub(super) struct Work<'w> {
    pub(super) lanes: &'w mut [Lane],
    pub(super) evals: &'w mut Evaluators,
    pub(super) one_signed: &'w [Stretch],
    pub(super) walk: (&'w Option<Band>, &'w [Kept]),
    pub(super) tile: (&'w mut Vec<(f32, u32)>, &'w mut Vec<Deferred>),
}

/// Traces the slice's `pixels` (see `tile::trace_pixel`) into `traced`, [`LANES`] side
/// by side across the boxes of `h` (the rays' hierarchy); the same hits, roots and
/// brackets as one by one, each pixel traced as its lane finishes it.
pub(super) fn trace_pixels(
    (formula, params): (&CompiledFormula, &[f64]),
    (h, u): (&Hierarchy, &Uniforms),
    work: &mut Work<'_>,
    mut pixels: impl Iterator<Item = (u32, u32)>,
    traced: &mut Vec<Traced>,
) {
    let context = (u, formula, params);
    let mut points = [[0.0f32; 4]; LANES];
    let mut values = [[0.0f32; 2]; LANES];
    // (Each point's lane and t.)
    let mut asked = [(0usize, 0.0f32); LANES];
    loop {
        let mut n = 0;
        for l in 0..work.lanes.len() {
            let Some(t) = next_sample(l, (h, context), work, &mut pixels, traced) else {
                continue;
            };
            let march = work.lanes[l]
                .march
                .as_ref()
                .expect("a lane that asks marches");
            points[n] = add(march.o, scale(march.d, t));
            asked[n] = (l, t);
            n += 1;
        }
        if n == 0 {
            break;
        }
        let d = u.n1;
        work.evals
            .samples(formula, params, (&points[..n], d), &mut values);
        for (&(l, t), &[f, slope]) in asked[..n].iter().zip(&values) {
            let lane = &mut work.lanes[l];
            let march = lane.march.as_mut().expect("a lane that asked marches");
            let (crossing, f_ta) = match lane.waiting.take() {
                // (F at the near end of the sign change that waited for it.)
                Some(crossing) => (crossing, f),
                None => {
                    let sample = [f, if march.bent { slope } else { 0.0 }];
                    let Some(crossing) = march.take(t, sample) else {
                        continue;
                    };
                    if !crossing.fresh {
                        lane.waiting = Some(crossing);
                        continue;
                    }
                    (crossing, crossing.fa)
                }
            };
            let march = *march;
            let start = lane.start.expect("a lane that marches has a pixel");
            let defers = work.evals.defers_roots();
            let mut pixel = start.pixel(context, (work.evals, &mut lane.hits), work.one_signed);
            let deferred = defers.then_some(&mut lane.deferred);
            (pixel.bracket, pixel.deferred) = (lane.bracket, deferred);
            pixel.cross(&march, crossing, f_ta);
            lane.bracket = pixel.bracket;
        }
    }
}

/// Where lane `l`'s next sample is (t along its march): the near end of a sign change
/// waiting for F there, else after moving the march on as far as it takes: to its
/// pixel's next box where its march is over, to the next of `pixels` (its last one traced
/// into `traced`) where its boxes are; None where no pixel is left.
fn next_sample(
    l: usize,
    (h, context): (&Hierarchy, (&Uniforms, &CompiledFormula, &[f64])),
    work: &mut Work<'_>,
    pixels: &mut impl Iterator<Item = (u32, u32)>,
    traced: &mut Vec<Traced>,
) -> Option<f32> {
    let u = context.0;
    let k_max = hits_kept(u);
    let lane = &mut work.lanes[l];
    if let Some(crossing) = &lane.waiting {
        return Some(crossing.ta);
    }
    loop {
        if let Some(march) = lane.march.as_mut() {
            let stop = stop_at(&lane.hits, k_max);
            if let Some(t) = march.next(stop, work.one_signed) {
                return Some(t);
            }
            lane.march = None;
        }
        if let Some(start) = lane.start {
            if let Some(b) = lane.boxes.get(lane.next_box) {
                lane.next_box += 1;
                let pixel = start.pixel(context, (work.evals, &mut lane.hits), work.one_signed);
                lane.march = pixel.march_of(start.o, b, 0);
                continue;
            }
            let tile = (&mut *work.tile.0, &mut *work.tile.1);
            let part = (lane.hits.as_slice(), &mut lane.deferred, lane.bracket);
            traced.push(Traced::keep(start, part, tile));
            lane.start = None;
        }
        let start = Start::of(u, pixels.next()?);
        boxes_of(h, u, start.o, work.walk, &mut lane.boxes);
        (lane.start, lane.next_box, lane.bracket) = (Some(start), 0, None);
        lane.hits.clear();
    }
}
