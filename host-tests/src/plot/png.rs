//! A figure as PNG: its SVG rasterised with resvg, the text in the embedded DejaVu Sans.

use resvg::{tiny_skia, usvg};

use super::PlotError;

/// DejaVu Sans 2.37 (assets/PROVENANCE): every font a figure names is drawn in it, so a
/// machine without fonts draws the same PNG as any other.
const FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The SVG document `svg` as a PNG of its own size, one pixel per SVG unit.
pub(crate) fn from_svg(svg: &str) -> Result<Vec<u8>, PlotError> {
    let mut options = usvg::Options::default();
    // No system fonts (resvg's `system-fonts` feature is off): only the embedded one, the
    // family of every generic name and the default.
    let fonts = options.fontdb_mut();
    fonts.load_font_data(FONT.to_vec());
    fonts.set_sans_serif_family("DejaVu Sans");
    fonts.set_serif_family("DejaVu Sans");
    fonts.set_monospace_family("DejaVu Sans");
    options.font_family = "DejaVu Sans".into();
    let tree = usvg::Tree::from_str(svg, &options)?;
    let size = tree.size().to_int_size();
    let mut pixmap =
        tiny_skia::Pixmap::new(size.width(), size.height()).ok_or(PlotError::TooLarge {
            width: size.width(),
            height: size.height(),
        })?;
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| PlotError::Png(Box::new(e)))
}
