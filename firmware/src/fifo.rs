//! Samples lost by a sensor's FIFO, counted against the sensor's own sample stream: a FIFO
//! polled by the MCU (the ADXL375's, on the board and emulated) says how many samples wait
//! and whether it overran, never how many it overwrote. Hardware-free (`host-tests/tests/
//! adxl375.rs` includes this file).
//!
//! Between two polls the sensor produced exactly the entries the second poll finds (each
//! poll reads all that its entry count showed, and reads that count first), so while the
//! FIFO does not overrun the samples read over the time between polls *is* the sensor's
//! output rate, measured on its own clock against the MCU's: good to one sample over the
//! whole clean stretch, whatever the part's rate tolerance. The ADXL375's overrun flag means
//! the FIFO *filled* (in stream and FIFO modes the data sheet sets it when the FIFO is
//! full, not only when an entry is overwritten), so a poll with the flag set lost what the
//! measured rate produced since the previous poll less what it read, which may be none (a
//! late poll that finds 32 or 33 entries): the flag alone is no loss, and a poll that finds
//! fewer entries than the FIFO holds lost none at all (entries leave only when read, so an
//! overwrite leaves it full). So a rate error never
//! adds up into a false gap, a full FIFO is not a gap, and the estimate's error is bounded by
//! one poll interval's worth of the rate's uncertainty (a sample or two).

/// Clean time, µs, before the measured rate replaces the nominal one (a tenth of a second:
/// several hundred samples at the ADXL375's rates, so the measurement's ±1 sample is < 1 %).
pub const MIN_MEASURED_US: u64 = 100_000;

/// How far the measured rate may stray from the nominal one before it is ignored (a rate off
/// by more is a broken measurement, not the part's tolerance).
const MAX_RATE_DEVIATION: f64 = 0.2;

/// The loss accounting of one polled FIFO.
#[derive(Clone, Debug)]
pub struct LossCounter {
    nominal_hz: f64,
    /// Entries a poll finds at most (the FIFO and the output registers): only a poll that
    /// finds it this full can follow an overwrite, since entries go only when read.
    capacity: usize,
    /// When the previous poll read the sensor's entry count, µs (MCU clock).
    last_us: u64,
    /// Samples read, and µs elapsed, over the intervals that ended without an overrun.
    clean_samples: u64,
    clean_us: u64,
}

impl LossCounter {
    /// The sensor started producing at `start_us` (MCU clock, µs) at a nominal
    /// `nominal_hz` samples per second into a FIFO a poll finds at most `capacity` entries in.
    pub fn new(nominal_hz: f32, capacity: usize, start_us: u64) -> Self {
        Self {
            nominal_hz: f64::from(nominal_hz),
            capacity,
            last_us: start_us,
            clean_samples: 0,
            clean_us: 0,
        }
    }

    /// The sensor's output rate, samples per second: measured over the clean intervals once
    /// they last [`MIN_MEASURED_US`], else (or if implausible) the nominal rate.
    pub fn rate_hz(&self) -> f64 {
        if self.clean_us < MIN_MEASURED_US {
            return self.nominal_hz;
        }
        let measured = self.clean_samples as f64 * 1e6 / self.clean_us as f64;
        if (measured / self.nominal_hz - 1.0).abs() > MAX_RATE_DEVIATION {
            self.nominal_hz
        } else {
            measured
        }
    }

    /// One poll: at `now_us` (taken just before the sensor's entry count was read) it read
    /// `read` samples, and `overrun` is the sensor's flag (the FIFO filled). Returns how many
    /// samples the sensor produced and overwrote before the ones read (0 without the flag,
    /// and 0 when the clock says every sample produced was read). A poll that
    /// failed (nothing read, the FIFO left as it was) is not a poll: skip the call.
    pub fn poll(&mut self, now_us: u64, read: usize, overrun: bool) -> u64 {
        let interval_us = now_us.saturating_sub(self.last_us);
        self.last_us = now_us;
        // Below capacity the FIFO never overflowed since the last poll, flag or not.
        let full = read >= self.capacity;
        let read = read as u64;
        if !overrun || !full {
            self.clean_samples = self.clean_samples.saturating_add(read);
            self.clean_us = self.clean_us.saturating_add(interval_us);
            return 0;
        }
        let produced = self.rate_hz() * interval_us as f64 * 1e-6;
        // `produced` is finite and non-negative; the cast saturates.
        let produced = (produced + 0.5) as u64;
        let lost = produced.saturating_sub(read);
        if lost == 0 {
            // Full, nothing overwritten: a clean interval too (leaving the full ones out
            // would measure the rate over the shorter intervals only, biased low).
            self.clean_samples = self.clean_samples.saturating_add(read);
            self.clean_us = self.clean_us.saturating_add(interval_us);
        }
        lost
    }
}
