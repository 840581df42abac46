//! The capture's tail: with a CFC the capture goes on after the impact's window for the
//! filter's padding after the contact, while the stream is idle again; it is handed over when
//! the padding is in, at the next trigger, a gap or the end of the stream.

use super::Stream;
use crate::capture::Sink;

impl<const PRE: usize> Stream<PRE> {
    /// The samples up to `until` into the capture whose tail is being taken (before they are
    /// kept; at a coarser step once it is full if `decimate`, see [`Stream::end`]); hands it
    /// over once the tail is complete or the capture full.
    #[cold]
    #[inline(never)]
    pub(super) fn extend_tail<const CAP: usize>(
        &mut self,
        (until, decimate): (u64, bool),
        samples: &[i16],
        sink: &mut impl Sink<CAP>,
    ) {
        let n = usize::try_from(until.saturating_sub(self.run.index))
            .unwrap_or(usize::MAX)
            .min(samples.len());
        let part = samples.get(..n).unwrap_or(&[]);
        let full = sink.buffer().is_none_or(|c| {
            let took = if decimate {
                c.extend_decimating(part)
            } else {
                c.extend(part)
            };
            took < part.len()
        });
        if full || n < samples.len() || self.run.index + n as u64 >= until {
            self.hand_over(sink);
        }
    }

    /// Hands over the capture whose tail is being taken, if any.
    pub(super) fn hand_over<const CAP: usize>(&mut self, sink: &mut impl Sink<CAP>) {
        if self.run.tail.take().is_some() {
            sink.captured(&self.scene);
            self.run.handed_over = true;
        }
    }
}
