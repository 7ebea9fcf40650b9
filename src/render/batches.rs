//! How many samples per pixel one parallel sweep over the image takes.
//!
//! A sweep ends when every thread has finished its rows: the threads wait for each other,
//! sleep, and are woken for the next sweep (on a virtual machine a sleeping core is slow
//! to wake). A sweep of one sample per pixel over a small image lasts milliseconds, and
//! sweeps of one sample cost 6–8 % of a 128 × 128 render at 64 spp here
//! (docs/design/integrator.md, "The film and passes"). After the first sample, sweeps take
//! as many samples per pixel as fill about [`TARGET`] — the time also bounds how late a
//! stop, a checkpoint or the live view sees the image. Each pixel still adds its samples
//! in ascending order, so the image is the same, bit for bit, whatever the batches.

use std::time::Duration;

/// About how long a sweep lasts once its passes' time is known.
pub const TARGET: Duration = Duration::from_millis(250);

/// What bounds the next batch, besides its time.
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    /// Samples per pixel still to take.
    pub remaining: u32,
    /// Samples per pixel until adaptive sampling next judges the pixels, if it does.
    pub until_check: Option<u32>,
    /// The path guide is still learning: it changes after every sample.
    pub training: bool,
    /// Time left before the time limit, if there is one.
    pub time_left: Option<Duration>,
}

/// The sizes of successive batches, from the time the previous ones took.
#[derive(Clone, Copy, Debug, Default)]
pub struct Batches {
    /// Time of one pass (one sample per pixel) in the last batch.
    per_pass: Option<Duration>,
    /// Passes in the last batch.
    last: u32,
}

impl Batches {
    /// Passes in the next batch: those that fill [`TARGET`], at most twice the last batch
    /// (a first pass timed short by chance cannot make a long batch), and within `bounds`;
    /// at least one.
    pub fn next(&self, bounds: Bounds) -> u32 {
        let Some(per_pass) = self.per_pass.filter(|_| !bounds.training) else {
            return 1;
        };
        let fits = |time: Duration| (time.as_secs_f64() / per_pass.as_secs_f64().max(1e-9)) as u32;
        let mut passes = fits(TARGET)
            .min(self.last.saturating_mul(2))
            .min(bounds.remaining);
        if let Some(until_check) = bounds.until_check {
            passes = passes.min(until_check);
        }
        if let Some(time_left) = bounds.time_left {
            passes = passes.min(fits(time_left));
        }
        passes.max(1)
    }

    /// Records that a batch of `passes` passes took `elapsed`.
    pub fn record(&mut self, passes: u32, elapsed: Duration) {
        self.per_pass = Some(elapsed / passes.max(1));
        self.last = passes;
    }

    /// Time of one pass in the last batch, once one is done.
    pub fn per_pass(&self) -> Option<Duration> {
        self.per_pass
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn open(remaining: u32) -> Bounds {
        Bounds {
            remaining,
            until_check: None,
            training: false,
            time_left: None,
        }
    }

    #[test]
    fn batches_start_at_one_and_at_most_double_towards_the_target() {
        let mut batches = Batches::default();
        assert_eq!(batches.next(open(1000)), 1);
        let pass = Duration::from_millis(10);
        let mut sizes = Vec::new();
        for _ in 0..7 {
            let n = batches.next(open(1000));
            sizes.push(n);
            batches.record(n, pass * n);
        }
        // 250 ms at 10 ms a pass: 25, reached by doubling from one.
        assert_eq!(sizes, [1, 2, 4, 8, 16, 25, 25]);
    }

    #[test]
    fn a_batch_stays_within_the_samples_left_the_next_check_and_the_time_left() {
        let mut batches = Batches::default();
        batches.record(16, Duration::from_millis(16));
        assert_eq!(batches.next(open(1000)), 32);
        assert_eq!(batches.next(open(5)), 5);
        let check = Bounds {
            until_check: Some(3),
            ..open(1000)
        };
        assert_eq!(batches.next(check), 3);
        let late = Bounds {
            time_left: Some(Duration::from_millis(7)),
            ..open(1000)
        };
        assert_eq!(batches.next(late), 7);
        // Never fewer than one: the caller decides whether to stop.
        let none_left = Bounds {
            time_left: Some(Duration::ZERO),
            ..open(1000)
        };
        assert_eq!(batches.next(none_left), 1);
        let training = Bounds {
            training: true,
            ..open(1000)
        };
        assert_eq!(batches.next(training), 1);
    }

    #[test]
    fn slow_passes_make_batches_of_one() {
        let mut batches = Batches::default();
        batches.record(1, Duration::from_secs(2));
        assert_eq!(batches.next(open(100)), 1);
        batches.record(1, Duration::ZERO);
        assert_eq!(batches.next(open(100)), 2);
    }
}
