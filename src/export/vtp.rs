//! `solution.vtp`: VTK XML PolyData, which ParaView and VTK read.
//!
//! The triangles are polygons and the discontinuity segments lines. Point data: `radiosity`,
//! `direct` and `indirect` (RGB, W/m²) and `luminance` (of the radiosity, Rec. 709). Cell data,
//! lines first as VTK orders cells: `surface` (the index in `solution.json`), `event`,
//! `boundary` and `order` (codes, -1 on triangles) and, for adaptive runs, `error_indicator`
//! (NaN on lines). A segment's ends are points of their own, where `solution.json` puts them,
//! after the mesh's vertices; their point data are those of the mesh vertex nearest each (the
//! vertex the end was built into, moved by no more than the mesh's welding of close ends).
//! Arrays are appended raw, little endian, in `f64` and `i64`.

use std::fmt::Write as _;

use penumbra_scenes::Rgb;

use super::mesh::{BOUNDARIES, EVENTS, FlatMesh};

/// How far from a segment's end the search for its nearest mesh vertex looks first, relative
/// to the diagonal of its surface's vertices' bounding box; beyond that it looks everywhere.
const NEAR_END: f64 = 1e-6;

/// The file's bytes.
pub fn vtp(mesh: &FlatMesh) -> Vec<u8> {
    let nearest = nearest_vertices(mesh);
    let ends: Vec<[f64; 3]> = mesh.lines.iter().flat_map(|l| l.ends).collect();
    let n = mesh.positions.len() + ends.len();
    let mut data = Appended::default();
    let mut xml = String::new();
    let nan3 = [f64::NAN; 3];
    let point_values = |values: &[[f64; 3]]| -> Vec<f64> {
        let at_ends = nearest.iter().map(|v| v.map_or(&nan3, |v| &values[v]));
        values.iter().chain(at_ends).flatten().copied().collect()
    };
    let _ = write!(
        xml,
        "<?xml version=\"1.0\"?>\n\
         <!-- penumbra solution. Cell codes: event {events}; boundary {boundaries}; order 0 \
         value, 1 slope, 2 curvature jumps; -1 on triangles. -->\n\
         <VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">\n<PolyData>\n<Piece NumberOfPoints=\"{n}\" \
         NumberOfVerts=\"0\" NumberOfLines=\"{l}\" NumberOfStrips=\"0\" NumberOfPolys=\"{t}\">\n\
         <PointData Scalars=\"luminance\">\n",
        events = codes(&EVENTS),
        boundaries = codes(&BOUNDARIES),
        l = mesh.lines.len(),
        t = mesh.triangles.len(),
    );
    for (name, values) in [
        ("radiosity", &mesh.radiosity),
        ("direct", &mesh.direct),
        ("indirect", &mesh.indirect),
    ] {
        data.array(
            &mut xml,
            "Float64",
            name,
            3,
            &f64_bytes(&point_values(values)),
        );
    }
    let luminance: Vec<f64> = point_values(&mesh.radiosity)
        .chunks(3)
        .map(|b| penumbra_viz::luminance(Rgb::new(b[0], b[1], b[2])))
        .collect();
    data.array(&mut xml, "Float64", "luminance", 1, &f64_bytes(&luminance));
    xml += "</PointData>\n<CellData Scalars=\"surface\">\n";
    cell_data(mesh, &mut xml, &mut data);
    xml += "</CellData>\n<Points>\n";
    let points: Vec<f64> = mesh
        .positions
        .iter()
        .chain(&ends)
        .flatten()
        .copied()
        .collect();
    data.array(&mut xml, "Float64", "Points", 3, &f64_bytes(&points));
    xml += "</Points>\n<Lines>\n";
    let first = mesh.positions.len() as i64;
    let line_points: Vec<i64> = (first..first + ends.len() as i64).collect();
    let line_offsets: Vec<i64> = (1..=mesh.lines.len() as i64).map(|i| 2 * i).collect();
    data.array(
        &mut xml,
        "Int64",
        "connectivity",
        1,
        &i64_bytes(&line_points),
    );
    data.array(&mut xml, "Int64", "offsets", 1, &i64_bytes(&line_offsets));
    xml += "</Lines>\n<Polys>\n";
    let corners: Vec<i64> = mesh
        .triangles
        .iter()
        .flatten()
        .map(|&i| i64::from(i))
        .collect();
    let poly_offsets: Vec<i64> = (1..=mesh.triangles.len() as i64).map(|i| 3 * i).collect();
    data.array(&mut xml, "Int64", "connectivity", 1, &i64_bytes(&corners));
    data.array(&mut xml, "Int64", "offsets", 1, &i64_bytes(&poly_offsets));
    xml += "</Polys>\n</Piece>\n</PolyData>\n<AppendedData encoding=\"raw\">\n_";
    let mut bytes = xml.into_bytes();
    bytes.extend_from_slice(&data.bytes);
    bytes.extend_from_slice(b"\n</AppendedData>\n</VTKFile>\n");
    bytes
}

/// The cells' data: lines first, then triangles.
fn cell_data(mesh: &FlatMesh, xml: &mut String, data: &mut Appended) {
    let lines = &mesh.lines;
    let surface: Vec<u8> = lines
        .iter()
        .map(|l| l.surface)
        .chain(mesh.triangle_surface.iter().copied())
        .flat_map(|s| i32::try_from(s).unwrap_or(-1).to_le_bytes())
        .collect();
    data.array(xml, "Int32", "surface", 1, &surface);
    let codes = |code: fn(&super::Line) -> u8| -> Vec<u8> {
        let none = std::iter::repeat_n(-1_i8, mesh.triangles.len());
        // Codes are below 8: the cast to i8 is exact.
        let line_codes = lines.iter().map(|l| code(l) as i8);
        line_codes.chain(none).map(|c| c.to_le_bytes()[0]).collect()
    };
    data.array(xml, "Int8", "event", 1, &codes(|l| l.event));
    data.array(xml, "Int8", "boundary", 1, &codes(|l| l.boundary));
    data.array(xml, "Int8", "order", 1, &codes(|l| l.order));
    if let Some(error) = &mesh.error {
        let values: Vec<f64> = std::iter::repeat_n(f64::NAN, lines.len())
            .chain(error.iter().copied())
            .collect();
        data.array(xml, "Float64", "error_indicator", 1, &f64_bytes(&values));
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

    /// The vertex nearest `p`, the first in the mesh on a tie: among those within
    /// [`NEAR_END`] in x if any is that near, else among all.
    fn nearest(&self, positions: &[[f64; 3]], p: [f64; 3]) -> Option<usize> {
        let distance = |i: usize| {
            (0..3)
                .map(|c| (positions[i][c] - p[c]).powi(2))
                .sum::<f64>()
        };
        let best = |candidates: &[(f64, usize)]| {
            let near = candidates.iter().map(|&(_, i)| (distance(i), i));
            near.min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        };
        let first = self.by_x.partition_point(|&(x, _)| x < p[0] - self.near);
        let last = self.by_x.partition_point(|&(x, _)| x <= p[0] + self.near);
        match best(&self.by_x[first..last.max(first)]) {
            Some((d, i)) if d <= self.near * self.near => Some(i),
            _ => best(&self.by_x).map(|(_, i)| i),
        }
    }
}

/// The appended data block: each array as its byte count (`u64`) and its bytes.
#[derive(Default)]
struct Appended {
    bytes: Vec<u8>,
}

impl Appended {
    /// Appends `raw` and declares it in `xml` as a `DataArray`.
    fn array(&mut self, xml: &mut String, kind: &str, name: &str, components: u8, raw: &[u8]) {
        let _ = writeln!(
            xml,
            "<DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{components}\" \
             format=\"appended\" offset=\"{}\"/>",
            self.bytes.len()
        );
        self.bytes
            .extend_from_slice(&(raw.len() as u64).to_le_bytes());
        self.bytes.extend_from_slice(raw);
    }
}

fn f64_bytes(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn i64_bytes(values: &[i64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}
