//! An impact's captured window cut into frames for sending off the board: whole, or the
//! mean of every `every` samples, [`FRAME_LEN`] values a frame.
//!
//! The firmware sends the frames after the impact's analysis (`wave` and `wave_frame`
//! lines, docs/board.md); the host (`impact log`) puts them back together, knowing
//! from the numbering which frames the link dropped.

/// Values per frame: 64 i16 values are 128 bytes of defmt payload, well within the RTT
/// buffer (4 KiB), so a frame that does not fit is dropped whole, never cut.
pub const FRAME_LEN: usize = 64;

/// Values a window of `samples` gives at one value per `every` samples (`every` 0 is
/// taken as 1).
pub const fn values(samples: usize, every: u16) -> usize {
    let every = if every == 0 { 1 } else { every as usize };
    samples.div_ceil(every)
}

/// Frames a window of `samples` gives.
pub const fn frames(samples: usize, every: u16) -> usize {
    values(samples, every).div_ceil(FRAME_LEN)
}

/// The mean of `group` rounded to the nearest count (halves away from zero); 0 for none.
fn mean(group: &[i16]) -> i16 {
    let n = group.len() as i64;
    if n == 0 {
        return 0;
    }
    let sum: i64 = group.iter().map(|&v| i64::from(v)).sum();
    let rounded = if sum >= 0 {
        (2 * sum + n) / (2 * n)
    } else {
        -((-2 * sum + n) / (2 * n))
    };
    // The mean of i16 values is an i16.
    rounded.clamp(i64::from(i16::MIN), i64::from(i16::MAX)) as i16
}

/// Frame `k` of `samples` at one value per `every` samples into `out`; how many values it
/// holds (0 past the last frame).
pub fn frame(samples: &[i16], every: u16, k: usize, out: &mut [i16; FRAME_LEN]) -> usize {
    let every = usize::from(every.max(1));
    let first = k.saturating_mul(FRAME_LEN);
    let total = values(samples.len(), every as u16);
    let n = total.saturating_sub(first).min(FRAME_LEN);
    for (j, slot) in out.iter_mut().enumerate().take(n) {
        let from = (first + j).saturating_mul(every);
        let group = samples
            .get(from..from.saturating_add(every).min(samples.len()))
            .unwrap_or(&[]);
        *slot = if every == 1 {
            group.first().copied().unwrap_or(0)
        } else {
            mean(group)
        };
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_frames_give_back_the_window() {
        let x: [i16; 150] = core::array::from_fn(|i| (i as i16 - 75) * 300);
        assert_eq!(frames(x.len(), 1), 3);
        let mut out = [0; FRAME_LEN];
        let mut back = [0i16; 150];
        for k in 0..3 {
            let n = frame(&x, 1, k, &mut out);
            back[k * FRAME_LEN..k * FRAME_LEN + n].copy_from_slice(&out[..n]);
        }
        assert_eq!(back, x);
        assert_eq!(frame(&x, 1, 3, &mut out), 0);
    }

    #[test]
    fn decimated_frames_hold_rounded_means() {
        let x = [1i16, 2, -1, -2, 32767, 32767, -32768];
        let mut out = [0; FRAME_LEN];
        assert_eq!(values(x.len(), 2), 4);
        assert_eq!(frame(&x, 2, 0, &mut out), 4);
        // 1.5 -> 2, -1.5 -> -2, the rails kept, a last group of one.
        assert_eq!(&out[..4], &[2, -2, 32767, -32768]);
        assert_eq!(frame(&x, 0, 0, &mut out), 7);
    }
}
