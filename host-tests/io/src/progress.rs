//! How far a read has got, for a bar on a terminal: a value handed down with the read (a
//! pass's part of one bar is a [`Progress::span`] of it), not a global.

use std::sync::Arc;

/// Where a reader reports the fraction of its input read (0 to 1); nothing is shown by
/// [`Progress::none`].
#[derive(Clone, Default)]
pub struct Progress(Option<Arc<dyn Fn(f64) + Send + Sync>>);

impl Progress {
    /// Nothing shown.
    pub fn none() -> Self {
        Self(None)
    }

    /// Each fraction handed to `show`.
    pub fn new(show: impl Fn(f64) + Send + Sync + 'static) -> Self {
        Self(Some(Arc::new(show)))
    }

    /// Whether anything is shown (a reader may skip measuring otherwise).
    pub fn is_shown(&self) -> bool {
        self.0.is_some()
    }

    /// `fraction` of the input read (clamped to 0..=1).
    pub fn report(&self, fraction: f64) {
        if let Some(show) = &self.0 {
            show(fraction.clamp(0.0, 1.0));
        }
    }

    /// The part of this bar from `from` to `to`: a pass's fraction shown within its span.
    pub fn span(&self, from: f64, to: f64) -> Self {
        match &self.0 {
            Some(show) => {
                let show = Arc::clone(show);
                Self::new(move |f| show(from + (to - from) * f.clamp(0.0, 1.0)))
            }
            None => Self::none(),
        }
    }
}

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.is_shown() {
            "Progress(shown)"
        } else {
            "Progress(none)"
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn a_span_shows_its_part_of_the_bar() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let s = Arc::clone(&seen);
        let bar = Progress::new(move |f| s.lock().unwrap().push(f));
        bar.span(0.5, 1.0).report(0.5);
        bar.span(0.0, 0.5).report(2.0);
        Progress::none().span(0.0, 1.0).report(0.3);
        assert_eq!(*seen.lock().unwrap(), [0.75, 0.5]);
    }
}
