//! The whole scene's mesh as one list of vertices and triangles, the form every export writes,
//! checked on the way: a `solution.json` read from disk may not fit together.

use crate::outputs::SurfaceSolution;

use super::ExportError;

use penumbra_meshing::discontinuity::{Boundary, Event};

/// The events' names, in the order their codes number them in the exports.
pub fn event_names() -> [&'static str; 6] {
    Event::ALL.map(Event::name)
}

/// The boundaries' names, in the order their codes number them.
pub fn boundary_names() -> [&'static str; 3] {
    Boundary::ALL.map(Boundary::name)
}

/// The largest magnitude an exported number may have: the formats that hold `f32` (glTF, the
/// viewer page) hold nothing larger.
const LARGEST: f64 = f32::MAX as f64;

/// The names of the discontinuity classes, by order: the derivative that jumps.
pub const CLASSES: [&str; 3] = ["D0", "D1", "D2"];

/// A discontinuity segment, its names coded as indices into [`event_names`] and
/// [`boundary_names`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// The segment's ends.
    pub ends: [[f64; 3]; 2],
    /// The surface it lies on.
    pub surface: u32,
    /// Its event, an index into [`event_names`].
    pub event: u8,
    /// Its boundary, an index into [`boundary_names`].
    pub boundary: u8,
    /// The derivative that jumps across it: 0, 1 or 2.
    pub order: u8,
}

/// Every surface's mesh, joined: vertex indices are global, surfaces follow one another.
#[derive(Clone, Debug, Default)]
pub struct FlatMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Radiosity at each vertex, W/m².
    pub radiosity: Vec<[f64; 3]>,
    /// The direct light's part of it, ρ·H_direct.
    pub direct: Vec<[f64; 3]>,
    /// The rest of the reflected light: radiosity − emission − direct.
    pub indirect: Vec<[f64; 3]>,
    /// The surface of each vertex.
    pub vertex_surface: Vec<u32>,
    /// Each surface's reflectance ρ.
    pub reflectance: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
    /// The surface of each triangle.
    pub triangle_surface: Vec<u32>,
    /// Each triangle's error indicator, when every surface has one (adaptive runs).
    pub error: Option<Vec<f64>>,
    /// The first vertex and the first triangle of each surface, and one past the last.
    pub vertex_offsets: Vec<usize>,
    /// See `vertex_offsets`.
    pub triangle_offsets: Vec<usize>,
    /// Every discontinuity segment, surface by surface.
    pub lines: Vec<Line>,
}

impl FlatMesh {
    /// The surfaces joined, after checking that each one's parts fit together.
    pub fn of(surfaces: &[SurfaceSolution]) -> Result<FlatMesh, ExportError> {
        let mut flat = FlatMesh {
            vertex_offsets: vec![0],
            triangle_offsets: vec![0],
            error: Some(Vec::new()),
            ..FlatMesh::default()
        };
        for (s, surface) in surfaces.iter().enumerate() {
            flat.push(s, surface)?;
        }
        if flat.triangles.is_empty() {
            return Err(ExportError::Empty);
        }
        if flat.positions.len() > u32::MAX as usize {
            return Err(ExportError::TooLarge {
                format: "an export",
                reason: format!("{} vertices: at most 2^32 - 1", flat.positions.len()),
            });
        }
        Ok(flat)
    }

    fn push(&mut self, s: usize, surface: &SurfaceSolution) -> Result<(), ExportError> {
        let missing = |field| ExportError::Missing {
            surface: surface.name.clone(),
            field,
        };
        let direct = surface.direct.as_ref().ok_or_else(|| missing("direct"))?;
        let emission = surface.emission.ok_or_else(|| missing("emission"))?;
        let reflectance = surface.reflectance.ok_or_else(|| missing("reflectance"))?;
        check(surface, direct).map_err(|reason| ExportError::Inconsistent {
            surface: surface.name.clone(),
            reason,
        })?;
        let n = surface.vertices.len();
        let offset = self.positions.len() as u64;
        let shifted = |i: u32| u32::try_from(u64::from(i) + offset).unwrap_or(u32::MAX);
        let id = u32::try_from(s).unwrap_or(u32::MAX);
        self.positions.extend_from_slice(&surface.vertices);
        self.radiosity.extend_from_slice(&surface.radiosity);
        self.direct.extend_from_slice(direct);
        self.indirect.extend(
            surface
                .radiosity
                .iter()
                .zip(direct)
                .map(|(b, d)| [0, 1, 2].map(|c| b[c] - emission[c] - d[c])),
        );
        self.vertex_surface.extend(std::iter::repeat_n(id, n));
        self.reflectance.push(reflectance);
        self.triangles
            .extend(surface.triangles.iter().map(|t| t.map(shifted)));
        self.triangle_surface
            .extend(std::iter::repeat_n(id, surface.triangles.len()));
        self.push_error(surface)?;
        self.vertex_offsets.push(self.positions.len());
        self.triangle_offsets.push(self.triangles.len());
        for d in &surface.discontinuities {
            let code = |names: &[&str], name: &str| names.iter().position(|n| *n == name);
            // `check` found every name among them.
            let (event, boundary) = (
                code(&event_names(), &d.event),
                code(&boundary_names(), &d.boundary),
            );
            self.lines.push(Line {
                ends: [d.from, d.to],
                surface: id,
                event: event.unwrap_or_default() as u8,
                boundary: boundary.unwrap_or_default() as u8,
                order: d.order,
            });
        }
        Ok(())
    }

    /// The error indicator stays only while every surface has one.
    fn push_error(&mut self, surface: &SurfaceSolution) -> Result<(), ExportError> {
        match (&mut self.error, &surface.error_indicator) {
            (Some(all), Some(values)) if values.len() == surface.triangles.len() => {
                all.extend_from_slice(values);
            }
            (Some(_), Some(values)) => {
                return Err(ExportError::Inconsistent {
                    surface: surface.name.clone(),
                    reason: format!(
                        "{} error indicators for {} triangles",
                        values.len(),
                        surface.triangles.len()
                    ),
                });
            }
            _ => self.error = None,
        }
        Ok(())
    }

    /// The segments of each class present, with its name, in the order of [`CLASSES`].
    pub fn lines_by_class(&self) -> impl Iterator<Item = (&'static str, Vec<&Line>)> {
        CLASSES.iter().enumerate().filter_map(|(order, &class)| {
            let lines: Vec<&Line> = self
                .lines
                .iter()
                .filter(|l| usize::from(l.order) == order)
                .collect();
            (!lines.is_empty()).then_some((class, lines))
        })
    }

    /// The surfaces `surfaces` alone (indices into this mesh's, in the order given), their
    /// vertices and triangles numbered anew; without lines or error indicators.
    pub fn part(&self, surfaces: &[usize]) -> FlatMesh {
        let mut part = FlatMesh {
            vertex_offsets: vec![0],
            triangle_offsets: vec![0],
            ..FlatMesh::default()
        };
        for (k, &s) in surfaces.iter().enumerate() {
            let vertices = self.vertex_offsets[s]..self.vertex_offsets[s + 1];
            let triangles = self.triangle_offsets[s]..self.triangle_offsets[s + 1];
            // Vertex numbers fit in u32 here as they did in the whole.
            let shift = (part.positions.len() as u32).wrapping_sub(vertices.start as u32);
            let k = k as u32;
            part.positions
                .extend_from_slice(&self.positions[vertices.clone()]);
            part.radiosity
                .extend_from_slice(&self.radiosity[vertices.clone()]);
            part.direct
                .extend_from_slice(&self.direct[vertices.clone()]);
            part.indirect
                .extend_from_slice(&self.indirect[vertices.clone()]);
            part.vertex_surface
                .extend(std::iter::repeat_n(k, vertices.len()));
            part.reflectance.push(self.reflectance[s]);
            part.triangles.extend(
                self.triangles[triangles.clone()]
                    .iter()
                    .map(|t| t.map(|i| i.wrapping_add(shift))),
            );
            part.triangle_surface
                .extend(std::iter::repeat_n(k, triangles.len()));
            part.vertex_offsets.push(part.positions.len());
            part.triangle_offsets.push(part.triangles.len());
        }
        part
    }

    /// The reflectance of vertex `v`'s surface.
    pub fn reflectance_at(&self, v: usize) -> [f64; 3] {
        self.reflectance[self.vertex_surface[v] as usize]
    }
}

/// What does not fit together in one surface of a `solution.json`, if anything.
fn check(surface: &SurfaceSolution, direct: &[[f64; 3]]) -> Result<(), String> {
    let n = surface.vertices.len();
    for (what, len) in [
        ("radiosity", surface.radiosity.len()),
        ("direct", direct.len()),
    ] {
        if len != n {
            return Err(format!("{len} {what} values for {n} vertices"));
        }
    }
    if let Some(bad) = surface
        .triangles
        .iter()
        .flatten()
        .find(|&&i| i as usize >= n)
    {
        return Err(format!(
            "a triangle's vertex {bad} is not one of its {n} vertices"
        ));
    }
    for d in &surface.discontinuities {
        if !event_names().contains(&d.event.as_str()) {
            return Err(format!("a segment's event is {:?}", d.event));
        }
        if !boundary_names().contains(&d.boundary.as_str()) {
            return Err(format!("a segment's boundary is {:?}", d.boundary));
        }
        if d.order > 2 {
            return Err(format!("a segment's order is {}", d.order));
        }
    }
    check_magnitudes(surface, direct)
}

/// Every number of the surface within [`LARGEST`].
fn check_magnitudes(surface: &SurfaceSolution, direct: &[[f64; 3]]) -> Result<(), String> {
    let triples = [
        ("vertices", &surface.vertices[..]),
        ("radiosity", &surface.radiosity[..]),
        ("direct", direct),
    ];
    let ends: Vec<[f64; 3]> = surface
        .discontinuities
        .iter()
        .flat_map(|d| [d.from, d.to])
        .collect();
    let singles = [surface.emission, surface.reflectance]
        .into_iter()
        .flatten();
    let too_large = |v: &f64| !(v.abs() <= LARGEST);
    for (what, values) in triples.into_iter().chain([("discontinuities", &ends[..])]) {
        if values.iter().flatten().any(too_large) {
            return Err(format!("its {what} hold a number beyond ±{LARGEST:e}"));
        }
    }
    let errors = surface.error_indicator.iter().flatten();
    if singles
        .flatten()
        .chain(errors.copied())
        .any(|v| too_large(&v))
    {
        return Err(format!(
            "its emission, reflectance or error indicator is beyond ±{LARGEST:e}"
        ));
    }
    Ok(())
}
