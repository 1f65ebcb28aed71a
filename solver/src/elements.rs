//! The discrete model the solvers work on: receivers (mesh vertices), elements (mesh triangles)
//! and patches (groups of neighbouring elements that shoot together, after Cohen et al. 1988).

use std::collections::{BTreeMap, HashMap, HashSet};

use glam::{DVec2, DVec3};
use penumbra_meshing::SceneMesh;
use penumbra_scenes::polygon::closest_point_on_segment;
use penumbra_scenes::{Bounds, Rgb, Scene, SurfaceId};

use crate::lambert::ReceivingPoint;

/// One mesh triangle.
#[derive(Clone, Debug)]
pub struct Element {
    /// The surface it is part of.
    pub surface: SurfaceId,
    /// Global receiver (vertex) indices.
    pub vertices: [usize; 3],
    /// Its corners.
    pub points: [DVec3; 3],
    /// Its area.
    pub area: f64,
    /// The patch it belongs to.
    pub patch: usize,
    /// Index of the triangle in its surface's mesh.
    pub triangle: usize,
}

/// Neighbouring elements of one surface that shoot their unshot power together.
#[derive(Clone, Debug)]
pub struct Patch {
    /// The surface it is part of.
    pub surface: SurfaceId,
    /// Its elements (indices into [`Discretization::elements`]).
    pub elements: Vec<usize>,
    /// Its area.
    pub area: f64,
    /// The unit normal of its surface.
    pub normal: DVec3,
    /// A point of the patch's plane.
    pub origin: DVec3,
    /// The distinct vertex positions, for culling.
    pub corners: Vec<DVec3>,
    /// The patch outline as directed edges, counter-clockwise about the normal: the contour of
    /// Lambert's formula (edges inside the patch cancel, so they are left out).
    pub outline: Vec<[DVec3; 2]>,
    /// Its bounding box.
    pub bounds: Bounds,
    /// The elements' corners, in the order of `elements`: the patch's geometry on its own, so
    /// that it can still be shot from (or gathered from) after the mesh has changed.
    pub triangles: Vec<[DVec3; 3]>,
    /// Cumulative element areas, for sampling points by area.
    pub cumulative_area: Vec<f64>,
}

/// Receivers, elements and patches of a meshed scene.
#[derive(Clone, Debug)]
pub struct Discretization {
    /// First global receiver index of each surface's mesh.
    pub offsets: Vec<usize>,
    /// Every mesh vertex, as a point receiving light.
    pub receivers: Vec<ReceivingPoint>,
    /// The surface of each receiver.
    pub receiver_surface: Vec<SurfaceId>,
    /// Every mesh triangle.
    pub elements: Vec<Element>,
    /// Groups of neighbouring elements that shoot together.
    pub patches: Vec<Patch>,
    /// The reflectance at each receiver (its surface's).
    pub reflectance: Vec<Rgb>,
    /// The emission at each receiver (its surface's).
    pub emission: Vec<Rgb>,
    /// The exact direct irradiance at each receiver, where the mesh measured it
    /// ([`SceneMesh::measured_direct`]).
    pub measured_direct: Vec<Option<Rgb>>,
}

impl Discretization {
    /// The receivers, elements and patches of `mesh`, with about `elements_per_patch`
    /// neighbouring elements of a surface in each patch.
    pub fn new(scene: &Scene, mesh: &SceneMesh, elements_per_patch: usize) -> Discretization {
        let mut offsets = Vec::with_capacity(mesh.surfaces.len());
        let mut receivers = Vec::new();
        let mut receiver_surface = Vec::new();
        let mut elements = Vec::new();
        let mut patches = Vec::new();
        let on_line = on_line_distance(scene);
        for m in &mesh.surfaces {
            let offset = receivers.len();
            offsets.push(offset);
            let normal = m.frame.normal;
            let lifts = hover_lifts(m, &mesh.hovering[m.surface], on_line);
            for ((p, inward), lift) in m.points3.iter().zip(m.interior_directions()).zip(lifts) {
                receivers.push(ReceivingPoint {
                    point: *p + inward * lift,
                    normal,
                    inward,
                });
                receiver_surface.push(m.surface);
            }
            // Patches: a grid over the surface in mesh coordinates, about `elements_per_patch`
            // triangles per cell; each triangle belongs to the cell of its centroid.
            let wanted = m
                .triangle_count()
                .div_ceil(elements_per_patch.max(1))
                .max(1);
            let (lo, hi) = m
                .local
                .iter()
                .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
                    (lo.min(p), hi.max(p))
                });
            let extent = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
            // About `wanted` cells, as square as the bounding box allows.
            let wanted_f = wanted as f64;
            let cells_x = (wanted_f * extent.x / extent.y)
                .sqrt()
                .round()
                .clamp(1.0, wanted_f);
            let cells_y = (wanted_f / cells_x).round().max(1.0);
            let cell = DVec2::new(extent.x / cells_x, extent.y / cells_y);
            let mut cells: BTreeMap<(i64, i64), Vec<usize>> = BTreeMap::new();
            for (t, tri) in m.triangles.iter().enumerate() {
                let c: DVec2 = tri.iter().map(|&i| m.local[i as usize]).sum::<DVec2>() / 3.0;
                let k = ((c - lo) / cell)
                    .floor()
                    .min(DVec2::new(cells_x - 1.0, cells_y - 1.0));
                cells.entry((k.x as i64, k.y as i64)).or_default().push(t);
            }
            // A cell's triangles that share no vertex path (the two sides of a contact line, whose
            // vertices are split) make separate patches: a patch shoots one radiosity, and the
            // dark floor under a block must not dilute the lit floor beside it.
            let pieces = cells
                .into_values()
                .flat_map(|triangles| connected_pieces(&triangles, m))
                .collect::<Vec<_>>();
            for triangles in pieces {
                let patch = patches.len();
                let first = elements.len();
                for &t in &triangles {
                    let tri = m.triangles[t];
                    elements.push(Element {
                        surface: m.surface,
                        vertices: tri.map(|i| offset + i as usize),
                        points: tri.map(|i| m.points3[i as usize]),
                        area: m.triangle_area(t),
                        patch,
                        triangle: t,
                    });
                }
                patches.push(make_patch(
                    m.surface,
                    normal,
                    &elements,
                    first..elements.len(),
                    &triangles,
                    m,
                ));
            }
        }
        let reflectance = receiver_surface
            .iter()
            .map(|&s| scene.surfaces[s].reflectance)
            .collect();
        let emission = receiver_surface
            .iter()
            .map(|&s| scene.surfaces[s].emission)
            .collect();
        let measured_direct = mesh
            .surfaces
            .iter()
            .flat_map(|m| {
                let known = mesh.measured_direct.get(m.surface);
                (0..m.vertex_count()).map(move |v| known.and_then(|k| k.get(v).copied().flatten()))
            })
            .collect();
        Discretization {
            offsets,
            receivers,
            receiver_surface,
            elements,
            patches,
            reflectance,
            emission,
            measured_direct,
        }
    }

    /// Receivers (mesh vertices) of every surface.
    pub fn receiver_count(&self) -> usize {
        self.receivers.len()
    }

    /// For each receiver, the receiver of `old` (a coarser discretization of the same scene)
    /// that stands for it, if any: the same point of the same surface. Where a position repeats
    /// (the sides of a contact line, the corners of a block standing on the surface) each copy's
    /// value is a one-sided limit from its own triangles, so a copy matches only an old one that
    /// looked from the same direction; elsewhere the light is continuous.
    pub fn matching_receivers(&self, old: &Discretization) -> Matching {
        let positions = |d: &Discretization| {
            let mut at: HashMap<(SurfaceId, [u64; 3]), Vec<usize>> = HashMap::new();
            for (v, x) in d.receivers.iter().enumerate() {
                at.entry((d.receiver_surface[v], x.point.to_array().map(f64::to_bits)))
                    .or_default()
                    .push(v);
            }
            at
        };
        let (old_at, new_at) = (positions(old), positions(self));
        let matching = (0..self.receiver_count())
            .map(|v| {
                let x = &self.receivers[v];
                let key = (
                    self.receiver_surface[v],
                    x.point.to_array().map(f64::to_bits),
                );
                let olds = old_at.get(&key).map_or(&[][..], Vec::as_slice);
                let unique = olds.len() == 1 && new_at.get(&key).is_some_and(|c| c.len() == 1);
                olds.iter()
                    .copied()
                    .find(|&o| unique || old.receivers[o].inward.dot(x.inward) >= 1.0 - 1e-9)
            })
            .collect();
        Matching(matching)
    }

    /// Splits a per-receiver vector into per-surface vectors.
    pub fn per_surface<T: Clone>(&self, values: &[T]) -> Vec<Vec<T>> {
        (0..self.offsets.len())
            .map(|s| {
                let end = self.offsets.get(s + 1).copied().unwrap_or(values.len());
                values[self.offsets[s]..end].to_vec()
            })
            .collect()
    }

    /// Patch-to-patch form factors from vertex-to-patch columns (per patch, the vertices that see
    /// it): F(p, q) is the area mean over patch p of the vertex form factors to q, linear over
    /// each element, the solvers' own quadrature. Dense, patches²: for small systems and checks.
    pub fn patch_factors(&self, columns: &[Vec<(u32, f32)>]) -> Vec<Vec<f64>> {
        let n = self.patches.len();
        let mut f = vec![vec![0.0; n]; n];
        for (q, column) in columns.iter().enumerate().take(n) {
            let mut dense = vec![0.0; self.receiver_count()];
            for &(v, value) in column {
                dense[v as usize] = value as f64;
            }
            for e in &self.elements {
                let mean = e.vertices.iter().map(|&v| dense[v]).sum::<f64>() / 3.0;
                f[e.patch][q] += e.area * mean / self.patches[e.patch].area;
            }
        }
        f
    }

    /// ∫ over each element of a linearly interpolated per-receiver quantity, summed: the power
    /// that quantity carries (for radiosity or irradiance values).
    pub fn integrate(&self, values: &[Rgb], weight: impl Fn(&Element) -> Rgb) -> Rgb {
        self.elements
            .iter()
            .map(|e| {
                let mean =
                    (values[e.vertices[0]] + values[e.vertices[1]] + values[e.vertices[2]]) / 3.0;
                mean.mul_rgb(weight(e)) * e.area
            })
            .sum()
    }
}

/// For each receiver of a discretization, the receiver of an older, coarser one that stands for
/// it, if any ([`Discretization::matching_receivers`]).
#[derive(Debug)]
pub struct Matching(Vec<Option<usize>>);

impl Matching {
    /// Per-receiver values of the older discretization carried over where receivers match (the
    /// default elsewhere).
    pub fn carry<T: Copy + Default>(&self, values: &[T]) -> Vec<T> {
        self.0
            .iter()
            .map(|m| m.map_or_else(T::default, |o| values[o]))
            .collect()
    }

    /// The receivers that match none.
    pub fn fresh(&self) -> Vec<usize> {
        (0..self.0.len()).filter(|&v| self.0[v].is_none()).collect()
    }
}

impl Discretization {
    /// ∫ f g over the mesh, with `values` (f) and `weights` (g) at the vertices, both linear
    /// over each triangle: A/12 (Σ fᵢ gᵢ + Σ fᵢ Σ gⱼ) per triangle, exact for the interpolants.
    pub fn integrate_product(&self, values: &[Rgb], weights: &[f64]) -> Rgb {
        self.elements
            .iter()
            .map(|e| {
                let [a, b, c] = e.vertices;
                let own = values[a] * weights[a] + values[b] * weights[b] + values[c] * weights[c];
                let all =
                    (values[a] + values[b] + values[c]) * (weights[a] + weights[b] + weights[c]);
                (own + all) * (e.area / 12.0)
            })
            .sum()
    }
}

/// How many gaps off a hovering face's contact line its vertices are evaluated: the face's blur
/// fades over a few gaps (to under 0.3 % of the light at 10 for light from all directions), so the
/// value there stands for the element, where the value right at the line would not.
pub(crate) const HOVER_LIFT: f64 = 10.0;

/// Points closer than this fraction of the scene's diagonal to a hovering face's contact line lie
/// on it.
const ON_LINE: f64 = 1e-9;

/// The distance within which a point of `scene` lies on a hovering face's contact line.
pub fn on_line_distance(scene: &Scene) -> f64 {
    ON_LINE * scene.diagonal()
}

/// How far a point `p` of a surface whose hovering faces cast `lines` (ends and gap) is to move
/// into the surface before it is evaluated: [`HOVER_LIFT`] times the largest gap of the lines it
/// lies on (within `on_line`, [`on_line_distance`]), or zero.
pub fn hover_lift(lines: &[(DVec3, DVec3, f64)], p: DVec3, on_line: f64) -> f64 {
    let gap = lines
        .iter()
        .filter(|&&(a, b, _)| p.distance(closest_point_on_segment(p, a, b)) <= on_line)
        .map(|l| l.2)
        .fold(0.0, f64::max);
    HOVER_LIFT * gap
}

/// Per vertex of `m`, how far to move it into its own triangles before evaluating it: its
/// [`hover_lift`], at most a quarter of its shortest edge.
pub fn hover_lifts(
    m: &penumbra_meshing::SurfaceMesh,
    lines: &[(DVec3, DVec3, f64)],
    on_line: f64,
) -> Vec<f64> {
    let mut lifts = vec![0.0; m.vertex_count()];
    if lines.is_empty() {
        return lifts;
    }
    let mut shortest = vec![f64::INFINITY; m.vertex_count()];
    for tri in &m.triangles {
        for k in 0..3 {
            let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
            let length = m.points3[a].distance(m.points3[b]);
            shortest[a] = shortest[a].min(length);
            shortest[b] = shortest[b].min(length);
        }
    }
    for (v, p) in m.points3.iter().enumerate() {
        let lift = hover_lift(lines, *p, on_line);
        if lift > 0.0 && shortest[v].is_finite() {
            lifts[v] = lift.min(0.25 * shortest[v]);
        }
    }
    lifts
}

/// Splits `triangles` (of mesh `m`) into groups connected through shared vertices, each in
/// ascending order, groups ordered by their first triangle.
fn connected_pieces(triangles: &[usize], m: &penumbra_meshing::SurfaceMesh) -> Vec<Vec<usize>> {
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut parent: Vec<usize> = (0..triangles.len()).collect();
    let mut owner: HashMap<u32, usize> = HashMap::new();
    for (k, &t) in triangles.iter().enumerate() {
        for &v in &m.triangles[t] {
            match owner.get(&v) {
                Some(&j) => {
                    let (a, b) = (root(&mut parent, k), root(&mut parent, j));
                    parent[a.max(b)] = a.min(b);
                }
                None => {
                    owner.insert(v, k);
                }
            }
        }
    }
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (k, &t) in triangles.iter().enumerate() {
        let r = root(&mut parent, k);
        groups.entry(r).or_default().push(t);
    }
    groups.into_values().collect()
}

fn make_patch(
    surface: SurfaceId,
    normal: DVec3,
    elements: &[Element],
    range: std::ops::Range<usize>,
    triangles: &[usize],
    mesh: &penumbra_meshing::SurfaceMesh,
) -> Patch {
    let mine = &elements[range.clone()];
    let directed: HashSet<(u32, u32)> = triangles
        .iter()
        .flat_map(|&t| {
            let [a, b, c] = mesh.triangles[t];
            [(a, b), (b, c), (c, a)]
        })
        .collect();
    let mut outline: Vec<(u32, u32)> = directed
        .iter()
        .copied()
        .filter(|&(a, b)| !directed.contains(&(b, a)))
        .collect();
    outline.sort_unstable();
    let mut corner_ids: Vec<u32> = triangles.iter().flat_map(|&t| mesh.triangles[t]).collect();
    corner_ids.sort_unstable();
    corner_ids.dedup();
    let corners: Vec<DVec3> = corner_ids
        .iter()
        .map(|&i| mesh.points3[i as usize])
        .collect();
    let mut cumulative_area = Vec::with_capacity(mine.len());
    let mut area = 0.0;
    for e in mine {
        area += e.area;
        cumulative_area.push(area);
    }
    Patch {
        surface,
        elements: range.collect(),
        area,
        normal,
        origin: corners[0],
        outline: outline
            .into_iter()
            .map(|(a, b)| [mesh.points3[a as usize], mesh.points3[b as usize]])
            .collect(),
        bounds: Bounds::from_points(&corners),
        corners,
        triangles: mine.iter().map(|e| e.points).collect(),
        cumulative_area,
    }
}
