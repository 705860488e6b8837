//! Telemetry from the control tick to the logging loop through a
//! `heapless::spsc::Queue`: the tick (in a drive, the control interrupt)
//! only enqueues a sample, never waits, and counts the samples a full
//! queue refuses; the logging loop (the idle loop) drains the queue at its
//! own pace and keeps the statistics the run reports.

use heapless::spsc::{Consumer, Producer};

/// Capacity of the telemetry queue (samples): the logging loop drains it
/// every [`DRAIN_EVERY`] ticks, well within.
pub const CAPACITY: usize = 64;

/// Ticks between two runs of the logging loop.
pub const DRAIN_EVERY: u32 = 32;

/// What one control tick reports.
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct Sample {
    /// Tracking error `x - x_ref` (rad).
    pub error: f32,
}

/// The control tick's end of the queue.
pub struct Sender<'q> {
    producer: Producer<'q, Sample>,
    /// Samples refused because the queue was full.
    pub overflows: u32,
}

impl<'q> Sender<'q> {
    /// An end for `producer`, with no overflow yet.
    pub fn new(producer: Producer<'q, Sample>) -> Self {
        Self {
            producer,
            overflows: 0,
        }
    }

    /// Hands `sample` over, or counts it lost: never blocks.
    pub fn send(&mut self, sample: Sample) {
        if self.producer.enqueue(sample).is_err() {
            self.overflows = self.overflows.saturating_add(1);
        }
    }
}

/// Tracking statistics, kept by the logging loop.
#[derive(Default)]
pub struct Stats {
    sum_sq: f32,
    /// Largest `|error|` (rad).
    pub max: f32,
    /// Samples received.
    pub count: u32,
}

impl Stats {
    /// Takes every sample waiting in the queue.
    pub fn drain(&mut self, consumer: &mut Consumer<'_, Sample>) {
        while let Some(s) = consumer.dequeue() {
            self.sum_sq += s.error * s.error;
            self.max = self.max.max(libm::fabsf(s.error));
            self.count += 1;
        }
    }

    /// RMS error (rad) over the samples received.
    pub fn rms(&self) -> f32 {
        if self.count == 0 {
            return 0.0;
        }
        libm::sqrtf(self.sum_sq / self.count as f32)
    }
}

/// A full queue refuses and counts, and the samples it took arrive in
/// order: run once at start-up (the firmware has no host test harness).
pub fn self_check() -> bool {
    let mut queue: heapless::spsc::Queue<Sample, 4> = heapless::spsc::Queue::new();
    let (producer, mut consumer) = queue.split();
    let mut sender = Sender::new(producer);
    for k in 0..5u8 {
        sender.send(Sample {
            error: f32::from(k),
        });
    }
    let mut stats = Stats::default();
    stats.drain(&mut consumer);
    // capacity 3: samples 0, 1, 2 kept (sum of squares 5), 3 and 4 refused
    sender.overflows == 2 && stats.count == 3 && stats.max == 2.0 && stats.sum_sq == 5.0
}
