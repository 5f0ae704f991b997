//! What a plot shows, as data: built from a [`Summary`](crate::Summary) by `build.rs`, drawn (as SVG or
//! PNG) by `draw.rs`. Keeping the two apart lets the tests check what a plot holds without reading pixels.

/// One image: a title over one or more panels side by side.
#[derive(Clone, Debug)]
pub struct Chart {
    /// File name without extension, unique within `plots/`.
    pub stem: String,
    pub title: String,
    pub panels: Vec<Panel>,
}

#[derive(Clone, Debug)]
pub enum Panel {
    Xy(XyPanel),
    Bars(BarPanel),
}

/// Points on two numeric axes, each linear or logarithmic.
#[derive(Clone, Debug)]
pub struct XyPanel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    /// Where to put the x ticks (the SFs measured); empty: chosen from the range.
    pub x_ticks: Vec<f64>,
    /// Join each series' points with a line (else a scatter).
    pub lines: bool,
    pub legend: LegendAt,
    pub series: Vec<Series>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LegendAt {
    UpperLeft,
    UpperRight,
    LowerRight,
}

/// One engine's points; `color` indexes the palette (0 is Embree's).
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub color: usize,
    pub points: Vec<Point>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    /// The spread of `y` over the repeats (min, max), drawn as an error bar.
    pub y_range: Option<(f64, f64)>,
}

/// Horizontal bars, one per category, top to bottom in the given order.
#[derive(Clone, Debug)]
pub struct BarPanel {
    pub title: String,
    pub value_label: String,
    pub bars: Vec<Bar>,
}

#[derive(Clone, Debug)]
pub struct Bar {
    pub label: String,
    pub value: f64,
    pub color: usize,
    /// Printed at the end of the bar.
    pub note: String,
    /// An interval drawn as an error bar across the bar's end (a ratio's 95 % interval).
    pub range: Option<(f64, f64)>,
}
