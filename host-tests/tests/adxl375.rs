//! Host tests of the firmware's ADXL375 driver (`firmware/src/adxl375.rs`, which only
//! depends on `embedded-hal-async`): exact SPI traffic against `embedded-hal-mock`, FIFO
//! behaviour against a small simulated ADXL375, and errors from a failing bus; and the loss
//! accounting of its polled FIFO (`firmware/src/fifo.rs`) against a part whose clock
//! is off nominal, polled with jitter.

// The driver and the FIFO's loss accounting (shared by the board and the emulator) are the
// firmware library's, built for the host.
use impact_firmware::{adxl375, fifo};

use std::collections::VecDeque;
use std::future::Future;
use std::pin::pin;
use std::task::{Context, Poll, Waker};

use adxl375::{reg, Adxl375, DataRate, Error, Sample};
use embedded_hal_async::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::spi::{Mock, Transaction as T};
use std::cell::RefCell;
use std::rc::Rc;

/// Runs a future whose I/O never waits (mocks answer at once).
fn block_on<F: Future>(future: F) -> F::Output {
    let mut future = pin!(future);
    let mut cx = Context::from_waker(Waker::noop());
    loop {
        if let Poll::Ready(out) = future.as_mut().poll(&mut cx) {
            return out;
        }
    }
}

/// Expected traffic of a one-register read.
fn read_reg(address: u8, value: u8) -> Vec<T<u8>> {
    vec![
        T::transaction_start(),
        T::write(0x80 | address),
        T::read(value),
        T::transaction_end(),
    ]
}

/// Expected traffic of a one-register write.
fn write_reg(address: u8, value: u8) -> Vec<T<u8>> {
    vec![
        T::transaction_start(),
        T::write_vec(vec![address, value]),
        T::transaction_end(),
    ]
}

/// Expected traffic of one FIFO pop: multi-byte read of DATAX0..DATAZ1 (the 5 us pop delay
/// follows, chip select high: see `each_fifo_pop_waits_after_chip_select_rises`).
fn read_data(bytes: [u8; 6]) -> Vec<T<u8>> {
    vec![
        T::transaction_start(),
        T::write(0x80 | 0x40 | 0x32),
        T::read_vec(bytes.to_vec()),
        T::transaction_end(),
    ]
}

#[test]
fn init_checks_the_id_then_configures_in_standby_and_measures() {
    let expected: Vec<T<u8>> = [
        read_reg(0x00, 0xE5),       // DEVID
        write_reg(0x2D, 0x00),      // POWER_CTL: standby
        write_reg(0x31, 0x0B),      // DATA_FORMAT: D3, D1, D0 set (fixed on the ADXL375)
        write_reg(0x2C, 0x0F),      // BW_RATE: 3200 Hz
        write_reg(0x2E, 0x00),      // INT_ENABLE: none
        write_reg(0x38, 0x00),      // FIFO_CTL: bypass (empties the FIFO)
        write_reg(0x38, 0x80 | 16), // FIFO_CTL: stream, watermark 16
        write_reg(0x2D, 0x08),      // POWER_CTL: measure
    ]
    .concat();
    let mut spi = Mock::new(&expected);
    let mut sensor = Adxl375::new(spi.clone(), NoopDelay);
    assert_eq!(block_on(sensor.init(DataRate::Hz3200)), Ok(()));
    spi.done();
}

#[test]
fn wrong_device_id_is_an_error_and_nothing_is_written() {
    for found in [0x00, 0xFF, 0xAD, 0xE6] {
        let expected = read_reg(0x00, found);
        let mut spi = Mock::new(&expected);
        let mut sensor = Adxl375::new(spi.clone(), NoopDelay);
        assert_eq!(
            block_on(sensor.init(DataRate::Hz3200)),
            Err(Error::WrongDeviceId { found })
        );
        spi.done();
    }
}

#[test]
fn fifo_read_pops_each_entry_with_one_multibyte_read() {
    let expected: Vec<T<u8>> = [
        read_reg(0x39, 0x80 | 2), // FIFO_STATUS: trigger bit set (ignored), 2 entries
        read_reg(0x30, 0x82),     // INT_SOURCE: data ready + watermark, no overrun
        read_data([0x14, 0x00, 0xEC, 0xFF, 0x00, 0xF0]),
        read_data([0xFF, 0x0F, 0x01, 0x00, 0xFF, 0xFF]),
    ]
    .concat();
    let mut spi = Mock::new(&expected);
    let mut sensor = Adxl375::new(spi.clone(), NoopDelay);
    let mut out = [Sample::default(); 4];
    assert_eq!(block_on(sensor.read_fifo(&mut out)), Ok(2));
    // 13-bit two's complement, right-justified and sign-extended: -4096..=4095.
    assert_eq!(
        out[0],
        Sample {
            x: 20,
            y: -20,
            z: -4096
        }
    );
    assert_eq!(
        out[1],
        Sample {
            x: 4095,
            y: 1,
            z: -1
        }
    );
    assert_eq!(out[2], Sample::default());
    spi.done();
}

#[test]
fn empty_fifo_reads_no_data() {
    let expected: Vec<T<u8>> = [read_reg(0x39, 0), read_reg(0x30, 0)].concat();
    let mut spi = Mock::new(&expected);
    let mut sensor = Adxl375::new(spi.clone(), NoopDelay);
    let mut out = [Sample::default(); 4];
    assert_eq!(block_on(sensor.read_fifo(&mut out)), Ok(0));
    spi.done();
}

#[test]
fn counts_convert_at_49_mg_per_lsb() {
    let one_g = 9.806_65_f32;
    let sample = Sample {
        x: 20,
        y: -20,
        z: 4095,
    };
    let [x, y, z] = sample.to_m_per_s2();
    assert!((x - 0.98 * one_g).abs() < 1e-4);
    assert!((y + 0.98 * one_g).abs() < 1e-4);
    // Full scale: 4095 * 49 mg = 200.7 g.
    assert!((z / one_g - 200.655).abs() < 1e-3);
    assert_eq!(adxl375::counts_to_m_per_s2(0), 0.0);
    assert_eq!(DataRate::Hz3200.hz(), 3200);
    assert_eq!(DataRate::Hz100 as u8, 0x0A);
}

/// What the simulated bus saw, in order: one command byte per transaction, and [`DELAY`] for
/// each delay the driver waited (between transactions: chip select high).
type Events = Rc<RefCell<Vec<u8>>>;

/// The mark of a delay in [`Events`].
const DELAY: u8 = 0xDD;

/// A delay that only records itself.
struct LogDelay(Events);

impl embedded_hal_async::delay::DelayNs for LogDelay {
    async fn delay_ns(&mut self, ns: u32) {
        assert!(ns >= 5_000, "the FIFO pop delay is 5 us: {ns} ns");
        self.0.borrow_mut().push(DELAY);
    }
}

/// A register-level ADXL375: 64 registers, a FIFO of samples, the overrun flag.
struct SimAdxl375 {
    regs: [u8; 64],
    fifo: VecDeque<Sample>,
    overrun: bool,
    /// Commands seen, one per transaction, and the delays between them.
    commands: Events,
}

impl SimAdxl375 {
    fn with_fifo(samples: impl IntoIterator<Item = Sample>, overrun: bool) -> Self {
        let mut regs = [0u8; 64];
        regs[usize::from(reg::DEVID)] = 0xE5;
        Self {
            regs,
            fifo: samples.into_iter().collect(),
            overrun,
            commands: Events::default(),
        }
    }

    /// The sensor on this bus, with a delay that logs into the same event list.
    fn sensor(self) -> Adxl375<Self, LogDelay> {
        let delay = LogDelay(self.commands.clone());
        Adxl375::new(self, delay)
    }

    fn read(&mut self, address: u8) -> u8 {
        match address {
            reg::FIFO_STATUS => self.fifo.len() as u8,
            reg::INT_SOURCE => u8::from(self.overrun) | if self.fifo.is_empty() { 0 } else { 0x80 },
            0x32..=0x37 => {
                let s = self.fifo.front().copied().unwrap_or_default();
                let bytes = [s.x.to_le_bytes(), s.y.to_le_bytes(), s.z.to_le_bytes()].concat();
                bytes[usize::from(address - 0x32)]
            }
            _ => self.regs[usize::from(address & 0x3F)],
        }
    }
}

impl ErrorType for SimAdxl375 {
    type Error = ErrorKind;
}

impl SpiDevice for SimAdxl375 {
    async fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        let mut command: Option<u8> = None;
        let mut address = 0u8;
        let mut data_read = false;
        for op in ops.iter_mut() {
            match op {
                Operation::Write(bytes) => {
                    let (&first, rest) = bytes.split_first().ok_or(ErrorKind::Other)?;
                    let cmd = *command.get_or_insert(first);
                    address = cmd & 0x3F;
                    if cmd & 0x80 == 0 {
                        for &value in rest {
                            self.regs[usize::from(address)] = value;
                            address += 1;
                        }
                    }
                }
                Operation::Read(buf) => {
                    let cmd = command.ok_or(ErrorKind::Other)?;
                    let multi = cmd & 0x40 != 0;
                    if buf.len() > 1 && !multi {
                        return Err(ErrorKind::Other);
                    }
                    for byte in buf.iter_mut() {
                        *byte = self.read(address);
                        data_read |= (0x32..=0x37).contains(&address);
                        address += 1;
                    }
                }
                Operation::DelayNs(_) => {}
                _ => return Err(ErrorKind::Other),
            }
        }
        self.commands.borrow_mut().extend(command);
        // Reading data pops one FIFO level on chip-select release and clears the overrun.
        if data_read {
            self.fifo.pop_front();
            self.overrun = false;
        }
        Ok(())
    }
}

fn ramp(n: i16) -> impl Iterator<Item = Sample> {
    (0..n).map(|i| Sample {
        x: i,
        y: -i,
        z: 100 * i,
    })
}

#[test]
fn fifo_read_stops_at_the_buffer_and_leaves_the_rest() {
    let mut sensor = SimAdxl375::with_fifo(ramp(10), false).sensor();
    let mut out = [Sample::default(); 4];
    assert_eq!(block_on(sensor.read_fifo(&mut out)), Ok(4));
    assert_eq!(out.to_vec(), ramp(4).collect::<Vec<_>>());
    assert_eq!(block_on(sensor.fifo_entries()), Ok(6));

    let mut rest = [Sample::default(); 33];
    assert_eq!(block_on(sensor.read_fifo(&mut rest)), Ok(6));
    assert_eq!(rest[..6].to_vec(), ramp(10).skip(4).collect::<Vec<_>>());
    let sim = sensor.release();
    assert!(sim.fifo.is_empty());
    // FIFO_STATUS, INT_SOURCE, 4 pops; then FIFO_STATUS; FIFO_STATUS, INT_SOURCE, 6 pops;
    // every pop followed by the pop delay, outside the transaction (chip select high).
    let pop = [0x80 | 0x40 | 0x32, DELAY];
    let mut expected = vec![0x80 | 0x39, 0x80 | 0x30];
    expected.extend(pop.repeat(4));
    expected.extend([0x80 | 0x39, 0x80 | 0x39, 0x80 | 0x30]);
    expected.extend(pop.repeat(6));
    assert_eq!(*sim.commands.borrow(), expected);
}

#[test]
fn fifo_overrun_is_reported_after_draining_and_then_clears() {
    let mut sensor = SimAdxl375::with_fifo(ramp(33), true).sensor();
    let mut out = [Sample::default(); 33];
    assert_eq!(
        block_on(sensor.read_fifo(&mut out)),
        Err(Error::FifoOverrun { samples_read: 33 })
    );
    assert_eq!(out.to_vec(), ramp(33).collect::<Vec<_>>());
    // Draining cleared the flag: the next read is clean.
    assert_eq!(block_on(sensor.read_fifo(&mut out)), Ok(0));
}

#[test]
fn init_on_the_simulated_sensor_sets_the_registers() {
    let mut sensor = SimAdxl375::with_fifo([], false).sensor();
    assert_eq!(block_on(sensor.init(DataRate::Hz1600)), Ok(()));
    let sim = sensor.release();
    assert_eq!(sim.regs[usize::from(reg::DATA_FORMAT)], 0x0B);
    assert_eq!(sim.regs[usize::from(reg::BW_RATE)], 0x0E);
    assert_eq!(sim.regs[usize::from(reg::FIFO_CTL)], 0x90);
    assert_eq!(sim.regs[usize::from(reg::POWER_CTL)], 0x08);
}

/// An SPI device whose every transaction fails.
struct BrokenBus;

impl ErrorType for BrokenBus {
    type Error = ErrorKind;
}

impl SpiDevice for BrokenBus {
    async fn transaction(&mut self, _ops: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        Err(ErrorKind::ModeFault)
    }
}

#[test]
fn bus_errors_are_passed_up() {
    let mut sensor = Adxl375::new(BrokenBus, NoopDelay);
    assert_eq!(
        block_on(sensor.init(DataRate::Hz3200)),
        Err(Error::Spi(ErrorKind::ModeFault))
    );
    let mut out = [Sample::default(); 4];
    assert_eq!(
        block_on(sensor.read_fifo(&mut out)),
        Err(Error::Spi(ErrorKind::ModeFault))
    );
    assert_eq!(
        block_on(sensor.read_register(reg::DEVID)),
        Err(Error::Spi(ErrorKind::ModeFault))
    );
    assert_eq!(
        block_on(sensor.write_register(reg::POWER_CTL, 0)),
        Err(Error::Spi(ErrorKind::ModeFault))
    );
}

#[test]
fn the_resultant_of_three_axes_is_the_rounded_magnitude() {
    let exact = |s: Sample| {
        let (x, y, z) = (s.x as f64, s.y as f64, s.z as f64);
        (x * x + y * y + z * z).sqrt()
    };
    let mut cases = vec![
        Sample { x: 0, y: 0, z: 0 },
        Sample { x: 3, y: 4, z: 0 },
        Sample {
            x: -4096,
            y: -4096,
            z: -4096,
        },
        Sample {
            x: 4095,
            y: -4096,
            z: 4095,
        },
        Sample { x: 0, y: 0, z: -1 },
        Sample { x: 1, y: 1, z: 0 },
    ];
    let mut state = 0x9e37_79b9u32;
    for _ in 0..100_000 {
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state % 8192) as i16 - 4096
        };
        cases.push(Sample {
            x: next(),
            y: next(),
            z: next(),
        });
    }
    for s in cases {
        let r = s.magnitude();
        let e = exact(s);
        assert!((r as f64 - e).abs() <= 0.5, "{s:?}: {r} vs {e}");
        // At a rail on any axis the plain magnitude reaches 4095.
        if [s.x, s.y, s.z].iter().any(|v| *v >= 4095 || *v <= -4096) {
            assert!(r >= 4095);
        }
    }
    assert_eq!(Sample { x: 3, y: 4, z: 0 }.magnitude(), 5);
    assert_eq!(
        Sample {
            x: -4096,
            y: -4096,
            z: -4096
        }
        .magnitude(),
        7094
    );
}

/// A part in stream mode on its own clock (`rate_hz`, its first sample one period after 0),
/// polled at the given MCU times (µs): each poll reads every entry (at most 33) and the
/// overrun flag, which the part sets when its 32 FIFO levels fill (overwritten or not).
/// Returns, per poll, (samples read, overrun flag, samples overwritten since the previous
/// poll).
fn polled_part(rate_hz: f64, polls_us: &[u64]) -> Vec<(usize, bool, u64)> {
    let mut produced = 0u64;
    let mut waiting = 0u64;
    let mut out = Vec::new();
    for &t in polls_us {
        let due = (t as f64 * 1e-6 * rate_hz).floor() as u64;
        let new = due - produced;
        produced = due;
        waiting += new;
        let overwritten = waiting.saturating_sub(33);
        waiting -= overwritten;
        out.push((waiting as usize, waiting >= 32, overwritten));
        waiting = 0;
    }
    out
}

/// Poll times every `period_us` from `from_us` with up to ±`jitter_us` of deterministic
/// jitter, `n` of them.
fn poll_times(from_us: u64, period_us: u64, jitter_us: u64, n: usize) -> Vec<u64> {
    let mut state = 0x2545_f491u32;
    (0..n as u64)
        .map(|k| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            let j = u64::from(state) % (2 * jitter_us + 1);
            from_us + k * period_us + j - jitter_us.min(k * period_us + from_us)
        })
        .collect()
}

#[test]
fn a_part_off_its_nominal_rate_never_makes_a_false_gap() {
    // 2 % fast and 2 % slow parts, polled every 5 ms ± 0.4 ms for 100 s: no overrun, so
    // nothing is counted lost (the old estimate, MCU time since the start times the nominal
    // rate, would have counted 6400 samples lost for the fast part, and hidden as many real
    // losses for the slow one); the rate is measured to 0.05 %.
    for rate in [3200.0 * 1.02, 3200.0 * 0.98] {
        let polls = poll_times(5_000, 5_000, 400, 20_000);
        let mut counter = fifo::LossCounter::new(3200.0, 33, 0);
        let mut lost = 0;
        for (&t, (read, overrun, _)) in polls.iter().zip(polled_part(rate, &polls)) {
            assert!(!overrun);
            lost += counter.poll(t, read, overrun);
        }
        assert_eq!(lost, 0);
        let measured = counter.rate_hz();
        assert!(
            (measured / rate - 1.0).abs() < 5e-4,
            "measured {measured} S/s of {rate}"
        );
    }
}

#[test]
fn an_overrun_is_counted_to_a_sample_at_the_measured_rate() {
    // A part 1.5 % slow, polled every 5 ms ± 0.4 ms; after 10 s one poll comes 15, 30 or
    // 300 ms late. The count of what the FIFO overwrote is the truth to within one sample;
    // with the nominal rate it would be off by 1.5 % of the interval (14 samples at 300 ms).
    let rate = 3200.0 * 0.985;
    for late_us in [15_000u64, 30_000, 300_000] {
        let mut polls = poll_times(5_000, 5_000, 400, 4_000);
        for t in polls.iter_mut().skip(2_000) {
            *t += late_us;
        }
        let mut counter = fifo::LossCounter::new(3200.0, 33, 0);
        let (mut lost, mut truth) = (0, 0);
        for (&t, (read, overrun, overwritten)) in polls.iter().zip(polled_part(rate, &polls)) {
            lost += counter.poll(t, read, overrun);
            truth += overwritten;
        }
        assert!(truth > 0, "the FIFO overran");
        assert!(
            lost.abs_diff(truth) <= 1,
            "{late_us} us late: counted {lost}, the part overwrote {truth}"
        );
    }
}

#[test]
fn an_overrun_before_the_rate_is_known_uses_the_nominal_rate() {
    let mut counter = fifo::LossCounter::new(3200.0, 33, 0);
    // 20 ms after the start: 64 produced, 33 read.
    assert_eq!(counter.poll(20_000, 33, true), 31);
    // The flag with 32 entries (the FIFO filled, nothing was overwritten) is no loss; it
    // counted one before. With 33 and nothing missing by the clock (10.3 ms: 33 samples)
    // neither.
    assert_eq!(counter.poll(30_000, 32, true), 0);
    assert_eq!(counter.poll(40_300, 33, true), 0);
    assert_eq!(counter.rate_hz(), 3200.0);
}

/// A late poll that finds the FIFO just full (32 or 33 entries, the flag set) lost nothing:
/// a part 1 % fast polled every 5 ms ± 0.4 ms for 100 s, one poll in 25 late by 4.5–5.3 ms
/// (so it finds 31–35 entries): the flag is set at most of them. Each poll's count is its
/// truth to within a sample, and a flagged poll that lost nothing is no gap but where the
/// clock's rounding cannot tell (a few percent; counting the flag as one lost made every one
/// of them a gap).
#[test]
fn a_full_fifo_is_no_gap() {
    let rate = 3200.0 * 1.01;
    let mut polls = poll_times(5_000, 5_000, 400, 20_000);
    let mut late = 0;
    for (k, t) in polls.iter_mut().enumerate() {
        if k % 25 == 24 {
            late += 4_500 + (k as u64 * 37) % 800;
        }
        *t += late;
    }
    let mut counter = fifo::LossCounter::new(3200.0, 33, 0);
    let (mut full, mut false_gaps, mut flagged) = (0, 0, 0);
    for (&t, (read, overrun, overwritten)) in polls.iter().zip(polled_part(rate, &polls)) {
        let lost = counter.poll(t, read, overrun);
        assert!(
            lost.abs_diff(overwritten) <= 1,
            "at {t} us: {lost} for {overwritten}"
        );
        flagged += usize::from(overrun);
        if overrun && overwritten == 0 {
            full += 1;
            false_gaps += usize::from(lost > 0);
        }
    }
    assert!(
        flagged > 400 && full > 200,
        "{flagged} flagged, {full} full only"
    );
    assert!(
        false_gaps * 20 < full,
        "{false_gaps} gaps of {full} polls that found the FIFO full and lost nothing"
    );
}

/// The board's resultant (`adxl375::Picker`) is the magnitude of the axes each zeroed: at
/// rest under 1 g on z it reads about 0, not 20 counts; and an axis at either rail, its
/// zero 20 counts (1 g) or 64 counts (3.1 g) off 0 toward that rail, reads at least
/// `RESULTANT_CLIP`, the scene's clip level, so the impact is flagged clipped.
#[test]
fn the_zeroed_resultant_reaches_the_clip_level_at_any_rail() {
    use adxl375::{Axis, Picker, AXIS_RAILS, RESULTANT_CLIP};
    let mut scene = impact_core::Scene::new(
        impact_core::signal::Calibration {
            gain_m_s2_per_count: 0.049 * 9.80665,
            sample_rate_hz: 3200.0,
        },
        10.0,
    );
    scene.edge_m_s2 = 2.0;
    let settings = scene.axes_zero([AXIS_RAILS; 3]);
    for axis in 0..3 {
        for rail in [AXIS_RAILS.0, AXIS_RAILS.1] {
            for lean in [20i16, 64] {
                let mut rest = [0i16; 3];
                rest[axis] = if rail > 0 { lean } else { -lean };
                let mut picker = Picker::new(Axis::Resultant, settings);
                // A second of rest (its noise one count) for the zeros to learn.
                let mut at_rest = 0;
                for k in 0..3200 {
                    let mut s = rest;
                    s[(axis + 1) % 3] += (k % 3) as i16 - 1;
                    at_rest = picker.pick(s);
                }
                assert!(at_rest <= 2, "axis {axis}, rest {rest:?}: {at_rest}");
                let mut hit = rest;
                hit[axis] = rail;
                let r = picker.pick(hit);
                assert!(
                    r >= RESULTANT_CLIP,
                    "axis {axis} at {rail}, zero {rest:?}: {r} < {RESULTANT_CLIP}"
                );
            }
        }
    }
}
