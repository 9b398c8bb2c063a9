//! The progressive state's measurements of the GPU's runs.

use super::*;
use web_time::Duration;

/// A run of `rays` that took `ms`, the one before it done at `after`; when it is done.
fn landed(
    progressive: &mut Progressive,
    after: Instant,
    (rays, ms): (f64, u64),
    certified: bool,
) -> Instant {
    let done = after + Duration::from_millis(ms);
    let run = Run {
        squares: 1,
        rays,
        certified,
        planned_ms: 1.0,
        submitted: after,
        done: Arc::new(OnceLock::new()),
    };
    progressive.land(&run, done);
    done
}

#[test]
fn previews_are_sized_by_the_whole_picture_s_throughput_not_the_fastest_runs() {
    let mut progressive = Progressive::default();
    // One run of squares on M, then fifty of sky, a hundred times faster a ray.
    let mut at = landed(&mut progressive, Instant::now(), (1000.0, 100), false);
    for _ in 0..50 {
        at = landed(&mut progressive, at, (1000.0, 1), false);
    }
    // A certified run is not a preview's cost.
    landed(&mut progressive, at, (1.0, 500), true);
    progressive.take_throughput();
    let whole = 51_000.0 / 150.0;
    assert!(
        (progressive.throughput() - whole).abs() < 1e-6 * whole,
        "{} rays/ms, the picture's {whole}",
        progressive.throughput()
    );
}

#[test]
fn a_few_milliseconds_of_runs_leave_the_throughput_as_it_was() {
    let mut progressive = Progressive::default();
    let before = progressive.throughput();
    landed(&mut progressive, Instant::now(), (1e6, 5), false);
    progressive.take_throughput();
    assert_eq!(progressive.throughput(), before);
}
