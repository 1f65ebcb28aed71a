//! Quality measures of meshes: the smallest angle, the smallest angle not forced by the input's
//! own narrow wedges, and the distribution of aspect ratios.

use serde::Serialize;

use crate::mesh::SurfaceMesh;
use crate::tolerances::FORCING_WEDGE_DEG;

/// Mesh quality figures: the smallest angle and the distribution of aspect ratios
/// (circumradius over twice the inradius: 1 for an equilateral triangle).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct MeshQuality {
    /// Triangles measured.
    pub triangles: usize,
    /// The smallest angle of any triangle, in degrees.
    pub min_angle_deg: f64,
    /// The smallest angle not forced by the input: two input edges (polygon edges and
    /// constraints) meeting at less than [`FORCING_WEDGE_DEG`] force the corners between them
    /// at their meeting point, and those meeting at less than 60 degrees the triangles between
    /// them, which refinement lays out in shells around the meeting point (Ruppert 1995;
    /// Shewchuk 2000).
    pub min_angle_unforced_deg: f64,
    /// Triangles with an angle under [`FORCING_WEDGE_DEG`] that the input does not force: none
    /// when the budget holds each surface's least mesh at that angle.
    pub triangles_below_min_angle: usize,
    /// The median aspect ratio.
    pub aspect_ratio_median: f64,
    /// The 95th percentile of the aspect ratios.
    pub aspect_ratio_p95: f64,
    /// The largest aspect ratio: infinite where a triangle has no area (written `null`, as JSON
    /// has no infinity, and read back so).
    #[serde(deserialize_with = "infinite_if_null")]
    pub aspect_ratio_max: f64,
}

/// A number, or `null` for the infinity it was written from.
fn infinite_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let value: Option<f64> = serde::Deserialize::deserialize(d)?;
    Ok(value.unwrap_or(f64::INFINITY))
}

impl SurfaceMesh {
    /// The mesh's quality figures.
    pub fn quality(&self) -> MeshQuality {
        quality_of(std::iter::once(self))
    }
}

/// Quality figures over several meshes together.
pub fn quality_of<'a>(meshes: impl IntoIterator<Item = &'a SurfaceMesh>) -> MeshQuality {
    let mut min_angle = f64::INFINITY;
    let mut min_unforced = f64::INFINITY;
    let mut triangles_below = 0;
    let mut ratios = Vec::new();
    for m in meshes {
        let wedges = crate::wedges::InputWedges::of(m);
        for tri in &m.triangles {
            let mut below = false;
            for k in 0..3 {
                let v = m.local[tri[k] as usize];
                let (a, b) = (
                    m.local[tri[(k + 1) % 3] as usize],
                    m.local[tri[(k + 2) % 3] as usize],
                );
                let corner = (a - v)
                    .normalize()
                    .dot((b - v).normalize())
                    .clamp(-1.0, 1.0);
                if !wedges.forces(&m.local, *tri, k, FORCING_WEDGE_DEG.to_radians()) {
                    let angle = corner.acos().to_degrees();
                    min_unforced = min_unforced.min(angle);
                    below |= angle < FORCING_WEDGE_DEG;
                }
            }
            triangles_below += usize::from(below);
            let [a, b, c] = tri.map(|i| m.local[i as usize]);
            let (la, lb, lc) = ((b - c).length(), (c - a).length(), (a - b).length());
            let angle = |opp: f64, s1: f64, s2: f64| {
                ((s1 * s1 + s2 * s2 - opp * opp) / (2.0 * s1 * s2))
                    .clamp(-1.0, 1.0)
                    .acos()
            };
            let smallest = angle(la, lb, lc)
                .min(angle(lb, lc, la))
                .min(angle(lc, la, lb));
            min_angle = min_angle.min(smallest.to_degrees());
            let area = 0.5 * (b - a).perp_dot(c - a);
            let s = 0.5 * (la + lb + lc);
            let (inradius, circumradius) = (area / s, la * lb * lc / (4.0 * area));
            ratios.push(circumradius / (2.0 * inradius));
        }
    }
    if ratios.is_empty() {
        return MeshQuality::default();
    }
    ratios.sort_by(f64::total_cmp);
    let at = |q: f64| ratios[((ratios.len() - 1) as f64 * q).round() as usize];
    MeshQuality {
        triangles: ratios.len(),
        min_angle_deg: min_angle,
        min_angle_unforced_deg: min_unforced,
        triangles_below_min_angle: triangles_below,
        aspect_ratio_median: at(0.5),
        aspect_ratio_p95: at(0.95),
        aspect_ratio_max: at(1.0),
    }
}
