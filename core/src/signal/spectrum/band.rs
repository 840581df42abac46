//! One band: its filter state per block, the second pass over the blocks whose bound can
//! reach the peak so far, and the peak's instant.

use super::bound::*;
use super::emphasis::*;
pub(super) use super::skim::State;
pub(super) use super::tops::Filter;
use super::tops::{step, value};
use crate::signal::srs::Oscillator;

/// A block from the first pass: the state at its start and the [`Bound`] of each response.
#[derive(Clone, Copy, Default)]
pub(super) struct Mark {
    pub(super) start: State,
    pub(super) bound: [f32; 2],
}

impl Mark {
    pub(super) const ZERO: Self = Self {
        start: State {
            w1: 0.0,
            w2: 0.0,
            w3: 0.0,
        },
        bound: [0.0; 2],
    };
}

impl Filter {
    /// The recursion alone over `block` (the operations of [`Filter::tops`], so the same
    /// state).
    pub(super) fn skim(&self, s: State, block: &[f32]) -> State {
        super::skim::skim(self.a, s, block)
    }

    /// Both responses over `block`: the state after it and each response's largest `|y|`.
    pub(super) fn tops(&self, s: State, block: &[f32]) -> (State, [f32; 2]) {
        let mut keys = [0; 2];
        let end = super::tops::tops(self, s, &mut keys, block);
        (end, keys.map(value))
    }

    /// Both responses over the two zeros after the input (the ramp back to rest): each
    /// response's largest `|y|` and the outputs of both samples.
    pub(super) fn ramp_down(&self, mut s: State) -> ([f32; 2], [[f32; 2]; 2]) {
        let mut keys = [0; 2];
        let last = [0, 1].map(|_| step(self, &mut s, &mut keys, 0.0));
        (keys.map(value), last)
    }

    /// Each response's output before the sample whose state is `s`.
    pub(super) fn before(&self, s: State) -> [f32; 2] {
        self.num
            .map(|[b0, b1, b2]| b0 * s.w1 + b1 * s.w2 + b2 * s.w3)
    }

    /// Keeps a block's largest `|y|` if it is a response's largest so far, or as large and
    /// earlier (so that any order of blocks gives the first block with the largest, as one
    /// pass does).
    pub(super) fn settle(&self, best: &mut [Best; 2], tops: [f32; 2], from: usize, start: State) {
        let before = self.before(start);
        for ((best, top), before) in best.iter_mut().zip(tops).zip(before) {
            if top > best.value || (top == best.value && from < best.from) {
                *best = Best {
                    value: top,
                    from,
                    w1: start.w1,
                    w2: start.w2,
                    before,
                };
            }
        }
    }
}

/// One band: both responses over the input and two zeros after it (the ramp back to rest),
/// then each residual in closed form. At a rate `decimation` (> 1) times below the full
/// rate, the peaks between samples, where the full-rate filter would sample them; at the
/// full rate (1), the largest samples, as the reference takes them.
///
/// Two passes: the first runs the recursion alone, marking each block with its state and
/// its [`Bound`] (from `rests`, the input's [`rests`], in `marks`; blocks beyond either are
/// computed at once); the second computes the outputs of
/// the blocks whose bound reaches the largest `|y|` found so far, starting with the block of
/// the largest bound. A block it leaves could not have changed either peak, so the result is
/// the same, bit for bit, as one pass over every block.
#[inline(never)]
pub(super) fn band(
    input: Input,
    rests: &[Rest],
    marks: &mut [Mark],
    f_hz: f32,
    damping: f32,
    rate_hz: f32,
    decimation: f32,
) -> (f32, f32) {
    let Some([acc, pv]) = Oscillator::<f32>::pair(f_hz, damping, rate_hz) else {
        return (0.0, 0.0);
    };
    let filter = Filter {
        a: acc.a,
        num: [acc.b, pv.b],
    };
    let bound = Bound::new(acc.a, [acc.b, pv.b]);
    let n = input.len();
    let mut marked = 0;
    // Per response, the block of the largest bound and that bound.
    let mut first = [(0usize, f32::NEG_INFINITY); 2];
    let mut best = [Best::default(); 2];
    let mut buf = [0.0f32; BLOCK];
    let mut state = State::default();
    let mut from = 0;
    while from < n {
        let block = input.block(from, &mut buf);
        if block.is_empty() {
            break;
        }
        let k = from / BLOCK;
        match (bound, rests.get(k), marks.get_mut(k)) {
            (Some(bound), Some(&rest), Some(mark)) => {
                *mark = Mark {
                    start: state,
                    bound: bound.over(state.w1, state.w2, block, rest),
                };
                marked = k + 1;
                for (f, &u) in first.iter_mut().zip(&mark.bound) {
                    if u > f.1 {
                        *f = (k, u);
                    }
                }
                state = filter.skim(state, block);
            }
            // Unmarked (no bound, or beyond the marks): computed now.
            _ => {
                let (end, tops) = filter.tops(state, block);
                filter.settle(&mut best, tops, from, state);
                state = end;
            }
        }
        from += block.len();
    }
    // The two zeros after the input: always computed (their outputs start the residuals).
    let (tops, [[ya_1, yp_1], [ya_2, yp_2]]) = filter.ramp_down(state);
    filter.settle(&mut best, tops, n, state);
    // The marked blocks: those of the largest bounds first, then each whose bound reaches a
    // largest `|y|` so far.
    let mut evaluate = |k: usize, best: &mut [Best; 2]| {
        if let Some(mark) = marks.get(k) {
            let block = input.block(k * BLOCK, &mut buf);
            let (_, tops) = filter.tops(mark.start, block);
            filter.settle(best, tops, k * BLOCK, mark.start);
        }
    };
    if marked > 0 {
        evaluate(first[0].0, &mut best);
        if first[1].0 != first[0].0 {
            evaluate(first[1].0, &mut best);
        }
    }
    for k in 0..marked {
        // Computed unless both bounds are below (a bound that is not a number never is).
        let reaches = marks
            .get(k)
            .is_some_and(|m| !(m.bound[0] < best[0].value && m.bound[1] < best[1].value));
        if reaches && k != first[0].0 && k != first[1].0 {
            evaluate(k, &mut best);
            #[cfg(test)]
            super::tests::EXACT.with(|q| q.set(q.get() + 1));
        }
    }
    let [a1, a2] = filter.a;
    let peak = |best: &Best, num: [f32; 3]| {
        if decimation > 1.0 {
            if let Some([before, at, after]) = around(input, best, num, [a1, a2]) {
                return between(before, at, after, decimation);
            }
        }
        best.value
    };
    let [best_a, best_p] = &best;
    (
        peak(best_a, acc.b).max(acc.residual_peak(ya_1, ya_2)),
        peak(best_p, pv.b).max(pv.residual_peak(yp_1, yp_2)),
    )
}

/// The outputs before, at and after a response's largest `|y|` (the recursion run again
/// over its block with the same operations, so the same values); `None` at the very end.
pub(super) fn around(
    input: Input,
    best: &Best,
    num: [f32; 3],
    [a1, a2]: [f32; 2],
) -> Option<[f32; 3]> {
    let n = input.len();
    let (mut w1, mut w2, mut before) = (best.w1, best.w2, best.before);
    let x = |i: usize| if i < n { input.at(i) } else { 0.0 };
    for i in best.from..(best.from + BLOCK).min(n + 2) {
        let w = x(i) - a1 * w1 - a2 * w2;
        let y = num[0] * w + num[1] * w1 + num[2] * w2;
        if y.abs() >= best.value {
            if i + 1 >= n + 2 {
                return None;
            }
            let next = x(i + 1) - a1 * w - a2 * w1;
            return Some([before, y, num[0] * next + num[1] * w + num[2] * w1]);
        }
        (before, w2, w1) = (y, w1, w);
    }
    None
}
