//! The font plots are drawn with: DejaVu Sans (cut down to the characters reports use), compiled into
//! the crate and registered with plotters' `ab_glyph` text backend. Nothing is looked up on the machine,
//! so a fresh system without fontconfig or any font package draws the same labels. See `fonts/README.md`.

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
