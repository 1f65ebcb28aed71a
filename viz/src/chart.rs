//! Log–log line charts (error against elements, error against time), drawn as SVG and as PNG
//! from one layout, so that the two files show the same thing.
//!
//! The layout is a list of primitives in chart points (y down): lines, polylines, markers and
//! text. The SVG backend writes them as elements; the PNG backend rasterizes them at
//! [`PNG_SCALE`] pixels per point, with antialiased strokes and the public-domain 8×8 bitmap font
//! of the `font8x8` crate, so a PNG needs no font installed. The same chart gives the same bytes.

use std::fmt::Write;

use glam::DVec2;
use image::{Rgb, RgbImage};
use penumbra_scenes::polygon::closest_point_on_segment;

use crate::VizError;
use crate::render::encode_png;
use crate::svg_plot::escape;

const WIDTH: f64 = 720.0;
const HEIGHT: f64 = 460.0;
const LEFT: f64 = 64.0;
/// Room right of the plot for the legend, at least; long names take more.
const RIGHT: f64 = 160.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 48.0;
/// Glyph cell of the bitmap font, in points; SVG text uses the same size.
const FONT: f64 = 8.0;
/// Series with more points than this are drawn as lines without markers.
const MAX_MARKERS: usize = 60;
/// PNG pixels per chart point.
pub(crate) const PNG_SCALE: u32 = 2;

/// Line colours of successive series (colour-blind safe, after Okabe & Ito).
const PALETTE: [[u8; 3]; 7] = [
    [0, 114, 178],
    [213, 94, 0],
    [0, 158, 115],
    [204, 121, 167],
    [230, 159, 0],
    [86, 180, 233],
    [0, 0, 0],
];
const GRID: [u8; 3] = [225, 225, 225];
const INK: [u8; 3] = [40, 40, 40];

/// One line of a chart: its name in the legend and its points (x, y), drawn in the given order.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The name in the legend.
    pub name: String,
    /// The points (x, y).
    pub points: Vec<(f64, f64)>,
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

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Anchor {
    Start,
    Middle,
    End,
}

#[derive(Clone, Debug)]
enum Shape {
    Line {
        from: DVec2,
        to: DVec2,
        color: [u8; 3],
        width: f64,
    },
    Polyline {
        points: Vec<DVec2>,
        color: [u8; 3],
        width: f64,
    },
    Marker {
        at: DVec2,
        color: [u8; 3],
        radius: f64,
    },
    /// Text with its baseline-left corner at `at` (after anchoring); `scale` times the font.
    Text {
        at: DVec2,
        text: String,
        anchor: Anchor,
        scale: f64,
        vertical: bool,
    },
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
        let decades = (hi / lo).log10();
        let multiples: &[f64] = if decades <= 2.5 {
            &[1.0, 2.0, 5.0]
        } else {
            &[1.0]
        };
        let mut ticks = Vec::new();
        let mut e = lo.log10().floor() as i32;
        while 10f64.powi(e) <= hi * (1.0 + 1e-12) {
            for m in multiples {
                let t = m * 10f64.powi(e);
                if t >= lo * (1.0 - 1e-12) && t <= hi * (1.0 + 1e-12) {
                    ticks.push(t);
                }
            }
            e += 1;
        }
        Axis { lo, hi, ticks }
    }

    /// Where `v` falls, 0 at `lo` and 1 at `hi`.
    fn unit(&self, v: f64) -> f64 {
        (v / self.lo).log10() / (self.hi / self.lo).log10()
    }
}

/// A tick value as people write it: 0.05, 2, 300, 20k.
fn tick_label(v: f64) -> String {
    if v >= 1e4 {
        return format!("{}k", tick_label(v / 1e3));
    }
    let decimals = (-v.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

impl LogLogChart {
    fn layout(&self) -> Vec<Shape> {
        let usable = |&(x, y): &(f64, f64)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite();
        let points = || {
            self.series
                .iter()
                .flat_map(|s| s.points.iter().filter(|p| usable(p)))
        };
        let x_axis = Axis::fit(points().map(|p| p.0));
        let y_axis = Axis::fit(points().map(|p| p.1));
        let longest = self.series.iter().map(|s| s.name.chars().count()).max();
        let right = RIGHT.max(52.0 + FONT * longest.unwrap_or(0) as f64);
        // Room left of the plot for the y label and the widest tick label.
        let widest = y_axis
            .ticks
            .iter()
            .map(|&t| tick_label(t).chars().count())
            .max()
            .unwrap_or(0);
        let left = LEFT.max(16.0 + 2.0 * FONT + 6.0 + FONT * widest as f64);
        let (x0, x1, y0, y1) = (left, WIDTH - right, HEIGHT - BOTTOM, TOP);
        let at = |x: f64, y: f64| {
            DVec2::new(
                x0 + (x1 - x0) * x_axis.unit(x),
                y0 + (y1 - y0) * y_axis.unit(y),
            )
        };
        let mut shapes = Vec::new();
        let line = |from, to, color, width| Shape::Line {
            from,
            to,
            color,
            width,
        };
        let text = |at, text: &str, anchor, scale, vertical| Shape::Text {
            at,
            text: text.to_owned(),
            anchor,
            scale,
            vertical,
        };
        for &t in &x_axis.ticks {
            let p = at(t, y_axis.lo);
            shapes.push(line(DVec2::new(p.x, y0), DVec2::new(p.x, y1), GRID, 1.0));
            shapes.push(text(
                DVec2::new(p.x, y0 + 6.0 + FONT),
                &tick_label(t),
                Anchor::Middle,
                1.0,
                false,
            ));
        }
        for &t in &y_axis.ticks {
            let p = at(x_axis.lo, t);
            shapes.push(line(DVec2::new(x0, p.y), DVec2::new(x1, p.y), GRID, 1.0));
            shapes.push(text(
                DVec2::new(x0 - 6.0, p.y + FONT / 2.0),
                &tick_label(t),
                Anchor::End,
                1.0,
                false,
            ));
        }
        let corners = [
            DVec2::new(x0, y0),
            DVec2::new(x1, y0),
            DVec2::new(x1, y1),
            DVec2::new(x0, y1),
            DVec2::new(x0, y0),
        ];
        shapes.push(Shape::Polyline {
            points: corners.to_vec(),
            color: INK,
            width: 1.0,
        });
        shapes.push(text(
            DVec2::new((x0 + x1) / 2.0, 14.0 + FONT * 2.0 - 4.0),
            &self.title,
            Anchor::Middle,
            1.5,
            false,
        ));
        shapes.push(text(
            DVec2::new((x0 + x1) / 2.0, HEIGHT - 10.0),
            &self.x_label,
            Anchor::Middle,
            1.0,
            false,
        ));
        shapes.push(text(
            DVec2::new(16.0 + FONT, (y0 + y1) / 2.0),
            &self.y_label,
            Anchor::Middle,
            1.0,
            true,
        ));
        for (k, s) in self.series.iter().enumerate() {
            let color = PALETTE[k % PALETTE.len()];
            let pts: Vec<DVec2> = s
                .points
                .iter()
                .filter(|p| usable(p))
                .map(|&(x, y)| at(x, y))
                .collect();
            if pts.len() > 1 {
                shapes.push(Shape::Polyline {
                    points: pts.clone(),
                    color,
                    width: 2.0,
                });
            }
            // Markers show where the data are; on a dense series they would only blot the line.
            for &p in pts.iter().filter(|_| pts.len() <= MAX_MARKERS) {
                shapes.push(Shape::Marker {
                    at: p,
                    color,
                    radius: 3.0,
                });
            }
            let row = DVec2::new(x1 + 14.0, y1 + 10.0 + 16.0 * k as f64);
            shapes.push(line(row, row + DVec2::new(22.0, 0.0), color, 2.0));
            shapes.push(Shape::Marker {
                at: row + DVec2::new(11.0, 0.0),
                color,
                radius: 3.0,
            });
            shapes.push(text(
                row + DVec2::new(28.0, FONT / 2.0 - 0.5),
                &s.name,
                Anchor::Start,
                1.0,
                false,
            ));
        }
        shapes
    }

    /// The chart as an SVG document.
    pub fn svg(&self) -> String {
        let mut out = String::new();
        let hex = |c: [u8; 3]| format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]);
        let _ = writeln!(
            out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{HEIGHT}\" \
             viewBox=\"0 0 {WIDTH} {HEIGHT}\" font-family=\"monospace\" font-size=\"{FONT}\">"
        );
        let _ = writeln!(
            out,
            "<rect width=\"{WIDTH}\" height=\"{HEIGHT}\" fill=\"#ffffff\"/>"
        );
        for shape in self.layout() {
            match shape {
                Shape::Line {
                    from,
                    to,
                    color,
                    width,
                } => {
                    let _ = writeln!(
                        out,
                        "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\" stroke=\"{}\" stroke-width=\"{width}\"/>",
                        from.x,
                        from.y,
                        to.x,
                        to.y,
                        hex(color)
                    );
                }
                Shape::Polyline {
                    points,
                    color,
                    width,
                } => {
                    let pts: Vec<String> = points
                        .iter()
                        .map(|p| format!("{:.2},{:.2}", p.x, p.y))
                        .collect();
                    let _ = writeln!(
                        out,
                        "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{width}\" stroke-linejoin=\"round\"/>",
                        pts.join(" "),
                        hex(color)
                    );
                }
                Shape::Marker { at, color, radius } => {
                    let _ = writeln!(
                        out,
                        "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"{radius}\" fill=\"{}\"/>",
                        at.x,
                        at.y,
                        hex(color)
                    );
                }
                Shape::Text {
                    at,
                    text,
                    anchor,
                    scale,
                    vertical,
                } => {
                    let anchor = match anchor {
                        Anchor::Start => "start",
                        Anchor::Middle => "middle",
                        Anchor::End => "end",
                    };
                    let rotate = if vertical {
                        format!(" transform=\"rotate(-90 {:.2} {:.2})\"", at.x, at.y)
                    } else {
                        String::new()
                    };
                    let _ = writeln!(
                        out,
                        "<text x=\"{:.2}\" y=\"{:.2}\" text-anchor=\"{anchor}\" font-size=\"{}\" fill=\"{}\"{rotate}>{}</text>",
                        at.x,
                        at.y,
                        FONT * scale * 1.25,
                        hex(INK),
                        escape(&text)
                    );
                }
            }
        }
        out.push_str("</svg>\n");
        out
    }

    /// The chart as a PNG file's bytes.
    pub fn png(&self) -> Result<Vec<u8>, VizError> {
        let s = PNG_SCALE as f64;
        let mut canvas = Canvas {
            image: RgbImage::from_pixel(
                (WIDTH * s) as u32,
                (HEIGHT * s) as u32,
                Rgb([255, 255, 255]),
            ),
        };
        for shape in self.layout() {
            match shape {
                Shape::Line {
                    from,
                    to,
                    color,
                    width,
                } => canvas.stroke(from * s, to * s, width * s, color),
                Shape::Polyline {
                    points,
                    color,
                    width,
                } => {
                    for w in points.windows(2) {
                        canvas.stroke(w[0] * s, w[1] * s, width * s, color);
                    }
                }
                Shape::Marker { at, color, radius } => canvas.disc(at * s, radius * s, color),
                Shape::Text {
                    at,
                    text,
                    anchor,
                    scale,
                    vertical,
                } => canvas.text(at * s, &text, anchor, (scale * s).round() as u32, vertical),
            }
        }
        encode_png(&canvas.image)
    }
}

struct Canvas {
    image: RgbImage,
}

impl Canvas {
    /// Blends `color` over a pixel with coverage `alpha`.
    fn blend(&mut self, x: i64, y: i64, color: [u8; 3], alpha: f64) {
        let (w, h) = self.image.dimensions();
        if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 || !(alpha > 0.0) {
            return;
        }
        let a = alpha.min(1.0);
        let p = self.image.get_pixel_mut(x as u32, y as u32);
        for k in 0..3 {
            p.0[k] = (p.0[k] as f64 * (1.0 - a) + color[k] as f64 * a).round() as u8;
        }
    }

    /// Coverage of pixels by the shape whose signed distance is `distance`, within a box.
    fn fill(&mut self, lo: DVec2, hi: DVec2, color: [u8; 3], distance: impl Fn(DVec2) -> f64) {
        for y in lo.y.floor() as i64..=hi.y.ceil() as i64 {
            for x in lo.x.floor() as i64..=hi.x.ceil() as i64 {
                let centre = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let coverage = (0.5 - distance(centre)).clamp(0.0, 1.0);
                self.blend(x, y, color, coverage);
            }
        }
    }

    fn stroke(&mut self, a: DVec2, b: DVec2, width: f64, color: [u8; 3]) {
        let r = width / 2.0;
        self.fill(a.min(b) - r - 1.0, a.max(b) + r + 1.0, color, |p| {
            (p - closest_point_on_segment(p, a, b)).length() - r
        });
    }

    fn disc(&mut self, at: DVec2, radius: f64, color: [u8; 3]) {
        self.fill(at - radius - 1.0, at + radius + 1.0, color, |p| {
            (p - at).length() - radius
        });
    }

    /// Text from the 8×8 font, each glyph pixel `scale` pixels wide; `at` is the baseline's
    /// anchor point (for vertical text, reading upwards, the anchor is on the baseline too).
    fn text(&mut self, at: DVec2, text: &str, anchor: Anchor, scale: u32, vertical: bool) {
        let scale = scale.max(1) as i64;
        let cell = 8 * scale;
        let length = text.chars().count() as i64 * cell;
        let shift = match anchor {
            Anchor::Start => 0,
            Anchor::Middle => length / 2,
            Anchor::End => length,
        };
        let (ax, ay) = (at.x.round() as i64, at.y.round() as i64);
        for (k, ch) in text.chars().enumerate() {
            let glyph = font8x8::legacy::BASIC_LEGACY
                .get(ch as usize)
                .copied()
                .unwrap_or(font8x8::legacy::BASIC_LEGACY[b'?' as usize]);
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits >> col & 1 == 0 {
                        continue;
                    }
                    // Glyph coordinates: u along the text, v down from the top of the cell,
                    // which sits one cell above the baseline.
                    let u = k as i64 * cell - shift + col as i64 * scale;
                    let v = row as i64 * scale - cell + scale;
                    for dy in 0..scale {
                        for dx in 0..scale {
                            let (x, y) = if vertical {
                                (ax + v + dy, ay - u - dx)
                            } else {
                                (ax + u + dx, ay + v + dy)
                            };
                            self.blend(x, y, INK, 1.0);
                        }
                    }
                }
            }
        }
    }
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

    #[test]
    fn axes_cover_the_data_in_whole_steps() {
        let x = Axis::fit([2000.0, 30000.0].into_iter());
        assert_eq!((x.lo, x.hi), (2000.0, 50000.0));
        assert_eq!(x.ticks, vec![2000.0, 5000.0, 10000.0, 20000.0, 50000.0]);
        let y = Axis::fit([0.39, 10.5].into_iter());
        assert_eq!((y.lo, y.hi), (0.2, 20.0));
        assert!(y.ticks.contains(&1.0) && y.ticks.contains(&10.0));
        // A single value still gets a decade.
        let one = Axis::fit([3.0].into_iter());
        assert!(one.hi / one.lo >= 9.99 && one.lo <= 3.0 && one.hi >= 3.0);
        assert_eq!(tick_label(0.05), "0.05");
        assert_eq!(tick_label(300.0), "300");
        assert_eq!(tick_label(20000.0), "20k");
    }

    #[test]
    fn svg_and_png_show_every_usable_point() {
        let c = chart();
        let svg = c.svg();
        // Five usable points, plus one legend marker per series; the (0, 1) point is left out.
        assert_eq!(svg.matches("<circle").count(), 5 + 2);
        assert!(svg.contains("discontinuity") && svg.contains("rotate(-90"));
        let png = c.png().expect("encodes");
        let image = image::load_from_memory(&png).expect("decodes").to_rgb8();
        assert_eq!(
            image.dimensions(),
            ((WIDTH as u32) * PNG_SCALE, (HEIGHT as u32) * PNG_SCALE)
        );
        // The first series' colour is drawn where its first point lies.
        let layout = c.layout();
        let first = layout
            .iter()
            .find_map(|s| match s {
                Shape::Marker { at, color, .. } if *color == PALETTE[0] => Some(*at),
                _ => None,
            })
            .expect("a marker");
        let px = image.get_pixel(
            (first.x * PNG_SCALE as f64) as u32,
            (first.y * PNG_SCALE as f64) as u32,
        );
        assert_eq!(px.0, PALETTE[0]);
        assert_eq!(
            c.png().expect("encodes"),
            png,
            "the same chart, the same bytes"
        );
    }
}
