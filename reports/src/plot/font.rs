//! The font plots are drawn with: DejaVu Sans (cut down to the characters reports use), compiled into
//! the crate. It is registered with plotters' `ab_glyph` text backend (which sizes text for the SVG
//! files) and drawn by the PNG backend (`bitmap.rs`). Nothing is looked up on the machine, so a fresh
//! system without fontconfig or any font package draws the same labels. See `fonts/README.md`.

use ab_glyph::FontRef;
use plotters::style::{register_font, FontStyle};
use std::sync::OnceLock;

/// The family name plots ask for.
pub const FAMILY: &str = "sans-serif";

static FONT: &[u8] = include_bytes!("../../fonts/DejaVuSans-subset.ttf");

/// Registers the font once per process.
pub fn register() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        register_font(FAMILY, FontStyle::Normal, FONT).map_err(|_| {
            "the bundled font fonts/DejaVuSans-subset.ttf is not a valid TrueType font".to_string()
        })
    })
    .clone()
}

/// The font itself, for the PNG backend's text (`bitmap.rs`).
pub fn font_ref() -> Result<FontRef<'static>, String> {
    FontRef::try_from_slice(FONT)
        .map_err(|e| format!("the bundled font fonts/DejaVuSans-subset.ttf: {e}"))
}
