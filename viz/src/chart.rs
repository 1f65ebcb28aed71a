//! Log–log line charts (error against elements, error against time), drawn with `plotters` as
//! SVG and as PNG by one drawing function, so that the two files show the same thing.
//!
//! Text is set in DejaVu Sans, which the crate carries and registers with plotters' `ab_glyph`
//! renderer, so a PNG needs no installed font and its text is antialiased. The SVG names the
//! generic `sans-serif` family and is laid out with the same font's metrics. Plotters' bitmap
//! strokes are not antialiased, so the PNG is drawn `SUPERSAMPLE` times larger and averaged
//! down. The same chart gives the same bytes.

use std::sync::OnceLock;

use image::{Rgb, RgbImage};
use plotters::coord::Shift;
use plotters::coord::combinators::WithKeyPoints;
use plotters::prelude::*;
use plotters::style::register_font;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters_backend::{BackendColor, BackendCoord, DrawingErrorKind};

use crate::VizError;
use crate::render::encode_png;

/// The chart's size in points, which are the SVG's pixels.
const WIDTH: f64 = 720.0;
const HEIGHT: f64 = 460.0;
/// Room between the image's edges and what is drawn nearest them.
const MARGIN: f64 = 12.0;
/// Text sizes in plotters' units: the SVG's font size is these over 1.24.
const TICK_FONT: f64 = 15.0;
const LABEL_FONT: f64 = 16.0;
const TITLE_FONT: f64 = 20.0;
/// Room between the frame and the tick labels, and between tick labels and axis labels.
const GAP: f64 = 8.0;
/// Series with more points than this are drawn as lines without markers.
const MAX_MARKERS: usize = 60;
const MARKER_RADIUS: f64 = 3.0;
const LINE_WIDTH: f64 = 2.0;
/// The legend's sample line, and the room between its rows.
const SWATCH: f64 = 24.0;
const LEGEND_ROW: f64 = 20.0;
/// Most labelled decades on an axis; a longer range labels every second (third, …) one.
const MAX_DECADE_TICKS: f64 = 8.0;
/// Most decades over which the grid also marks 2, 3, … 9 times each power of ten.
const MAX_MINOR_DECADES: f64 = 6.0;
/// SVG units per chart point: plotters' coordinates are whole units, too coarse for points.
const SVG_SCALE: u32 = 4;
/// PNG pixels per chart point.
const PNG_SCALE: u32 = 2;
/// Samples per PNG pixel, along each side.
const SUPERSAMPLE: u32 = 2;
/// How far the PNG's text is moved down, in font sizes (see `Bitmap`).
const BITMAP_TEXT_DROP: f64 = 0.12;
/// The family the bundled font is registered as, and the one SVG viewers are asked for.
const FONT_FAMILY: &str = "sans-serif";
/// DejaVu Sans (Bitstream Vera licence, see `fonts/LICENSE`).
static FONT: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");

/// Line colours of successive series (colour-blind safe, after Okabe & Ito).
const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];
const GRID: RGBColor = RGBColor(220, 220, 220);
const MINOR_GRID: RGBColor = RGBColor(240, 240, 240);
const INK: RGBColor = RGBColor(40, 40, 40);

/// One line of a chart: its name in the legend and its points (x, y), drawn in the given order.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The name in the legend.
    pub name: String,
    /// The points (x, y).
    pub points: Vec<(f64, f64)>,
}

impl Series {
    /// The points a logarithmic axis can show: positive and finite.
    fn usable(&self) -> Vec<(f64, f64)> {
        let usable = |&(x, y): &(f64, f64)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite();
        self.points.iter().copied().filter(usable).collect()
    }
}

/// A chart with logarithmic axes. Points that are not positive and finite are left out.
#[derive(Clone, Debug, PartialEq)]
pub struct LogLogChart {
    /// The title above the plot.
    pub title: String,
    /// The label of the horizontal axis.
    pub x_label: String,
    /// The label of the vertical axis.
    pub y_label: String,
    /// The lines, in legend order.
    pub series: Vec<Series>,
}

/// A logarithmic axis: the decades it spans and where its ticks go.
#[derive(Clone, Debug)]
struct Axis {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
}

impl Axis {
    fn fit(values: impl Iterator<Item = f64>) -> Axis {
        let (mut lo, mut hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        if !(lo.is_finite() && hi.is_finite()) {
            (lo, hi) = (1.0, 10.0);
        }
        // Whole 1-2-5 steps around the data, at least a factor of 10 in all.
        let steps = [1.0, 2.0, 5.0];
        let below = |v: f64| {
            let e = v.log10().floor();
            steps
                .iter()
                .rev()
                .map(|s| s * 10f64.powf(e))
                .find(|&t| t <= v * (1.0 + 1e-12))
                .unwrap_or(10f64.powf(e))
        };
        let above = |v: f64| {
            let e = v.log10().floor();
            steps
                .iter()
                .chain(&[10.0])
                .map(|s| s * 10f64.powf(e))
                .find(|&t| t >= v * (1.0 - 1e-12))
                .unwrap_or(10f64.powf(e + 1.0))
        };
        let (mut lo, mut hi) = (below(lo), above(hi));
        while hi / lo < 9.99 {
            lo = below(lo * 0.99);
            if hi / lo < 9.99 {
                hi = above(hi * 1.01);
            }
        }
        Axis {
            lo,
            hi,
            ticks: ticks_between(lo, hi),
        }
    }

    /// Grid lines between the ticks: the whole multiples of each decade that are not ticks, or
    /// over a long range, where those would grey the plot, the powers of ten that are not.
    fn minor(&self) -> Vec<f64> {
        let multiples = if (self.hi / self.lo).log10() <= MAX_MINOR_DECADES {
            1..=9
        } else {
            1..=1
        };
        let mut out = Vec::new();
        for e in exponents(self.lo, self.hi) {
            for m in multiples.clone() {
                let t = f64::from(m) * 10f64.powi(e);
                let tick = self.ticks.iter().any(|&k| (k / t - 1.0).abs() < 1e-9);
                if !tick && t > self.lo && t < self.hi {
                    out.push(t);
                }
            }
        }
        out
    }

    /// The axis as plotters' coordinate: logarithmic, labelled at the ticks.
    fn coord(&self) -> WithKeyPoints<LogCoord<f64>> {
        (self.lo..self.hi)
            .log_scale()
            .with_key_points(self.ticks.clone())
            .with_light_points(self.minor())
    }

    /// Where `v` falls, 0 at `lo` and 1 at `hi`.
    #[cfg(test)]
    fn unit(&self, v: f64) -> f64 {
        (v / self.lo).log10() / (self.hi / self.lo).log10()
    }
}

/// Ticks from `lo` to `hi`: at 1, 2 and 5 times each power of ten over a short range, at the
/// powers of ten over a longer one, and at every second (third, …) power over a long one.
fn ticks_between(lo: f64, hi: f64) -> Vec<f64> {
    let decades = (hi / lo).log10();
    let multiples: &[f64] = if decades <= 2.5 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let step = (decades / MAX_DECADE_TICKS).ceil().max(1.0) as i32;
    let mut ticks = Vec::new();
    for e in exponents(lo, hi).filter(|e| e.rem_euclid(step) == 0) {
        for m in multiples {
            let t = m * 10f64.powi(e);
            if t >= lo * (1.0 - 1e-12) && t <= hi * (1.0 + 1e-12) {
                ticks.push(t);
            }
        }
    }
    ticks
}

/// The powers of ten whose decades meet `lo` to `hi`, within the range of `f64`.
fn exponents(lo: f64, hi: f64) -> std::ops::RangeInclusive<i32> {
    let first = lo.log10().floor().max(-330.0) as i32;
    let last = hi.log10().floor().min(308.0) as i32;
    first..=last
}

/// A tick value as people write it: 0.05, 2, 300, 20k, 5M, and below a thousandth 10⁻⁶ or
/// 2×10⁻⁶, which read better than a row of zeros.
fn tick_label(v: f64) -> String {
    if v >= 1e6 {
        return format!("{}M", tick_label(v / 1e6));
    }
    if v >= 1e4 {
        return format!("{}k", tick_label(v / 1e3));
    }
    // Ticks are 1, 2 or 5 times a power of ten, whose logarithm may come out a hair low.
    let exponent = (v.log10() + 1e-9).floor();
    if v < 1e-3 {
        let power = format!("10{}", superscript(exponent as i32));
        let mantissa = (v / 10f64.powf(exponent)).round();
        return if mantissa > 1.0 {
            format!("{mantissa}×{power}")
        } else {
            power
        };
    }
    let decimals = (-exponent).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// An exponent in superscript digits.
fn superscript(n: i32) -> String {
    n.to_string()
        .chars()
        .map(|c| match c.to_digit(10) {
            Some(d) => ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'][d as usize],
            None => '⁻',
        })
        .collect()
}

/// The chart's coordinates: logarithmic on both axes.
type LogLog = Cartesian2d<WithKeyPoints<LogCoord<f64>>, WithKeyPoints<LogCoord<f64>>>;

/// Where the parts of a chart go, in points (y down).
#[derive(Clone, Debug)]
struct Layout {
    x_axis: Axis,
    y_axis: Axis,
    /// The plot's frame: left, top, right, bottom.
    plot: [f64; 4],
    /// The middle of the title.
    title_x: f64,
}

impl LogLogChart {
    fn layout(&self) -> Result<Layout, VizError> {
        ensure_font()?;
        let points: Vec<(f64, f64)> = self.series.iter().flat_map(Series::usable).collect();
        let x_axis = Axis::fit(points.iter().map(|p| p.0));
        let y_axis = Axis::fit(points.iter().map(|p| p.1));
        let widest_tick = widest(y_axis.ticks.iter().map(|&t| tick_label(t)), TICK_FONT)?;
        let widest_name = widest(self.series.iter().map(|s| one_line(&s.name)), TICK_FONT)?;
        // Left of the plot, the rotated axis label and the tick labels; right of it, the legend.
        let left = MARGIN + LABEL_FONT + GAP + widest_tick + GAP;
        let legend = 2.0 * GAP + SWATCH + GAP + widest_name + MARGIN;
        // Long names clip at the image's edge rather than squeeze the plot to nothing.
        let right = (WIDTH - legend).max(left + 0.4 * WIDTH);
        let top = MARGIN + TITLE_FONT + GAP;
        let bottom = HEIGHT - MARGIN - (GAP + TICK_FONT + GAP + LABEL_FONT);
        // Over the plot's middle, unless that would push a long title off the image.
        let half = text_width(&one_line(&self.title), TITLE_FONT)? / 2.0 + MARGIN;
        let middle = (left + right) / 2.0;
        let title_x = if half >= WIDTH / 2.0 {
            WIDTH / 2.0
        } else {
            middle.clamp(half, WIDTH - half)
        };
        Ok(Layout {
            x_axis,
            y_axis,
            plot: [left, top, right, bottom],
            title_x,
        })
    }

    /// Draws the whole chart at `scale` backend pixels per point.
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        layout: &Layout,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let px = |v: f64| (v * scale).round() as i32;
        root.fill(&WHITE)?;
        let [left, top, right, bottom] = layout.plot;
        let mut chart = ChartBuilder::on(root)
            .margin_left(px(MARGIN))
            .margin_top(px(top))
            .margin_right(px(WIDTH - right))
            .margin_bottom(px(MARGIN))
            .y_label_area_size(px(left - MARGIN))
            .x_label_area_size(px(HEIGHT - MARGIN - bottom))
            .build_cartesian_2d(layout.x_axis.coord(), layout.y_axis.coord())?;
        self.draw_mesh(&mut chart, scale)?;
        let (x_axis, y_axis) = (&layout.x_axis, &layout.y_axis);
        let (x0, y0) = chart.backend_coord(&(x_axis.lo, y_axis.hi));
        let (x1, y1) = chart.backend_coord(&(x_axis.hi, y_axis.lo));
        let corners = vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)];
        root.draw(&PathElement::new(
            corners,
            INK.stroke_width(stroke(1.0, scale)),
        ))?;
        self.draw_series(&mut chart, scale)?;
        let title = font(TITLE_FONT, scale).pos(Pos::new(HPos::Center, VPos::Top));
        root.draw_text(
            &one_line(&self.title),
            &title,
            (px(layout.title_x), px(MARGIN)),
        )?;
        self.draw_legend(root, layout, scale)
    }

    /// The grid at the ticks (and fainter between them), the tick labels and the axis labels.
    fn draw_mesh<DB: DrawingBackend>(
        &self,
        chart: &mut ChartContext<'_, DB, LogLog>,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let format = |v: &f64| tick_label(*v);
        chart
            .configure_mesh()
            .bold_line_style(GRID.stroke_width(stroke(1.0, scale)))
            .light_line_style(MINOR_GRID.stroke_width(stroke(1.0, scale)))
            // The frame is drawn on its own, and tick marks would only repeat the grid.
            .axis_style(TRANSPARENT)
            // Plotters sets tick labels twice the tick mark's length away from the axis.
            .set_all_tick_mark_size((GAP / 2.0 * scale).round() as i32)
            .label_style(font(TICK_FONT, scale))
            .axis_desc_style(font(LABEL_FONT, scale))
            .x_desc(one_line(&self.x_label))
            .y_desc(one_line(&self.y_label))
            .x_label_formatter(&format)
            .y_label_formatter(&format)
            .draw()
    }

    /// Each series as one line through its usable points, with markers if it has few.
    fn draw_series<DB: DrawingBackend>(
        &self,
        chart: &mut ChartContext<'_, DB, LogLog>,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let radius = (MARKER_RADIUS * scale).round() as i32;
        for (k, s) in self.series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let points = s.usable();
            if points.len() > 1 {
                let style = color.stroke_width(stroke(LINE_WIDTH, scale));
                chart.draw_series([PathElement::new(points.clone(), style)])?;
            }
            // Markers show where the data are; on a dense series they would only blot the line.
            if points.len() <= MAX_MARKERS {
                let markers = points
                    .iter()
                    .map(|&p| Circle::new(p, radius, color.filled()));
                chart.draw_series(markers)?;
            }
        }
        Ok(())
    }

    /// The legend, right of the plot and level with its top: a sample of each line and its name.
    fn draw_legend<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        layout: &Layout,
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let px = |v: f64| (v * scale).round() as i32;
        let [_, top, right, _] = layout.plot;
        let x = right + 2.0 * GAP;
        let name_style = font(TICK_FONT, scale).pos(Pos::new(HPos::Left, VPos::Center));
        for (k, s) in self.series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let y = top + GAP + LEGEND_ROW * k as f64;
            let half = LINE_WIDTH / 2.0;
            // A filled bar rather than a path: the SVG's polylines stay the frame and the series.
            let bar = [(px(x), px(y - half)), (px(x + SWATCH), px(y + half))];
            root.draw(&Rectangle::new(bar, color.filled()))?;
            if s.usable().len() <= MAX_MARKERS {
                let at = (px(x + SWATCH / 2.0), px(y));
                root.draw(&Circle::new(at, px(MARKER_RADIUS), color.filled()))?;
            }
            root.draw_text(
                &one_line(&s.name),
                &name_style,
                (px(x + SWATCH + GAP), px(y)),
            )?;
        }
        Ok(())
    }

    /// The chart as an SVG document, 720 × 460 points.
    pub fn svg(&self) -> Result<String, VizError> {
        let layout = self.layout()?;
        let scale = f64::from(SVG_SCALE);
        let size = ((WIDTH * scale) as u32, (HEIGHT * scale) as u32);
        let mut out = String::new();
        {
            let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
            self.draw(&root, &layout, scale)
                .map_err(|e| chart_error(&e))?;
            root.present().map_err(|e| chart_error(&e))?;
        }
        // The document keeps its fine units in the view box and gives its size in points.
        let drawn = format!("width=\"{}\" height=\"{}\"", size.0, size.1);
        Ok(out.replacen(&drawn, &format!("width=\"{WIDTH}\" height=\"{HEIGHT}\""), 1))
    }

    /// The chart as a PNG file's bytes, twice the SVG's size.
    pub fn png(&self) -> Result<Vec<u8>, VizError> {
        let layout = self.layout()?;
        let scale = f64::from(PNG_SCALE * SUPERSAMPLE);
        let (width, height) = ((WIDTH * scale) as u32, (HEIGHT * scale) as u32);
        let mut buffer = vec![0; width as usize * height as usize * 3];
        {
            let backend = BitMapBackend::with_buffer(&mut buffer, (width, height));
            let root = Bitmap(backend).into_drawing_area();
            self.draw(&root, &layout, scale)
                .map_err(|e| chart_error(&e))?;
            root.present().map_err(|e| chart_error(&e))?;
        }
        encode_png(&downsample(&buffer, width, height, SUPERSAMPLE))
    }
}

/// Plotters' bitmap backend with two of its ways mended. Its `ab_glyph` text has the baseline
/// half the font size below the text's top, about an eighth of the size higher than an SVG's,
/// which sets tick labels above their grid lines: the text is moved down. And it fills a thick
/// path as one polygon, which cancels itself where the path turns back (error against time
/// does): the path is stroked a segment at a time, with round joins.
struct Bitmap<'a>(BitMapBackend<'a>);

type BitmapError = <BitMapBackend<'static> as DrawingBackend>::ErrorType;

impl DrawingBackend for Bitmap<'_> {
    type ErrorType = BitmapError;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<BitmapError>> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<BitmapError>> {
        self.0.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<BitmapError>> {
        self.0.draw_pixel(point, color)
    }

    fn draw_line<S: plotters_backend::BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<BitmapError>> {
        self.0.draw_line(from, to, style)
    }

    fn draw_rect<S: plotters_backend::BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<BitmapError>> {
        self.0.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: plotters_backend::BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<BitmapError>> {
        let points: Vec<BackendCoord> = path.into_iter().collect();
        if style.stroke_width() <= 1 {
            return self.0.draw_path(points, style);
        }
        for pair in points.windows(2) {
            self.0.draw_path(pair.iter().copied(), style)?;
        }
        let inner = points.len().saturating_sub(2);
        for &joint in points.iter().skip(1).take(inner) {
            self.0
                .draw_circle(joint, style.stroke_width() / 2, style, true)?;
        }
        Ok(())
    }

    fn draw_text<S: plotters_backend::BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        (x, y): BackendCoord,
    ) -> Result<(), DrawingErrorKind<BitmapError>> {
        // Down in the text's own frame, which is sideways for the rotated axis label.
        let drop = (BITMAP_TEXT_DROP * style.size()).round() as i32;
        let (dx, dy) = style.transform().transform(0, drop);
        self.0.draw_text(text, style, (x + dx, y + dy))
    }
}

/// Registers the bundled font with plotters, once for the process.
fn ensure_font() -> Result<(), VizError> {
    static LOADED: OnceLock<bool> = OnceLock::new();
    let loaded = LOADED.get_or_init(|| register_font(FONT_FAMILY, FontStyle::Normal, FONT).is_ok());
    if *loaded {
        Ok(())
    } else {
        Err(VizError::Chart("the bundled font does not load".to_owned()))
    }
}

/// The chart's text style at `size` (plotters' units) and `scale` pixels per point.
fn font(size: f64, scale: f64) -> TextStyle<'static> {
    (FONT_FAMILY, size * scale).into_font().color(&INK)
}

/// A stroke `width` points wide, in whole pixels.
fn stroke(width: f64, scale: f64) -> u32 {
    (width * scale).round().max(1.0) as u32
}

/// The width of `text` at `size`, in points.
fn text_width(text: &str, size: f64) -> Result<f64, VizError> {
    let (width, _) = (FONT_FAMILY, size)
        .into_font()
        .box_size(text)
        .map_err(|e| VizError::Chart(e.to_string()))?;
    Ok(f64::from(width))
}

/// The width of the widest of `texts` at `size`, in points; 0 for none.
fn widest(mut texts: impl Iterator<Item = String>, size: f64) -> Result<f64, VizError> {
    texts.try_fold(0.0, |m: f64, t| Ok(m.max(text_width(&t, size)?)))
}

/// Text on one line: control characters (line breaks, and those XML does not allow) become
/// spaces.
fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// A failure of plotters, as the crate's error.
fn chart_error<E: std::error::Error + Send + Sync>(e: &DrawingAreaErrorKind<E>) -> VizError {
    VizError::Chart(e.to_string())
}

/// Averages each `factor` × `factor` block of an RGB buffer into one pixel.
fn downsample(buffer: &[u8], width: u32, height: u32, factor: u32) -> RgbImage {
    let samples = factor * factor;
    RgbImage::from_fn(width / factor, height / factor, |x, y| {
        let mut sum = [0u32; 3];
        for dy in 0..factor {
            let row = (y * factor + dy) as usize * width as usize;
            for dx in 0..factor {
                let at = 3 * (row + (x * factor + dx) as usize);
                for c in 0..3 {
                    sum[c] += u32::from(buffer[at + c]);
                }
            }
        }
        Rgb(sum.map(|s| ((s + samples / 2) / samples) as u8))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> LogLogChart {
        LogLogChart {
            title: "error against triangles".into(),
            x_label: "triangles".into(),
            y_label: "RMS error (% of mean)".into(),
            series: vec![
                Series {
                    name: "uniform".into(),
                    points: vec![(2500.0, 10.5), (5000.0, 7.0), (30000.0, 3.2)],
                },
                Series {
                    name: "discontinuity".into(),
                    points: vec![(2000.0, 7.5), (30000.0, 0.39), (0.0, 1.0)],
                },
            ],
        }
    }

    /// The trimmed text of every `<text>` element, with the element's `x` attribute.
    fn texts(svg: &str) -> Vec<(f64, String)> {
        svg.split("<text")
            .skip(1)
            .filter_map(|t| {
                let x = t.split("x=\"").nth(1)?.split('"').next()?.parse().ok()?;
                let body = &t[t.find('>')? + 1..];
                Some((x, body[..body.find("</text>")?].trim().to_owned()))
            })
            .collect()
    }

    fn png_of(chart: &LogLogChart) -> RgbImage {
        let png = chart.png().expect("encodes");
        image::load_from_memory(&png).expect("decodes").to_rgb8()
    }

    /// Where a data point falls in the PNG, in pixels.
    fn pixel(layout: &Layout, (x, y): (f64, f64)) -> (u32, u32) {
        let [left, top, right, bottom] = layout.plot;
        let u = left + (right - left) * layout.x_axis.unit(x);
        let v = bottom - (bottom - top) * layout.y_axis.unit(y);
        let s = f64::from(PNG_SCALE);
        ((u * s).round() as u32, (v * s).round() as u32)
    }

    /// Whether a pixel within `reach` of `at` has exactly `color`.
    fn drawn_near(image: &RgbImage, at: (u32, u32), reach: u32, color: RGBColor) -> bool {
        let (x0, y0) = (at.0.saturating_sub(reach), at.1.saturating_sub(reach));
        (y0..=at.1 + reach).any(|y| {
            (x0..=at.0 + reach).any(|x| image.get_pixel(x, y).0 == [color.0, color.1, color.2])
        })
    }

    #[test]
    fn axes_cover_the_data_in_whole_steps() {
        let x = Axis::fit([2000.0, 30000.0].into_iter());
        assert_eq!((x.lo, x.hi), (2000.0, 50000.0));
        assert_eq!(x.ticks, vec![2000.0, 5000.0, 10000.0, 20000.0, 50000.0]);
        assert_eq!(
            x.minor(),
            vec![
                3000.0, 4000.0, 6000.0, 7000.0, 8000.0, 9000.0, 30000.0, 40000.0
            ]
        );
        let y = Axis::fit([0.39, 10.5].into_iter());
        assert_eq!((y.lo, y.hi), (0.2, 20.0));
        assert!(y.ticks.contains(&1.0) && y.ticks.contains(&10.0));
        // A single value still gets a decade.
        let one = Axis::fit([3.0].into_iter());
        assert!(one.hi / one.lo >= 9.99 && one.lo <= 3.0 && one.hi >= 3.0);
        // Over many decades, ticks only at the powers of ten.
        let wide = Axis::fit([1.0, 1e6].into_iter());
        assert_eq!(wide.ticks, vec![1.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1e6]);
        assert_eq!(wide.minor().len(), 6 * 8);
        // Over very many, at every second one, with the others as fainter lines.
        let long = Axis::fit([1e-14, 0.8].into_iter());
        let labels: Vec<String> = long.ticks.iter().map(|&t| tick_label(t)).collect();
        assert_eq!(
            labels,
            [
                "10⁻¹⁴",
                "10⁻¹²",
                "10⁻¹⁰",
                "10⁻⁸",
                "10⁻⁶",
                "10⁻⁴",
                "0.01",
                "1"
            ]
        );
        assert_eq!(long.minor().len(), 7);
    }

    #[test]
    fn tick_labels_read_as_people_write_them() {
        let labels = [0.05, 300.0, 20000.0, 5e6, 1e-3, 1e-6, 2e-6, 1e-10];
        assert_eq!(
            labels.map(tick_label),
            [
                "0.05",
                "300",
                "20k",
                "5M",
                "0.001",
                "10⁻⁶",
                "2×10⁻⁶",
                "10⁻¹⁰"
            ]
        );
    }

    #[test]
    fn svg_has_the_title_labels_ticks_and_a_legend_beside_the_plot() {
        let c = chart();
        let svg = c.svg().expect("draws");
        let texts = texts(&svg);
        let has = |s: &str| texts.iter().any(|(_, t)| t == s);
        for label in [&c.title, &c.x_label, "uniform", "discontinuity"] {
            assert!(has(label), "{label} in {texts:?}");
        }
        // Escaped as XML.
        assert!(svg.contains("RMS error (% of mean)"));
        for tick in ["2000", "5000", "10k", "20k", "50k", "0.2", "1", "10", "20"] {
            assert!(has(tick), "tick {tick} in {texts:?}");
        }
        assert!(svg.contains("rotate(270"), "the y label reads upwards");
        // The legend's names are right of the plot, where no line goes.
        let right = c.layout().expect("lays out").plot[2] * f64::from(SVG_SCALE);
        for name in ["uniform", "discontinuity"] {
            let (x, _) = texts.iter().find(|(_, t)| t == name).expect("named");
            assert!(*x > right, "{name} at {x}, plot ends at {right}");
        }
        // Sized in points, drawn in finer units.
        assert!(svg.starts_with("<svg width=\"720\" height=\"460\" viewBox=\"0 0 2880 1840\""));
    }

    #[test]
    fn svg_shows_every_usable_point_and_a_line_per_series() {
        let c = chart();
        let svg = c.svg().expect("draws");
        // Five usable points, plus one legend marker per series; the (0, 1) point is left out.
        assert_eq!(svg.matches("<circle").count(), 5 + 2);
        assert_eq!(svg.matches("<polyline").count(), 1 + 2, "frame and 2 lines");
        for color in ["#0072B2", "#D55E00"] {
            assert!(svg.contains(&format!("stroke=\"{color}\"")), "{color}");
        }
        // A dense series is a line alone, in the legend as in the plot.
        let dense = LogLogChart {
            series: vec![Series {
                name: "dense".into(),
                points: (1..=100)
                    .map(|n| (f64::from(n), 1.0 / f64::from(n)))
                    .collect(),
            }],
            ..chart()
        };
        let svg = dense.svg().expect("draws");
        assert_eq!(svg.matches("<circle").count(), 0);
        assert_eq!(svg.matches("<polyline").count(), 1 + 1);
    }

    #[test]
    fn points_that_are_not_positive_and_finite_are_left_out() {
        let c = LogLogChart {
            series: vec![Series {
                name: "odd".into(),
                points: vec![
                    (10.0, 1.0),
                    (0.0, 5.0),
                    (-3.0, 2.0),
                    (f64::NAN, 2.0),
                    (20.0, f64::INFINITY),
                    (50.0, -1.0),
                    (100.0, 2.0),
                ],
            }],
            ..chart()
        };
        let layout = c.layout().expect("lays out");
        assert_eq!((layout.x_axis.lo, layout.x_axis.hi), (10.0, 100.0));
        assert_eq!((layout.y_axis.lo, layout.y_axis.hi), (0.5, 5.0));
        let svg = c.svg().expect("draws");
        assert_eq!(svg.matches("<circle").count(), 2 + 1);
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
        // Values at the ends of f64's range neither hang nor panic.
        let extreme = LogLogChart {
            series: vec![Series {
                name: "extreme".into(),
                points: vec![(1e-320, 1e-300), (1.7e308, 1e300)],
            }],
            ..chart()
        };
        assert!(extreme.svg().is_ok() && extreme.png().is_ok());
        // Nothing usable at all still gives a chart.
        let empty = LogLogChart {
            series: vec![],
            ..chart()
        };
        assert!(empty.svg().expect("draws").contains(&empty.title));
        assert!(empty.png().is_ok());
    }

    #[test]
    fn wide_ranges_are_labelled_at_the_decades() {
        let c = LogLogChart {
            series: vec![Series {
                name: "residual".into(),
                points: (0..=6).map(|k| (10f64.powi(k), 10f64.powi(-k))).collect(),
            }],
            ..chart()
        };
        let svg = c.svg().expect("draws");
        let texts = texts(&svg);
        for tick in [
            "1", "10", "100", "1000", "10k", "100k", "1M", "0.1", "0.001", "10⁻⁶",
        ] {
            assert!(texts.iter().any(|(_, t)| t == tick), "{tick} in {texts:?}");
        }
        assert!(!texts.iter().any(|(_, t)| t == "2" || t == "5" || t == "20"));
    }

    #[test]
    fn png_draws_the_series_in_their_colours_where_the_points_are() {
        let c = chart();
        let image = png_of(&c);
        assert_eq!(
            image.dimensions(),
            ((WIDTH as u32) * PNG_SCALE, (HEIGHT as u32) * PNG_SCALE)
        );
        let layout = c.layout().expect("lays out");
        for (k, s) in c.series.iter().enumerate() {
            for p in s.usable() {
                let at = pixel(&layout, p);
                assert!(drawn_near(&image, at, 1, PALETTE[k]), "{} at {p:?}", s.name);
            }
        }
        // Halfway along the first line (in log space), its colour again.
        let (a, b) = ((2500f64, 10.5f64), (5000f64, 7.0f64));
        let middle = ((a.0 * b.0).sqrt(), (a.1 * b.1).sqrt());
        assert!(drawn_near(&image, pixel(&layout, middle), 1, PALETTE[0]));
        // White outside the plot, away from text.
        assert_eq!(image.get_pixel(2, 2).0, [255, 255, 255]);
    }

    #[test]
    fn png_lines_that_turn_back_are_drawn_whole() {
        // Error against time: a larger budget may take less time, and the line turns back, here
        // onto itself (a sweep's error-driven runs, whose meshes stopped growing).
        let points = vec![
            (0.0102, 0.696),
            (0.0156, 0.535),
            (0.0079, 0.535),
            (0.0114, 0.535),
        ];
        let c = LogLogChart {
            series: vec![Series {
                name: "error-driven".into(),
                points: points.clone(),
            }],
            ..chart()
        };
        let image = png_of(&c);
        let layout = c.layout().expect("lays out");
        for pair in points.windows(2) {
            let ((x0, y0), (x1, y1)) = (pair[0], pair[1]);
            let middle = ((x0 * x1).sqrt(), (y0 * y1).sqrt());
            let (x, y) = pixel(&layout, middle);
            // Two pixels across a line four pixels wide: both in the line's colour.
            assert!(
                [y, y + 1]
                    .iter()
                    .all(|&y| drawn_near(&image, (x, y), 0, PALETTE[0]))
                    || [y - 1, y]
                        .iter()
                        .all(|&y| drawn_near(&image, (x, y), 0, PALETTE[0])),
                "{middle:?}"
            );
        }
    }

    #[test]
    fn png_text_is_antialiased() {
        let image = png_of(&chart());
        // The title's band holds greys between the ink and the paper, not just the two.
        let rows = (MARGIN as u32 * PNG_SCALE)..((MARGIN + TITLE_FONT) as u32 * PNG_SCALE);
        let mut greys: Vec<u8> = rows
            .flat_map(|y| (0..image.width()).map(move |x| (x, y)))
            .map(|(x, y)| image.get_pixel(x, y).0[0])
            .filter(|&g| g > INK.0 && g < 255)
            .collect();
        greys.sort_unstable();
        greys.dedup();
        assert!(greys.len() > 20, "{} grey levels", greys.len());
    }

    #[test]
    fn the_same_chart_gives_the_same_bytes() {
        let c = chart();
        assert_eq!(c.svg().expect("draws"), c.svg().expect("draws"));
        assert_eq!(c.png().expect("encodes"), c.png().expect("encodes"));
        assert_ne!(
            c.png().expect("encodes"),
            LogLogChart {
                title: "another".into(),
                ..chart()
            }
            .png()
            .expect("encodes")
        );
    }

    #[test]
    fn names_are_kept_on_one_line_and_escaped() {
        let c = LogLogChart {
            title: "a < b & c\nd\u{1}".into(),
            ..chart()
        };
        let svg = c.svg().expect("draws");
        assert!(svg.contains("a &lt; b &amp; c d "), "{svg}");
        assert!(!svg.chars().any(|ch| ch.is_control() && ch != '\n'));
    }
}
