//! Tessellated solids: the same solid as a few polygons or as thousands of small triangles.
//!
//! Real scenes hold meshes exported from modelling tools, where a flat wall is hundreds of
//! triangles and a statue tens of thousands. Subdividing a solid's faces keeps its shape exactly,
//! so the light it lets through must not change: these scenes test that, and measure what the
//! tessellation costs.
//!
//! Subdivision points on an edge are computed from the edge's ends in a fixed order, so the
//! faces on both sides of an edge share their corners bit for bit, as the faces of a welded mesh
//! exported to OBJ do.

use glam::{DAffine3, DVec2, DVec3};

use crate::color::Rgb;
use crate::model::{Scene, Surface};
use crate::polygon::triangulate_ccw;

/// Most subdivisions per face edge a `tessellated-N` name may ask for (20 N² faces).
pub const MAX_SUBDIVISIONS: usize = 100;

/// The point `k / n` of the way along edge `p-q`, the same bits whichever way it is walked.
fn edge_point(p: DVec3, q: DVec3, k: usize, n: usize) -> DVec3 {
    if k == 0 {
        return p;
    }
    if k == n {
        return q;
    }
    let key = |v: DVec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
    if key(p) <= key(q) {
        p + (q - p) * (k as f64 / n as f64)
    } else {
        q + (p - q) * ((n - k) as f64 / n as f64)
    }
}

/// Triangle `[a, b, c]` split into `n²` triangles of the same orientation.
pub fn subdivide_triangle([a, b, c]: [DVec3; 3], n: usize) -> Vec<[DVec3; 3]> {
    let n = n.max(1);
    // Point (i, j): i steps from a towards b, j from a towards c.
    let point = |i: usize, j: usize| {
        if j == 0 {
            edge_point(a, b, i, n)
        } else if i == 0 {
            edge_point(a, c, j, n)
        } else if i + j == n {
            edge_point(b, c, j, n)
        } else {
            a + (b - a) * (i as f64 / n as f64) + (c - a) * (j as f64 / n as f64)
        }
    };
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n - i {
            out.push([point(i, j), point(i + 1, j), point(i, j + 1)]);
            if i + j + 2 <= n {
                out.push([point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)]);
            }
        }
    }
    out
}

/// A planar polygon (convex or not, counter-clockwise in `frame` coordinates given by `flat`)
/// as triangles, each split into `n²`.
fn subdivide_polygon(polygon: &[DVec3], flat: &[DVec2], n: usize) -> Vec<[DVec3; 3]> {
    triangulate_ccw(flat)
        .into_iter()
        .flat_map(|[i, j, k]| subdivide_triangle([polygon[i], polygon[j], polygon[k]], n))
        .collect()
}

/// The faces of an L-shaped prism (a statue-like solid: not convex, so it shades itself), outward
/// and counter-clockwise seen from outside: two L-shaped caps and six sides.
pub fn l_prism(place: &DAffine3) -> Vec<Vec<DVec3>> {
    let outline = [
        DVec2::new(0.0, 0.0),
        DVec2::new(1.2, 0.0),
        DVec2::new(1.2, 0.5),
        DVec2::new(0.5, 0.5),
        DVec2::new(0.5, 1.0),
        DVec2::new(0.0, 1.0),
    ];
    let at = |p: DVec2, z: f64| place.transform_point3(DVec3::new(p.x - 0.6, p.y - 0.5, z));
    let (bottom, top) = (-0.3, 0.3);
    let mut faces = vec![
        outline.iter().map(|&p| at(p, top)).collect(),
        outline.iter().rev().map(|&p| at(p, bottom)).collect(),
    ];
    for i in 0..outline.len() {
        let (p, q) = (outline[i], outline[(i + 1) % outline.len()]);
        faces.push(vec![at(p, bottom), at(q, bottom), at(q, top), at(p, top)]);
    }
    faces
}

/// The L prism's faces, each split into triangles `n` to an edge: `20 n²` faces in all.
pub fn tessellated_l_prism(place: &DAffine3, n: usize) -> Vec<Vec<DVec3>> {
    l_prism(place)
        .into_iter()
        .flat_map(|face| {
            let frame = crate::frame::PlaneFrame::of_polygon(&face);
            let flat: Vec<DVec2> = match frame {
                Some(f) => face.iter().map(|&p| f.to_2d(p)).collect(),
                None => Vec::new(),
            };
            subdivide_polygon(&face, &flat, n)
        })
        .map(|t| t.to_vec())
        .collect()
}

/// Where the L prism hangs in the `tessellated` scenes: turned against the light's edges and
/// tilted, clear of the floor.
fn prism_placement() -> DAffine3 {
    DAffine3::from_translation(DVec3::new(0.1, -0.05, 1.2))
        * DAffine3::from_rotation_z(0.35)
        * DAffine3::from_rotation_x(0.2)
}

/// A square light over a floor, and between them the L prism as `20 n²` triangles (`n = 0`:
/// as its eight polygons). The shadow is the same for every `n`.
pub fn tessellated(n: usize) -> Scene {
    let grey = Rgb::splat(0.6);
    let mut surfaces = vec![
        Surface::new(
            "light",
            vec![
                DVec3::new(-0.5, -0.5, 3.0),
                DVec3::new(-0.5, 0.5, 3.0),
                DVec3::new(0.5, 0.5, 3.0),
                DVec3::new(0.5, -0.5, 3.0),
            ],
            Rgb::ZERO,
        )
        .with_emission(Rgb::splat(10.0)),
        Surface::new(
            "floor",
            vec![
                DVec3::new(-3.0, -3.0, 0.0),
                DVec3::new(3.0, -3.0, 0.0),
                DVec3::new(3.0, 3.0, 0.0),
                DVec3::new(-3.0, 3.0, 0.0),
            ],
            grey,
        ),
    ];
    let place = prism_placement();
    let faces = if n == 0 {
        l_prism(&place)
    } else {
        tessellated_l_prism(&place, n)
    };
    surfaces.extend(
        faces
            .into_iter()
            .enumerate()
            .map(|(i, f)| Surface::new(format!("prism/{i}"), f, grey)),
    );
    Scene {
        up: None,
        unit: None,
        name: format!("tessellated-{n}"),
        camera: None,
        surfaces,
    }
}

/// A sphere's tessellation as a geodesic (icosahedral) mesh: an icosahedron's faces split
/// `levels` times into four, every corner on the sphere of `radius` about `center`
/// (20·4^levels triangles: 1,280 at 3). Welded and turned outwards: a closed solid.
pub fn icosphere(center: DVec3, radius: f64, levels: usize) -> Vec<[DVec3; 3]> {
    unit_icosphere(levels)
        .into_iter()
        .map(|t| t.map(|d| center + d * radius))
        .collect()
}

/// A statue-like blob: [`icosphere`]'s corners pushed out from the centre by a smooth bumpy
/// function of their direction (folds, dents and overhangs that shade the blob itself),
/// centred at `center` with mean radius `radius`. Welded and turned outwards.
pub fn bumpy_blob(center: DVec3, radius: f64, levels: usize) -> Vec<[DVec3; 3]> {
    let bump = |d: DVec3| {
        1.0 + 0.25 * (3.0 * d.x + 1.0).sin() * (2.0 * d.y).cos()
            + 0.15 * (5.0 * d.z + 2.0 * d.x).sin()
    };
    unit_icosphere(levels)
        .into_iter()
        .map(|t| t.map(|d| center + d * (radius * bump(d))))
        .collect()
}

/// A torus about the vertical axis through `center`: the tube of radius `minor` around the
/// circle of radius `major`, as `around` × `across` quads split into triangles. Welded and
/// turned outwards.
pub fn torus(
    center: DVec3,
    major: f64,
    minor: f64,
    around: usize,
    across: usize,
) -> Vec<[DVec3; 3]> {
    let (around, across) = (around.max(3), across.max(3));
    let point = |i: usize, j: usize| {
        let u = std::f64::consts::TAU * (i % around) as f64 / around as f64;
        let v = std::f64::consts::TAU * (j % across) as f64 / across as f64;
        let ring = major + minor * v.cos();
        center + DVec3::new(ring * u.cos(), ring * u.sin(), minor * v.sin())
    };
    (0..around)
        .flat_map(|i| (0..across).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            [[a, b, c], [a, c, d]]
        })
        .collect()
}

/// [`icosphere`] of the unit sphere about the origin.
fn unit_icosphere(levels: usize) -> Vec<[DVec3; 3]> {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let v = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .map(|(x, y, z)| DVec3::new(x, y, z).normalize());
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut triangles: Vec<[DVec3; 3]> = faces.iter().map(|f| f.map(|i| v[i])).collect();
    for _ in 0..levels {
        // Midpoints on the unit sphere: a + b has the same bits either way round.
        let mid = |a: DVec3, b: DVec3| (a + b).normalize();
        triangles = triangles
            .into_iter()
            .flat_map(|[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn key(p: DVec3) -> [u64; 3] {
        [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
    }

    #[test]
    fn subdivided_faces_are_welded_and_keep_their_area() {
        let place = prism_placement();
        let whole: f64 = l_prism(&place)
            .iter()
            .map(|f| 0.5 * crate::polygon::newell_normal(f).length())
            .sum();
        for n in [1, 2, 5] {
            let faces = tessellated_l_prism(&place, n);
            assert_eq!(faces.len(), 20 * n * n);
            let area: f64 = faces
                .iter()
                .map(|f| 0.5 * crate::polygon::newell_normal(f).length())
                .sum();
            assert!((area - whole).abs() < 1e-12 * whole, "{area} vs {whole}");
            // Every directed edge has exactly one reverse: a closed, consistently oriented mesh.
            let mut edges: HashMap<([u64; 3], [u64; 3]), usize> = HashMap::new();
            for f in &faces {
                for i in 0..3 {
                    *edges.entry((key(f[i]), key(f[(i + 1) % 3]))).or_default() += 1;
                }
            }
            for (&(a, b), &count) in &edges {
                assert_eq!(count, 1);
                assert_eq!(
                    edges.get(&(b, a)),
                    Some(&1),
                    "edge without its twin at n = {n}"
                );
            }
        }
    }

    /// The blob, the sphere and the torus are closed, welded, turned outwards, and hold about
    /// the volume of what they tessellate.
    #[test]
    fn the_solids_are_closed_and_welded() {
        let sphere = std::f64::consts::PI * 4.0 / 3.0;
        let torus_volume = 2.0 * std::f64::consts::PI.powi(2) * 0.25 * 0.25;
        for (faces, count, (lo, hi)) in [
            (bumpy_blob(DVec3::ZERO, 1.0, 2), 320, (2.0, 8.0)),
            (
                icosphere(DVec3::ZERO, 1.0, 3),
                1280,
                (0.99 * sphere, sphere),
            ),
            (
                torus(DVec3::ZERO, 1.0, 0.25, 48, 16),
                2 * 48 * 16,
                (0.95 * torus_volume, torus_volume),
            ),
        ] {
            assert_closed(&faces, count, lo, hi);
        }
    }

    fn assert_closed(faces: &[[DVec3; 3]], count: usize, lo: f64, hi: f64) {
        assert_eq!(faces.len(), count);
        let mut edges: HashMap<([u64; 3], [u64; 3]), usize> = HashMap::new();
        let mut volume = 0.0;
        for f in faces {
            for i in 0..3 {
                *edges.entry((key(f[i]), key(f[(i + 1) % 3]))).or_default() += 1;
            }
            volume += f[0].dot(f[1].cross(f[2])) / 6.0;
        }
        for (&(a, b), &count) in &edges {
            assert_eq!((count, edges.get(&(b, a))), (1, Some(&1)));
        }
        // Turned outwards: a positive volume, near the solid's.
        assert!(volume > lo && volume < hi, "{volume} not in {lo}..{hi}");
    }

    #[test]
    fn the_scenes_are_valid() {
        for n in [0, 1, 3] {
            let scene = tessellated(n);
            assert!(crate::validate(&scene).is_empty(), "tessellated-{n}");
        }
    }
}
