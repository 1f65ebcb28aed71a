//! `solution.vtp`: VTK XML PolyData, which ParaView and VTK read.
//!
//! The triangles are polygons and the discontinuity segments lines. Point data: `radiosity`,
//! `direct` and `indirect` (RGB, W/m²) and `luminance` (of the radiosity, Rec. 709). Cell data,
//! lines first as VTK orders cells: `surface` (the index in `solution.json`), `event`,
//! `boundary` and `order` (codes, -1 on triangles) and, for adaptive runs, `error_indicator`
//! (NaN on lines). A segment's ends are points of their own, where `solution.json` puts them,
//! after the mesh's vertices; their point data are those of the mesh vertex nearest each (the
//! vertex the end was built into, moved by no more than the mesh's welding of close ends), NaN
//! where none is that near.
//! Arrays are appended raw, little endian, in `f64` and `i64`.

use std::fmt::Write as _;

use penumbra_scenes::Rgb;

use super::mesh::{FlatMesh, boundary_names, event_names};

/// How far from a segment's end the mesh vertex it was built into may lie, relative to the
/// diagonal of its surface's vertices' bounding box: the mesh welds ends closer than about 1e-9
/// of a polygon's extent, or a few contact distances where lines meet blocks.
const NEAR_END: f64 = 1e-6;

/// The file's bytes.
pub fn vtp(mesh: &FlatMesh) -> Vec<u8> {
    let ends: Vec<[f64; 3]> = mesh.lines.iter().flat_map(|l| l.ends).collect();
    let mut doc = Document {
        xml: header(mesh, mesh.positions.len() + ends.len()),
        data: Vec::new(),
    };
    doc.xml += "<PointData Scalars=\"luminance\">\n";
    point_data(mesh, &mut doc);
    doc.xml += "</PointData>\n<CellData Scalars=\"surface\">\n";
    cell_data(mesh, &mut doc);
    doc.xml += "</CellData>\n<Points>\n";
    let points: Vec<f64> = mesh
        .positions
        .iter()
        .chain(&ends)
        .flatten()
        .copied()
        .collect();
    doc.array("Float64", "Points", 3, &f64_bytes(&points));
    doc.xml += "</Points>\n<Lines>\n";
    let first = mesh.positions.len() as i64;
    let line_points: Vec<i64> = (first..first + ends.len() as i64).collect();
    doc.cells(&line_points, 2);
    doc.xml += "</Lines>\n<Polys>\n";
    let corners: Vec<i64> = mesh
        .triangles
        .iter()
        .flatten()
        .map(|&i| i64::from(i))
        .collect();
    doc.cells(&corners, 3);
    doc.xml += "</Polys>\n</Piece>\n</PolyData>\n<AppendedData encoding=\"raw\">\n_";
    let mut bytes = doc.xml.into_bytes();
    bytes.extend_from_slice(&doc.data);
    bytes.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    bytes
}

/// The XML up to the piece's data, with a comment that says what the codes mean.
fn header(mesh: &FlatMesh, points: usize) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n\
         <!-- penumbra solution. Cell codes: event {events}; boundary {boundaries}; order 0 \
         value, 1 slope, 2 curvature jumps; -1 on triangles. -->\n\
         <VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">\n<PolyData>\n<Piece NumberOfPoints=\"{points}\" \
         NumberOfVerts=\"0\" NumberOfLines=\"{l}\" NumberOfStrips=\"0\" NumberOfPolys=\"{t}\">\n",
        events = codes(&event_names()),
        boundaries = codes(&boundary_names()),
        l = mesh.lines.len(),
        t = mesh.triangles.len(),
    )
}

/// The values at the mesh's vertices, then at each segment end those of its nearest vertex.
fn point_data(mesh: &FlatMesh, doc: &mut Document) {
    let nearest = nearest_vertices(mesh);
    let nan3 = [f64::NAN; 3];
    let point_values = |values: &[[f64; 3]]| -> Vec<f64> {
        let at_ends = nearest.iter().map(|v| v.map_or(&nan3, |v| &values[v]));
        values.iter().chain(at_ends).flatten().copied().collect()
    };
    for (name, values) in [
        ("radiosity", &mesh.radiosity),
        ("direct", &mesh.direct),
        ("indirect", &mesh.indirect),
    ] {
        doc.array("Float64", name, 3, &f64_bytes(&point_values(values)));
    }
    let luminance: Vec<f64> = point_values(&mesh.radiosity)
        .chunks(3)
        .map(|b| penumbra_viz::luminance(Rgb::new(b[0], b[1], b[2])))
        .collect();
    doc.array("Float64", "luminance", 1, &f64_bytes(&luminance));
}

/// The cells' data: lines first, then triangles.
fn cell_data(mesh: &FlatMesh, doc: &mut Document) {
    let lines = &mesh.lines;
    let surface: Vec<u8> = lines
        .iter()
        .map(|l| l.surface)
        .chain(mesh.triangle_surface.iter().copied())
        .flat_map(|s| i32::try_from(s).unwrap_or(-1).to_le_bytes())
        .collect();
    doc.array("Int32", "surface", 1, &surface);
    let codes = |code: fn(&super::Line) -> u8| -> Vec<u8> {
        let none = std::iter::repeat_n(-1_i8, mesh.triangles.len());
        // Codes are below 8: the cast to i8 is exact.
        let line_codes = lines.iter().map(|l| code(l) as i8);
        line_codes.chain(none).map(|c| c.to_le_bytes()[0]).collect()
    };
    doc.array("Int8", "event", 1, &codes(|l| l.event));
    doc.array("Int8", "boundary", 1, &codes(|l| l.boundary));
    doc.array("Int8", "order", 1, &codes(|l| l.order));
    if let Some(error) = &mesh.error {
        let values: Vec<f64> = std::iter::repeat_n(f64::NAN, lines.len())
            .chain(error.iter().copied())
            .collect();
        doc.array("Float64", "error_indicator", 1, &f64_bytes(&values));
    }
}

/// `0 EV, 1 VE, ...`
fn codes(names: &[&str]) -> String {
    let coded: Vec<String> = names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{i} {n}"))
        .collect();
    coded.join(", ")
}

/// The mesh vertex nearest each segment end (two per segment, in order), on the segment's
/// surface; `None` on a surface without vertices.
fn nearest_vertices(mesh: &FlatMesh) -> Vec<Option<usize>> {
    let mut nearest = Vec::with_capacity(2 * mesh.lines.len());
    let mut finder: Option<(u32, VertexFinder)> = None;
    for line in &mesh.lines {
        let s = line.surface;
        if finder.as_ref().is_none_or(|(on, _)| *on != s) {
            let range = mesh.vertex_offsets[s as usize]..mesh.vertex_offsets[s as usize + 1];
            finder = Some((s, VertexFinder::new(&mesh.positions, range)));
        }
        if let Some((_, find)) = &finder {
            nearest.extend(line.ends.map(|end| find.nearest(&mesh.positions, end)));
        }
    }
    nearest
}

/// The vertices of one surface, sorted by x, to find the one nearest a point.
struct VertexFinder {
    by_x: Vec<(f64, usize)>,
    near: f64,
}

impl VertexFinder {
    fn new(positions: &[[f64; 3]], range: std::ops::Range<usize>) -> VertexFinder {
        let mut by_x: Vec<(f64, usize)> = range.map(|i| (positions[i][0], i)).collect();
        by_x.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &(_, i) in &by_x {
            for c in 0..3 {
                lo[c] = lo[c].min(positions[i][c]);
                hi[c] = hi[c].max(positions[i][c]);
            }
        }
        let diagonal = (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt();
        VertexFinder {
            by_x,
            near: NEAR_END * diagonal,
        }
    }

    /// The vertex nearest `p` within [`NEAR_END`], the first in the mesh on a tie.
    fn nearest(&self, positions: &[[f64; 3]], p: [f64; 3]) -> Option<usize> {
        let distance = |i: usize| {
            (0..3)
                .map(|c| (positions[i][c] - p[c]).powi(2))
                .sum::<f64>()
        };
        let first = self.by_x.partition_point(|&(x, _)| x < p[0] - self.near);
        let last = self.by_x.partition_point(|&(x, _)| x <= p[0] + self.near);
        let near = self.by_x[first..last.max(first)]
            .iter()
            .map(|&(_, i)| (distance(i), i));
        let (d, i) = near.min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))?;
        (d <= self.near * self.near).then_some(i)
    }
}

/// The XML being written, and its appended data block: each array as its byte count (`u64`)
/// and its bytes.
struct Document {
    xml: String,
    data: Vec<u8>,
}

impl Document {
    /// Appends `raw` and declares it as a `DataArray`.
    fn array(&mut self, kind: &str, name: &str, components: u8, raw: &[u8]) {
        let _ = writeln!(
            self.xml,
            "<DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{components}\" \
             format=\"appended\" offset=\"{}\"/>",
            self.data.len()
        );
        self.data
            .extend_from_slice(&(raw.len() as u64).to_le_bytes());
        self.data.extend_from_slice(raw);
    }

    /// Cells of `size` points each, as VTK's connectivity and (end) offsets.
    fn cells(&mut self, points: &[i64], size: i64) {
        let offsets: Vec<i64> = (1..=points.len() as i64 / size).map(|i| size * i).collect();
        self.array("Int64", "connectivity", 1, &i64_bytes(points));
        self.array("Int64", "offsets", 1, &i64_bytes(&offsets));
    }
}

fn f64_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn i64_bytes(values: &[i64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}
