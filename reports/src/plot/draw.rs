//! Drawing a [`Chart`] with plotters, as SVG text or PNG bytes. One drawing routine serves both
//! backends, so the two files of a plot always show the same thing.

use super::bitmap::Bitmap;
use super::font::{self, FAMILY};
use super::model::{BarPanel, Chart, LegendAt, Panel, XyPanel};
use super::ticks::log_ticks;
use crate::number;
use plotters::coord::combinators::BindKeyPoints;
use plotters::coord::ranged1d::{AsRangedCoord, SegmentValue, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Pixels per panel.
const PANEL_W: u32 = 640;
const PANEL_H: u32 = 460;
const TITLE_H: u32 = 44;

/// Tableau's ten colours after black (Embree's).
const PALETTE: [(u8, u8, u8); 11] = [
    (0, 0, 0),
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
];

fn color(i: usize) -> RGBColor {
    // Past the palette, colours repeat (from 1: black stays Embree's).
    let (r, g, b) = if i < PALETTE.len() {
        PALETTE[i]
    } else {
        PALETTE[1 + (i - 1) % (PALETTE.len() - 1)]
    };
    RGBColor(r, g, b)
}

fn text(size: u32) -> TextStyle<'static> {
    (FAMILY, size).into_font().color(&BLACK)
}

/// The image size of a chart.
pub fn size(chart: &Chart) -> (u32, u32) {
    (
        PANEL_W * chart.panels.len().max(1) as u32,
        PANEL_H + TITLE_H,
    )
}

/// The chart as an SVG document.
pub fn svg(chart: &Chart) -> Result<String, String> {
    font::register()?;
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, size(chart)).into_drawing_area();
        draw(&root, chart)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// The chart as a PNG file's bytes.
pub fn png(chart: &Chart) -> Result<Vec<u8>, String> {
    font::register()?;
    let (w, h) = size(chart);
    let mut pixels = vec![0u8; (w * h * 3) as usize];
    {
        let backend = Bitmap::new(
            BitMapBackend::with_buffer(&mut pixels, (w, h)),
            font::font_ref()?,
        );
        let root = backend.into_drawing_area();
        draw(&root, chart)?;
        root.present().map_err(|e| e.to_string())?;
    }
    let img = image::RgbImage::from_raw(w, h, pixels)
        .ok_or("the pixel buffer does not match the image size")?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    Ok(bytes.into_inner())
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, chart: &Chart) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let body = root.titled(&chart.title, text(22)).map_err(e)?;
    let areas = body.split_evenly((1, chart.panels.len().max(1)));
    for (area, panel) in areas.iter().zip(&chart.panels) {
        match panel {
            Panel::Xy(p) => draw_xy_any(area, p)?,
            Panel::Bars(p) => draw_bars(area, p)?,
        }
    }
    Ok(())
}

/// Axis bounds around `values`, with a margin; a log axis only sees positive values.
fn bounds(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    // Padded, but never past the finite doubles (a figure of 1e308 made the axis infinite and
    // its ticks endless).
    if log {
        let (a, b) = if hi / lo < 1.01 {
            (lo / 2.0, hi * 2.0)
        } else {
            let pad = (hi / lo).powf(0.06);
            (lo / pad, hi * pad)
        };
        (a.max(f64::MIN_POSITIVE), b.min(f64::MAX))
    } else {
        let (a, b) = if hi - lo < 1e-12 * hi.abs().max(1.0) {
            (lo - 1.0, hi + 1.0)
        } else {
            let pad = (hi - lo) * 0.06;
            (lo - pad, hi + pad)
        };
        (a.max(-f64::MAX / 4.0), b.min(f64::MAX / 4.0))
    }
}

/// A panel's frame: its caption (if any), margins and the room for tick labels.
fn builder<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    title: &str,
    y_label_room: u32,
) -> ChartBuilder<'a, 'b, DB> {
    let mut b = ChartBuilder::on(area);
    if !title.is_empty() {
        b.caption(title, text(16));
    }
    b.margin(12)
        .x_label_area_size(44)
        .y_label_area_size(y_label_room);
    b
}

fn draw_xy_any<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &XyPanel,
) -> Result<(), String> {
    let points = || p.series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) = bounds(points().map(|q| q.x), p.x_log);
    let (y0, y1) = bounds(
        points()
            .flat_map(|q| [Some(q.y), q.y_range.map(|r| r.0), q.y_range.map(|r| r.1)])
            .flatten(),
        p.y_log,
    );
    let (x_bold, x_light) = if p.x_ticks.is_empty() {
        log_ticks(x0, x1)
    } else {
        (p.x_ticks.clone(), p.x_ticks.clone())
    };
    let (y_bold, y_light) = log_ticks(y0, y1);
    let x_log = || {
        (x0..x1)
            .log_scale()
            .with_key_points(x_bold.clone())
            .with_light_points(x_light.clone())
    };
    let y_log = || {
        (y0..y1)
            .log_scale()
            .with_key_points(y_bold.clone())
            .with_light_points(y_light.clone())
    };
    // The coordinate types differ with the scale, so each combination is its own instance.
    match (p.x_log, p.y_log) {
        (true, true) => draw_xy(area, p, x_log(), y_log()),
        (true, false) => draw_xy(area, p, x_log(), y0..y1),
        (false, true) => draw_xy(area, p, x0..x1, y_log()),
        (false, false) => draw_xy(area, p, x0..x1, y0..y1),
    }
}

fn draw_xy<DB, X, Y>(area: &DrawingArea<DB, Shift>, p: &XyPanel, x: X, y: Y) -> Result<(), String>
where
    DB: DrawingBackend,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut chart = builder(area, &p.title, 64)
        .build_cartesian_2d(x, y)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(&p.x_label)
        .y_desc(&p.y_label)
        .x_label_formatter(&|v| number::axis(*v))
        .y_label_formatter(&|v| number::axis(*v))
        .label_style(text(13))
        .axis_desc_style(text(14))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(e)?;

    for s in &p.series {
        let c = color(s.color);
        let xy: Vec<(f64, f64)> = s.points.iter().map(|q| (q.x, q.y)).collect();
        let bars = s.points.iter().filter_map(|q| {
            q.y_range
                .filter(|r| r.1 > r.0)
                .map(|(lo, hi)| ErrorBar::new_vertical(q.x, lo, q.y, hi, c.stroke_width(1), 8))
        });
        chart.draw_series(bars).map_err(e)?;
        let marks = xy.iter().map(|&q| Circle::new(q, 4, c.filled()));
        if p.lines {
            chart.draw_series(marks).map_err(e)?;
            chart
                .draw_series(LineSeries::new(xy.iter().copied(), c.stroke_width(2)))
                .map_err(e)?
                .label(&s.name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
        } else {
            chart
                .draw_series(marks)
                .map_err(e)?
                .label(&s.name)
                .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
        }
    }
    if !p.series.is_empty() {
        let position = match p.legend {
            LegendAt::UpperLeft => SeriesLabelPosition::UpperLeft,
            LegendAt::UpperRight => SeriesLabelPosition::UpperRight,
            LegendAt::LowerRight => SeriesLabelPosition::LowerRight,
        };
        chart
            .configure_series_labels()
            .position(position)
            .label_font(text(13))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(180, 180, 180))
            .draw()
            .map_err(e)?;
    }
    Ok(())
}

fn draw_bars<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &BarPanel,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let n = p.bars.len().max(1);
    let max = p
        .bars
        .iter()
        .flat_map(|b| [Some(b.value), b.range.map(|r| r.1)])
        .flatten()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    // Room at the right for the value printed after the longest bar.
    let x_max = if max > 0.0 { max * 1.45 } else { 1.0 };
    let longest = p
        .bars
        .iter()
        .map(|b| b.label.chars().count())
        .max()
        .unwrap_or(4) as u32;
    let mut chart = builder(area, &p.title, (longest * 7 + 16).clamp(60, 320))
        // An integer range includes its end: 0..n−1 holds n categories.
        .build_cartesian_2d(0.0..x_max, (0..n - 1).into_segmented())
        .map_err(e)?;
    // The first bar on top: category i is drawn at row n − 1 − i.
    let label_of = |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(row) if *row < n => p
            .bars
            .get(n - 1 - row)
            .map(|b| b.label.clone())
            .unwrap_or_default(),
        _ => String::new(),
    };
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(n)
        .y_label_formatter(&label_of)
        .x_label_formatter(&|v| number::axis(*v))
        .x_desc(&p.value_label)
        .label_style(text(13))
        .axis_desc_style(text(14))
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(e)?;
    chart
        .draw_series(p.bars.iter().enumerate().map(|(i, b)| {
            let row = n - 1 - i;
            let mut r = Rectangle::new(
                [
                    (0.0, SegmentValue::Exact(row)),
                    (b.value.max(0.0), SegmentValue::Exact(row + 1)),
                ],
                color(b.color).filled(),
            );
            r.set_margin(6, 6, 0, 0);
            r
        }))
        .map_err(e)?;
    // Error bars: the interval as a line across the bar's end, with end caps.
    for (i, b) in p.bars.iter().enumerate() {
        let Some((lo, hi)) = b.range.filter(|r| r.0.is_finite() && r.1.is_finite()) else {
            continue;
        };
        let row = n - 1 - i;
        let at = |x: f64| (x.max(0.0), SegmentValue::CenterOf(row));
        let ink = BLACK.stroke_width(2);
        chart
            .draw_series(std::iter::once(PathElement::new(vec![at(lo), at(hi)], ink)))
            .map_err(e)?;
        for x in [lo, hi] {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(at(x)) + PathElement::new(vec![(0, -6), (0, 6)], ink),
                ))
                .map_err(e)?;
        }
    }
    chart
        .draw_series(p.bars.iter().enumerate().map(|(i, b)| {
            let end = b.range.map_or(b.value, |r| r.1.max(b.value));
            let at = (end.max(0.0), SegmentValue::CenterOf(n - 1 - i));
            EmptyElement::at(at) + Text::new(b.note.clone(), (6, -7), text(13))
        }))
        .map_err(e)?;
    Ok(())
}
