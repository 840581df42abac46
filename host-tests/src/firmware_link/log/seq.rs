//! The sequence numbers (`seq`) of a run's data lines, kept as spans.

/// The distinct sequence numbers of a run's lines, as runs of consecutive numbers: memory
/// grows with the gaps, not with the lines.
#[derive(Default)]
pub(super) struct SeqSet {
    /// First number of each run of consecutive numbers, and its last.
    spans: std::collections::BTreeMap<u32, u32>,
    /// Distinct numbers held.
    len: u64,
}

impl SeqSet {
    pub(super) fn insert(&mut self, s: u32) {
        let before = self.spans.range(..=s).next_back().map(|(&a, &b)| (a, b));
        if before.is_some_and(|(_, last)| s <= last) {
            return;
        }
        self.len += 1;
        let after = s
            .checked_add(1)
            .and_then(|next| self.spans.get(&next).map(|&last| (next, last)));
        match (before, after) {
            (Some((a, last)), Some((next, end))) if last.checked_add(1) == Some(s) => {
                self.spans.remove(&next);
                self.spans.insert(a, end);
            }
            (Some((a, last)), _) if last.checked_add(1) == Some(s) => {
                self.spans.insert(a, s);
            }
            (_, Some((next, end))) => {
                self.spans.remove(&next);
                self.spans.insert(s, end);
            }
            _ => {
                self.spans.insert(s, s);
            }
        }
    }

    /// Numbers missing before the last one held.
    pub(super) fn missing(&self) -> u64 {
        match self.spans.last_key_value() {
            Some((_, &last)) => u64::from(last) + 1 - self.len,
            None => 0,
        }
    }

    /// The first `n` numbers missing (before the last one held).
    pub(super) fn first_missing(&self, n: usize) -> Vec<u32> {
        let mut out = Vec::new();
        let mut next = 0u32;
        for (&a, &b) in &self.spans {
            out.extend((next..a).take(n - out.len()));
            if out.len() == n {
                break;
            }
            next = b.saturating_add(1);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequence_numbers_are_kept_as_spans_and_the_missing_ones_named() {
        let mut seqs = SeqSet::default();
        for s in [0, 1, 2, 5, 4, 9, 2, 7, 3, 10, 8] {
            seqs.insert(s);
        }
        // 0..=5 and 7..=10: 6 missing.
        assert_eq!(seqs.spans.len(), 2);
        assert_eq!((seqs.missing(), seqs.first_missing(5)), (1, vec![6]));
        let mut gaps = SeqSet::default();
        for s in (1..40).step_by(2) {
            gaps.insert(s);
        }
        assert_eq!(gaps.missing(), 20);
        assert_eq!(gaps.first_missing(5), [0, 2, 4, 6, 8]);
        assert_eq!(SeqSet::default().missing(), 0);
    }
}
