//! Plots of a results set: time and memory vs SF, rays per second by engine, speed vs error.
//! `build` decides what each plot holds, `draw` turns it into SVG or PNG, `font` supplies the text.

mod bitmap;
mod build;
mod draw;
mod font;
mod model;
mod ticks;

pub use build::charts;
pub use draw::{png, size, svg};
pub use model::{Bar, BarPanel, Chart, LegendAt, Panel, Point, Series, XyPanel};
