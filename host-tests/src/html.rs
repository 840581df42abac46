//! HTML (and the SVG inside it) that cannot be written unescaped: a page is built only from
//! markup written in the code and values whose type says how they are written.
//!
//! - [`html!`](crate::html!) appends a format string, which must be a literal (markup the
//!   code wrote), with its arguments written by [`ToHtml`]: numbers as they are (their
//!   format specs kept: `{:.1}`), text escaped (`&`, `<`, `>`, `"`), an [`Html`] fragment as
//!   the markup it already is. Arguments are named after the literal, never captured inside
//!   it (`{x}` would skip the escaping): `tests/escaping.rs` holds every `html!` in the crate
//!   to that.
//! - [`Html::raw`] takes only a `&'static str`: markup in the code (a style sheet), never
//!   text read at run time.
//! - `Html::from_plotters` (crate-private) takes an SVG drawn by plotters' SVG backend, which
//!   escapes its text and attributes itself; only `plot::svg_html` calls it.
//!
//! There is no other way to put a `String` into an [`Html`].

use std::fmt::{self, Write as _};

/// Markup built by [`html!`](crate::html!): static markup and values written by their type.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Html(String);

impl Html {
    /// An empty fragment.
    pub fn new() -> Self {
        Self(String::new())
    }

    /// Markup written in the code (only a `&'static str`, so no text read at run time).
    pub fn raw(&mut self, markup: &'static str) -> &mut Self {
        self.0.push_str(markup);
        self
    }

    /// An SVG drawn by plotters' SVG backend (`plotters_svg::SVGBackend`), which escapes
    /// every text and attribute value it writes: for `plot::svg_html` alone
    /// (`tests/escaping.rs` holds that).
    pub(crate) fn from_plotters(svg: String) -> Self {
        Self(svg)
    }

    /// The markup.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// Whether nothing was written.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The markup, owned.
    pub fn into_string(self) -> String {
        self.0
    }

    /// Writes `args`, built by [`html!`](crate::html!) from a literal and [`Arg`]s; not for
    /// use outside that macro (`tests/escaping.rs` checks that it is not).
    #[doc(hidden)]
    pub fn __write_markup(&mut self, args: fmt::Arguments<'_>) {
        // Writing to a String cannot fail.
        let _ = self.0.write_fmt(args);
    }
}

mod sealed {
    /// Only this module's types are written into HTML.
    pub trait Sealed {}
}

/// How a value is written into HTML (implemented here only: a type outside cannot choose to
/// write itself unescaped).
pub trait ToHtml: sealed::Sealed {
    /// Writes the value, escaped as its type needs, with `f`'s format spec where it has one.
    fn fmt_html(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result;
}

/// A value as [`html!`](crate::html!) writes it: through [`ToHtml`].
#[doc(hidden)]
pub struct Arg<'a, T: ?Sized>(pub &'a T);

impl<T: ToHtml + ?Sized> fmt::Display for Arg<'_, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt_html(f)
    }
}

/// Numbers: their digits need no escaping, and their format spec is kept.
macro_rules! numbers {
    ($($t:ty),*) => {$(
        impl sealed::Sealed for $t {}
        impl ToHtml for $t {
            fn fmt_html(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Display::fmt(self, f)
            }
        }
    )*};
}
numbers!(f64, f32, u8, u16, u32, u64, usize, i8, i16, i32, i64, isize);

// The text types and fragments below.
impl sealed::Sealed for str {}
impl sealed::Sealed for String {}
impl sealed::Sealed for std::borrow::Cow<'_, str> {}
impl sealed::Sealed for Html {}
impl<T: sealed::Sealed + ?Sized> sealed::Sealed for &T {}

impl ToHtml for str {
    fn fmt_html(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut rest = self;
        while let Some(k) = rest.find(['&', '<', '>', '"']) {
            f.write_str(&rest[..k])?;
            f.write_str(match rest.as_bytes()[k] {
                b'&' => "&amp;",
                b'<' => "&lt;",
                b'>' => "&gt;",
                _ => "&quot;",
            })?;
            rest = &rest[k + 1..];
        }
        f.write_str(rest)
    }
}

impl ToHtml for String {
    fn fmt_html(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.as_str().fmt_html(f)
    }
}

impl ToHtml for std::borrow::Cow<'_, str> {
    fn fmt_html(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.as_ref().fmt_html(f)
    }
}

impl ToHtml for Html {
    fn fmt_html(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl<T: ToHtml + ?Sized> ToHtml for &T {
    fn fmt_html(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        (**self).fmt_html(f)
    }
}

/// Appends markup to an [`Html`]: `html!(out, "<td>{}</td>", value)`. The format string
/// must be a literal; each argument is written by its [`ToHtml`] (text escaped).
#[macro_export]
macro_rules! html {
    ($out:expr, $fmt:literal $(, $arg:expr)* $(,)?) => {
        $out.__write_markup(format_args!($fmt $(, $crate::html::Arg(&$arg))*))
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped_numbers_keep_their_format_and_fragments_stay_markup() {
        let mut inner = Html::new();
        html!(inner, "<b>{}</b>", "a<b&\"c\"'");
        assert_eq!(inner.as_str(), "<b>a&lt;b&amp;&quot;c&quot;'</b>");
        let mut h = Html::new();
        html!(
            h,
            "<td>{:+.1}</td><td>{}</td><td>{}</td>",
            2.25f64,
            7usize,
            inner
        );
        h.raw("<br>");
        assert_eq!(
            h.as_str(),
            "<td>+2.2</td><td>7</td><td><b>a&lt;b&amp;&quot;c&quot;'</b></td><br>"
        );
    }
}
