//! The whole scene's mesh as one list of vertices and triangles, the form every export writes,
//! checked on the way: a `solution.json` read from disk may not fit together.

use crate::outputs::SurfaceSolution;

use super::ExportError;

/// The events and boundaries, in the order their codes number them in the exports.
pub const EVENTS: [&str; 6] = ["EV", "VE", "EEE", "contact", "blocker-EV", "horizon"];
/// The boundaries a line may be, in the order their codes number them.
pub const BOUNDARIES: [&str; 3] = ["umbra", "penumbra", "inner"];

/// The names of the discontinuity classes, by order: the derivative that jumps.
pub const CLASSES: [&str; 3] = ["D0", "D1", "D2"];

/// A discontinuity segment, its names coded as indices into [`EVENTS`] and [`BOUNDARIES`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// The segment's ends.
    pub ends: [[f64; 3]; 2],
    /// The surface it lies on.
    pub surface: u32,
    /// Its event, an index into [`EVENTS`].
    pub event: u8,
    /// Its boundary, an index into [`BOUNDARIES`].
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
        if flat.positions.len() > u32::MAX as usize {
            return Err(ExportError::TooLarge {
                format: "an export",
                reason: format!("{} vertices: at most 2^32 - 1", flat.positions.len()),
            });
        }
        Ok(flat)
    }

    fn push(&mut self, s: usize, surface: &SurfaceSolution) -> Result<(), ExportError> {
        let inconsistent = |reason: String| ExportError::Inconsistent {
            surface: surface.name.clone(),
            reason,
        };
        let missing = |field| ExportError::Missing {
            surface: surface.name.clone(),
            field,
        };
        let n = surface.vertices.len();
        let direct = surface.direct.as_ref().ok_or_else(|| missing("direct"))?;
        let emission = surface.emission.ok_or_else(|| missing("emission"))?;
        let reflectance = surface.reflectance.ok_or_else(|| missing("reflectance"))?;
        for (what, len) in [
            ("radiosity", surface.radiosity.len()),
            ("direct", direct.len()),
        ] {
            if len != n {
                return Err(inconsistent(format!(
                    "{len} {what} values for {n} vertices"
                )));
            }
        }
        if let Some(bad) = surface
            .triangles
            .iter()
            .flatten()
            .find(|&&i| i as usize >= n)
        {
            return Err(inconsistent(format!(
                "a triangle's vertex {bad} is not one of its {n} vertices"
            )));
        }
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
            let code = |names: &[&str], name: &str, what: &str| {
                let i = names.iter().position(|n| *n == name);
                i.map(|i| i as u8)
                    .ok_or_else(|| inconsistent(format!("a segment's {what} is {name:?}")))
            };
            if d.order > 2 {
                return Err(inconsistent(format!("a segment's order is {}", d.order)));
            }
            self.lines.push(Line {
                ends: [d.from, d.to],
                surface: id,
                event: code(&EVENTS, &d.event, "event")?,
                boundary: code(&BOUNDARIES, &d.boundary, "boundary")?,
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

    /// The reflectance of vertex `v`'s surface.
    pub fn reflectance_at(&self, v: usize) -> [f64; 3] {
        self.reflectance[self.vertex_surface[v] as usize]
    }

    /// The number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
}
