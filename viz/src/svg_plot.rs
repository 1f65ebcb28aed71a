//! A small SVG plot builder for figures in a plane: data in its own units with y up, written as
//! SVG with y down, a fitted view box, a title, a scale bar and a legend.
//!
//! Geometry goes into named layers (`class`), each drawn as one SVG group with one line style;
//! legend entries show a layer's style next to a label. Numbers are written with the shortest
//! decimal form that reads back as the same `f64`, and nothing depends on hashing or threads, so
//! the same plot always gives the same bytes.

use std::fmt::Write;

use glam::DVec2;

/// Size of the longer side of the data on the canvas, in pixels; widths and fonts are in these.
const PLOT_PX: f64 = 640.0;
const MARGIN_PX: f64 = 24.0;
const TITLE_PX: f64 = 20.0;
const NOTE_PX: f64 = 16.0;
const FONT_PX: f64 = 13.0;
const SCALE_BAR_PX: f64 = 30.0;
const LEGEND_ROW_PX: f64 = 18.0;
const LEGEND_SAMPLE_PX: f64 = 26.0;

/// How a layer's lines look; widths and dashes are in canvas pixels.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LineStyle {
    pub(crate) color: String,
    pub(crate) width_px: f64,
    pub(crate) dash_px: Option<[f64; 2]>,
}

impl LineStyle {
    pub(crate) fn solid(color: &str, width_px: f64) -> LineStyle {
        LineStyle {
            color: color.to_owned(),
            width_px,
            dash_px: None,
        }
    }
}

#[derive(Debug)]
struct Layer {
    class: String,
    style: LineStyle,
    /// SVG elements, already in SVG coordinates.
    elements: Vec<String>,
}

#[derive(Debug)]
pub(crate) struct SvgPlot {
    title: String,
    notes: Vec<String>,
    /// The data's bounding box, grown by everything added.
    bounds: Option<(DVec2, DVec2)>,
    layers: Vec<Layer>,
    labels: Vec<(DVec2, String)>,
    legend: Vec<(String, String)>,
    unit: String,
}

impl SvgPlot {
    /// An empty plot; `unit` names the data's length unit on the scale bar.
    pub(crate) fn new(title: &str, unit: &str) -> SvgPlot {
        SvgPlot {
            title: title.to_owned(),
            notes: Vec::new(),
            bounds: None,
            layers: Vec::new(),
            labels: Vec::new(),
            legend: Vec::new(),
            unit: unit.to_owned(),
        }
    }

    /// A line of text under the title.
    pub(crate) fn add_note(&mut self, text: &str) {
        self.notes.push(text.to_owned());
    }

    /// Declares layer `class` with its style; layers are drawn in the order they are declared.
    /// Geometry added to an undeclared class gets a thin black line.
    pub(crate) fn add_layer(&mut self, class: &str, style: LineStyle) {
        match self.layers.iter_mut().find(|l| l.class == class) {
            Some(layer) => layer.style = style,
            None => self.layers.push(Layer {
                class: class.to_owned(),
                style,
                elements: Vec::new(),
            }),
        }
    }

    /// Triangles as outlined polygons, each filled with its colour if `fills` is given.
    pub(crate) fn add_triangles(
        &mut self,
        triangles: &[[DVec2; 3]],
        fills: Option<&[[u8; 3]]>,
        class: &str,
    ) {
        let mut elements = Vec::with_capacity(triangles.len());
        for (t, corners) in triangles.iter().enumerate() {
            corners.iter().for_each(|&p| self.include(p));
            let points = corners.map(svg_point).join(" ");
            let fill = match fills.and_then(|f| f.get(t)) {
                Some([r, g, b]) => format!(" fill=\"#{r:02x}{g:02x}{b:02x}\""),
                None => String::new(),
            };
            elements.push(format!("<polygon points=\"{points}\"{fill}/>"));
        }
        self.layer(class).elements.extend(elements);
    }

    /// A closed outline.
    pub(crate) fn add_outline(&mut self, points: &[DVec2], class: &str) {
        if points.is_empty() {
            return;
        }
        points.iter().for_each(|&p| self.include(p));
        let d: Vec<String> = points
            .iter()
            .map(|&p| svg_point(p).replace(',', " "))
            .collect();
        let element = format!("<path d=\"M {} Z\"/>", d.join(" L "));
        self.layer(class).elements.push(element);
    }

    /// An open polyline (two points make a segment).
    pub(crate) fn add_polyline(&mut self, points: &[DVec2], class: &str) {
        if points.len() < 2 {
            return;
        }
        points.iter().for_each(|&p| self.include(p));
        let points: Vec<String> = points.iter().map(|&p| svg_point(p)).collect();
        let element = format!("<polyline points=\"{}\"/>", points.join(" "));
        self.layer(class).elements.push(element);
    }

    /// A text label at a data point.
    pub(crate) fn add_label(&mut self, at: DVec2, text: &str) {
        self.include(at);
        self.labels.push((at, text.to_owned()));
    }

    /// A legend line: a short sample of layer `class`'s style, then `label`.
    pub(crate) fn add_legend_entry(&mut self, label: &str, class: &str) {
        self.legend.push((label.to_owned(), class.to_owned()));
    }

    fn include(&mut self, p: DVec2) {
        if !p.is_finite() {
            return;
        }
        self.bounds = Some(match self.bounds {
            None => (p, p),
            Some((lo, hi)) => (lo.min(p), hi.max(p)),
        });
    }

    fn layer(&mut self, class: &str) -> &mut Layer {
        let index = match self.layers.iter().position(|l| l.class == class) {
            Some(index) => index,
            None => {
                self.add_layer(class, LineStyle::solid("#000000", 1.0));
                self.layers.len() - 1
            }
        };
        &mut self.layers[index]
    }

    /// The SVG document.
    pub(crate) fn finish(&self) -> String {
        let (lo, hi) = self.bounds.unwrap_or((DVec2::ZERO, DVec2::ONE));
        let extent = (hi - lo).max_element();
        let extent = if extent > 0.0 && extent.is_finite() {
            extent
        } else {
            lo.abs().max(hi.abs()).max_element().max(1.0)
        };
        // Data units per canvas pixel.
        let px = extent / PLOT_PX;
        let header_px = MARGIN_PX + TITLE_PX + NOTE_PX * self.notes.len() as f64;
        let footer_px = SCALE_BAR_PX + LEGEND_ROW_PX * self.legend.len() as f64 + MARGIN_PX;
        let left = lo.x - MARGIN_PX * px;
        let top = -hi.y - header_px * px;
        let width = (hi.x - lo.x) + 2.0 * MARGIN_PX * px;
        let height = (hi.y - lo.y) + (header_px + MARGIN_PX + footer_px) * px;
        // The legend needs some width even for a narrow plot.
        let width = width.max(260.0 * px);

        let mut out = String::new();
        out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" width=\"{}\" height=\"{}\">",
            num(left),
            num(top),
            num(width),
            num(height),
            num((width / px).round()),
            num((height / px).round()),
        );
        let _ = writeln!(out, "<title>{}</title>", escape(&self.title));
        let _ = writeln!(
            out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#ffffff\"/>",
            num(left),
            num(top),
            num(width),
            num(height)
        );
        let mut y = top + (MARGIN_PX + 0.5 * TITLE_PX) * px;
        let _ = writeln!(
            out,
            "{}",
            svg_text(px, lo.x, y, " font-weight=\"bold\"", &self.title)
        );
        for note in &self.notes {
            y += NOTE_PX * px;
            let _ = writeln!(out, "{}", svg_text(px, lo.x, y, "", note));
        }

        self.write_layers(&mut out, px);
        self.write_scale_bar(&mut out, lo, extent, px);
        self.write_legend(&mut out, lo, px);
        out.push_str("</svg>\n");
        out
    }

    /// The layers, each a group of one line style, and the labels over them.
    fn write_layers(&self, out: &mut String, px: f64) {
        for layer in &self.layers {
            let _ = writeln!(
                out,
                "<g class=\"{}\" fill=\"none\" {}>",
                escape(&layer.class),
                stroke(&layer.style, px)
            );
            for element in &layer.elements {
                out.push_str(element);
                out.push('\n');
            }
            out.push_str("</g>\n");
        }
        for (at, label) in &self.labels {
            let _ = writeln!(
                out,
                "{}",
                svg_text(px, at.x + 3.0 * px, -at.y - 3.0 * px, "", label)
            );
        }
    }

    /// A bar of a round length under the plot, from its left edge, with its length.
    fn write_scale_bar(&self, out: &mut String, lo: DVec2, extent: f64, px: f64) {
        // Scale bar under the plot, from its left edge.
        let bar = nice_length(0.25 * extent);
        let bar_y = -lo.y + (MARGIN_PX + 0.5 * SCALE_BAR_PX) * px;
        let tick = 4.0 * px;
        let _ = writeln!(
            out,
            "<path class=\"scale-bar\" d=\"M {x0} {a} L {x0} {b} L {x1} {b} L {x1} {a}\" fill=\"none\" stroke=\"#202020\" stroke-width=\"{w}\"/>",
            x0 = num(lo.x),
            x1 = num(lo.x + bar.0),
            a = num(bar_y - tick),
            b = num(bar_y),
            w = num(1.5 * px),
        );
        let _ = writeln!(
            out,
            "{}",
            svg_text(
                px,
                lo.x + bar.0 + 6.0 * px,
                bar_y + 4.0 * px,
                "",
                &format!("{} {}", bar.1, self.unit)
            )
        );
    }

    /// A row per legend entry: its layer's line style and its label.
    fn write_legend(&self, out: &mut String, lo: DVec2, px: f64) {
        let mut row_y = -lo.y + (MARGIN_PX + SCALE_BAR_PX + 0.5 * LEGEND_ROW_PX) * px;
        for (label, class) in &self.legend {
            let style = self
                .layers
                .iter()
                .find(|l| &l.class == class)
                .map_or_else(|| LineStyle::solid("#000000", 1.0), |l| l.style.clone());
            let _ = writeln!(
                out,
                "<line class=\"legend {}\" x1=\"{}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" {}/>",
                escape(class),
                num(lo.x),
                num(lo.x + LEGEND_SAMPLE_PX * px),
                stroke(&style, px),
                y = num(row_y),
            );
            let _ = writeln!(
                out,
                "{}",
                svg_text(
                    px,
                    lo.x + (LEGEND_SAMPLE_PX + 6.0) * px,
                    row_y + 4.0 * px,
                    "",
                    label
                )
            );
            row_y += LEGEND_ROW_PX * px;
        }
    }
}

/// A `<text>` at `(x, y)` in data units, laid out in canvas pixels and scaled by `px` data units
/// per pixel: renderers that lay out fonts at whole sizes (librsvg) garble a font a tenth of a
/// unit tall.
fn svg_text(px: f64, x: f64, y: f64, weight: &str, content: &str) -> String {
    format!(
        "<text transform=\"translate({} {}) scale({})\" font-family=\"sans-serif\" \
         font-size=\"{}\" fill=\"#202020\"{weight}>{}</text>",
        num(x),
        num(y),
        num(px),
        num(FONT_PX),
        escape(content)
    )
}

/// Stroke attributes of a style at `px` data units per canvas pixel.
fn stroke(style: &LineStyle, px: f64) -> String {
    let mut s = format!(
        "stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\" stroke-linecap=\"round\"",
        escape(&style.color),
        num(style.width_px * px)
    );
    if let Some([on, off]) = style.dash_px {
        let _ = write!(
            s,
            " stroke-dasharray=\"{} {}\"",
            num(on * px),
            num(off * px)
        );
    }
    s
}

/// A data point (y up) as SVG `x,y` (y down).
fn svg_point(p: DVec2) -> String {
    format!("{},{}", num(p.x), num(-p.y))
}

/// The shortest decimal that reads back as `x` (never exponent notation; `-0` as `0`).
fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{}", x + 0.0)
    } else {
        "0".to_owned()
    }
}

/// A round length (1, 2 or 5 times a power of ten) no longer than `limit`, and its label.
fn nice_length(limit: f64) -> (f64, String) {
    if !(limit > 0.0 && limit.is_finite()) {
        return (1.0, "1".to_owned());
    }
    let exponent = limit.log10().floor() as i32;
    let power = 10f64.powi(exponent);
    let mantissa = [5.0, 2.0, 1.0]
        .into_iter()
        .find(|&m| m * power <= limit)
        .unwrap_or(1.0);
    let length = mantissa * power;
    let label = if exponent >= 0 {
        format!("{length}")
    } else {
        format!("{length:.*}", exponent.unsigned_abs() as usize)
    };
    (length, label)
}

/// XML text and attribute escaping, for every SVG this crate writes.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters other than tab and newlines are not allowed in XML 1.0.
            c if c.is_control() && !matches!(c, '\t' | '\n' | '\r') => out.push('\u{fffd}'),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip() {
        for x in [0.1, 1.0 / 3.0, 1e9 + 0.123, -2.5e-7, 123456.789] {
            assert_eq!(num(x).parse::<f64>().expect("a number"), x);
            assert!(!num(x).contains('e'));
        }
        assert_eq!(num(-0.0), "0");
    }

    #[test]
    fn nice_lengths() {
        assert_eq!(nice_length(137.0), (100.0, "100".to_owned()));
        assert_eq!(nice_length(0.26), (0.2, "0.2".to_owned()));
        assert_eq!(nice_length(0.0051).1, "0.005");
        assert_eq!(nice_length(5.0).0, 5.0);
    }

    #[test]
    fn escapes_markup() {
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
    }

    #[test]
    fn layers_and_legend() {
        let mut plot = SvgPlot::new("demo", "m");
        plot.add_layer("umbra", LineStyle::solid("#d62728", 2.0));
        plot.add_triangles(
            &[[DVec2::ZERO, DVec2::X, DVec2::Y]],
            Some(&[[255, 0, 16]]),
            "mesh",
        );
        plot.add_polyline(&[DVec2::ZERO, DVec2::new(0.5, 0.5)], "umbra");
        plot.add_legend_entry("umbra boundary", "umbra");
        let svg = plot.finish();
        assert!(svg.contains("<g class=\"umbra\" fill=\"none\" stroke=\"#d62728\""));
        assert!(svg.contains("fill=\"#ff0010\""));
        assert!(svg.contains("<polyline points=\"0,0 0.5,-0.5\"/>"));
        assert!(svg.contains("<line class=\"legend umbra\""));
        assert!(svg.contains(">umbra boundary</text>"));
        assert_eq!(svg, plot.finish());
    }
}
