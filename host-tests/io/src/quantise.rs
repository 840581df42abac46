//! Readings to the i16 counts the core pipeline takes: the gain that puts a full scale at
//! 32 000 counts, and rounding that saturates as an ADC does.

/// The gain, m/s² per count, that puts `full_scale_m_s2` at 32 000 counts (at least the
/// smallest full scale, [`crate::limits::LEVEL_M_S2`]: a recording of zeros has one too).
pub fn gain_for(full_scale_m_s2: f64) -> f64 {
    full_scale_m_s2.max(crate::limits::LEVEL_M_S2.low) / 32000.0
}

/// A file's values to the core's counts: times `scale` (the units, `--gain` and `--invert`)
/// to m/s², then over `gain` (m/s² per count) to counts, saturating as an ADC does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantiser {
    /// File value to m/s².
    pub scale: f64,
    /// m/s² per count.
    pub gain: f64,
}

impl Quantiser {
    /// A file value's count.
    #[inline]
    pub fn count(&self, value: f64) -> i16 {
        to_count(value * self.scale, self.gain)
    }

    /// A reading already in m/s² (a head read at `scale`), in counts.
    #[inline]
    pub fn count_m_s2(&self, a_m_s2: f64) -> i16 {
        to_count(a_m_s2, self.gain)
    }

    /// Readings already in m/s², in counts.
    pub fn counts_m_s2(&self, a_m_s2: &[f64]) -> Vec<i16> {
        a_m_s2.iter().map(|&a| self.count_m_s2(a)).collect()
    }
}

/// One reading in counts (saturating at the i16 rails, as an ADC does).
pub fn to_count(v: f64, gain: f64) -> i16 {
    round_to_i16(v / gain)
}

/// `x.round() as i16` (half away from zero, saturating, NaN to 0) without `round`, which on
/// x86-64's baseline is a library call: the truncation, and a step where the fraction
/// reaches a half (exact for every `f64`: beyond 2^52 there is no fraction).
#[inline]
pub fn round_to_i16(x: f64) -> i16 {
    let t = x as i64;
    let frac = x - t as f64;
    // Without a branch (noise makes the fraction's side a coin toss).
    let t = t.clamp(-(1 << 20), 1 << 20);
    let r = t + i64::from(frac >= 0.5) - i64::from(frac <= -0.5);
    r.clamp(i64::from(i16::MIN), i64::from(i16::MAX)) as i16
}

#[cfg(test)]
mod tests {
    use super::round_to_i16;

    #[test]
    fn rounding_to_counts_is_round_as_i16() {
        let mut edge = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            0.49999999999999994,
            -0.49999999999999994,
            32766.5,
            32767.49,
            32767.5,
            -32768.5,
            -32767.5,
            4.5e15 + 0.5,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            9.3e18,
            -9.3e18,
            f64::MIN_POSITIVE,
        ];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..100_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            edge.push((state as i64) as f64 / 2f64.powi(45));
            edge.push(f64::from_bits(state));
        }
        for x in edge {
            assert_eq!(round_to_i16(x), x.round() as i16, "{x:e}");
        }
    }
}
