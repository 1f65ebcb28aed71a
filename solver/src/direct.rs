//! Exact direct light from polygonal emitters.
//!
//! At a receiving point x, each emitter's visible part is found by backprojection: every occluder
//! that can block x from the emitter is clipped to the shaft between x and the emitter (the
//! pyramid with apex x over the emitter), projected from x onto the emitter's plane, and
//! subtracted from the emitter polygon. What remains is a set of convex polygons, and Lambert's
//! formula on them is the exact (unsampled) form factor to the visible part:
//!
//! H(x) = Σ_e E_e F(x → visible part of e),  B_direct(x) = ρ(x) H(x).
//!
//! This is the reference every approximation in penumbra is measured against.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use penumbra_scenes::polygon::{
    self, closest_point_on_segment, is_convex_ccw, signed_area_2d, triangulate_ccw,
};
use penumbra_scenes::{PlaneFrame, Rgb, Scene, SurfaceId, Visibility};
use smallvec::SmallVec;

use crate::clip::{
    HalfPlane, clip_half_plane, clip_polygon_3d, convex_hull_2d, inside_convex,
    merge_close_vertices, subtract_convex, subtract_half_planes, wider_than,
};
use crate::lambert::{ReceivingPoint, contour_sum};
use crate::occluder_tree::{OccluderTree, Reached, ShaftTest, TreeFace};
use crate::shadow_union::{
    CornerKey, OverlayLimit, Refusal, ShadowUnion, VisibleShape, visible_points,
};
use crate::solids::closed_solid_orientation;

/// Visible pieces narrower than this many units in the last place of the coordinates involved
/// are slivers left by rounding where two shadows share an edge; they are dropped.
const SLIVER_ULPS: f64 = 64.0;
/// Projected occluder vertices closer than this fraction of the emitter's diameter are merged.
const MERGE_FRACTION: f64 = 1e-12;
/// Up to this many occluders in a shaft are subtracted from the emitter one by one, as convex
/// polygons; more are subtracted at once by one polygon difference (Clipper2 on an integer
/// grid), whose cost grows with their outline rather than with the product of their counts. The
/// default of [`DirectLight::with_sequential_shadows`].
pub const SEQUENTIAL_SHADOWS: usize = 16;
/// Occluder faces whose corners are all at least this fraction of x's height from x (towards
/// the emitter) project within this many times the shaft's width, and go whole into the union.
const PROJECTION_REACH: f64 = 16.0;
/// A shaft holding more faces than this is narrowed first ([`DirectLight::window`]): a light seen
/// past a building has most of the building in its shaft, and most of it behind a few large faces.
const WINDOW_FACES: usize = 4096;

/// The faces and outline sheets subtracted first to narrow a shaft: the ones filling the largest
/// solid angles. (All the sheets in a shaft, fused and subtracted twice, cost more than the
/// narrowing saved: 1,500 of Sponza's vertices took 1.6 times as long as with none.)
const WINDOW_SHADOWS: usize = 64;

/// A shaft is narrowed only when what the largest faces leave has a hull smaller than this share
/// of the piece: else the second walk costs more than it saves.
const WINDOW_SHRINK: f64 = 0.75;

/// A node of the occluder tree stands for its faces by its outline only when each face turns
/// towards (or away from) x by more than this many contact distances: never a face through x.
const OUTLINE_MARGIN: f64 = 2.0;

/// A planar convex polygon of a surface, with its plane.
#[derive(Clone, Debug)]
struct ConvexPiece {
    surface: SurfaceId,
    polygon: Vec<DVec3>,
    normal: DVec3,
    /// The corners' welded ids: the same for every face with a corner at the same point.
    keys: Vec<CornerKey>,
    /// The outward normal, for a face of a closed solid.
    outward: Option<DVec3>,
    /// Area and centroid, to rank faces by the solid angle they fill.
    area: f64,
    centroid: DVec3,
}

impl ConvexPiece {
    /// Whether the piece's plane passes within `tol` of `point`.
    fn holds(&self, point: DVec3, tol: f64) -> bool {
        self.normal.dot(point - self.polygon[0]).abs() <= tol
    }

    fn new(
        surface: SurfaceId,
        polygon: Vec<DVec3>,
        normal: DVec3,
        outward: Option<f64>,
        corners: &mut CornerIds,
    ) -> Self {
        ConvexPiece {
            surface,
            keys: polygon.iter().map(|&p| corners.id(p)).collect(),
            outward: outward.map(|sign| normal * sign),
            area: 0.5 * polygon::newell_normal(&polygon).length(),
            centroid: polygon.iter().copied().sum::<DVec3>() / polygon.len().max(1) as f64,
            polygon,
            normal,
        }
    }
}

/// Welded ids of points, by their exact coordinates.
#[derive(Default)]
struct CornerIds(std::collections::HashMap<[u64; 3], CornerKey>);

impl CornerIds {
    fn id(&mut self, p: DVec3) -> CornerKey {
        let next = self.0.len() as CornerKey;
        *self
            .0
            .entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .or_insert(next)
    }
}

/// What one occluder hides of an emitter piece, seen from a point.
enum Blocking<'a> {
    /// The occluder's plane holds the point (occluder index): what it hides depends on the side
    /// the receiving surface lies on ([`contact_shadow`]).
    Touching(usize),
    /// A face of one of a group's own surfaces whose plane misses the point (occluder index):
    /// it shadows the group's other receivers only ([`Viewer::Group`]).
    Own(usize),
    /// A touching occluder's hidden regions, for one receiver: intersections of half-planes.
    Contact(Vec<Vec<HalfPlane>>),
    /// The occluder clipped to the shaft and projected onto the emitter's plane; with the
    /// corners' keys when the whole occluder lies inside the shaft. Most are triangles, held
    /// inline: a shaft through a building holds tens of thousands.
    Shadow {
        corners: FaceCorners,
        keys: Option<&'a [CornerKey]>,
    },
    /// The faces of a sheet of the occluder tree (a node, or a plane of one), projected whole:
    /// their outline's edges (corner keys and the projection of the first), all turned one way.
    Outline {
        sheet: usize,
        edges: Vec<(CornerKey, CornerKey, DVec2)>,
    },
}

/// A projected face's corners.
type FaceCorners = SmallVec<[DVec2; 4]>;

#[derive(Clone, Debug)]
struct Emitter {
    surface: SurfaceId,
    emission: Rgb,
    frame: PlaneFrame,
    /// The emitter as convex pieces (itself, if convex).
    pieces: Vec<Vec<DVec3>>,
    /// Largest coordinate magnitude of the emitter, for the rounding scale.
    magnitude: f64,
    /// Shadow vertices closer than this (on the emitter's plane) are one vertex.
    merge_distance: f64,
}

impl Emitter {
    /// The lowest and highest of the points' heights above the emitter's plane.
    fn height_range(&self, points: &[DVec3]) -> (f64, f64) {
        points
            .iter()
            .map(|&p| self.frame.height(p))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), h| {
                (lo.min(h), hi.max(h))
            })
    }

    /// Visible pieces and shadows no wider than this, seen from `point`, are slivers of rounding:
    /// coordinates as large as the emitter's and the point's carry this error.
    fn sliver_width(&self, point: DVec3) -> f64 {
        SLIVER_ULPS * f64::EPSILON * self.magnitude.max(point.abs().max_element())
    }
}

/// Splits a surface polygon into convex pieces: itself when convex, else its triangles.
fn convex_pieces(polygon: &[DVec3]) -> Vec<Vec<DVec3>> {
    let Some(frame) = PlaneFrame::of_polygon(polygon) else {
        return Vec::new();
    };
    let flat: Vec<DVec2> = polygon.iter().map(|&p| frame.to_2d(p)).collect();
    if is_convex_ccw(&flat) {
        return vec![polygon.to_vec()];
    }
    triangulate_ccw(&flat)
        .into_iter()
        .map(|t| t.iter().map(|&i| polygon[i]).collect())
        .collect()
}

/// The exact direct-light evaluator of a scene.
pub struct DirectLight<'a> {
    /// For estimates by rays ([`Self::irradiance_sampled`]).
    visibility: &'a Visibility,
    emitters: Vec<Emitter>,
    occluders: Vec<ConvexPiece>,
    /// The occluders' bounding-volume tree, for the shafts.
    tree: OccluderTree,
    tol: f64,
    /// Occluders per shaft up to which shadows are subtracted one by one.
    sequential_shadows: usize,
    /// Faces per shaft beyond which the largest are subtracted first, to narrow the shaft.
    window_faces: usize,
    /// How far one polygon difference may go ([`Self::with_overlay_cap`],
    /// [`Self::with_deadline`]).
    overlay_limit: OverlayLimit,
}

/// The visible part of a light needs a larger polygon difference than the evaluator allows.
#[derive(Clone, Copy, Debug)]
struct TooComplex;

/// Whose point a shaft starts from.
#[derive(Clone, Copy, Debug)]
enum Viewer<'s> {
    /// One receiver's: its own surface casts no shadow on it.
    Receiver(SurfaceId),
    /// A group of receivers', on these surfaces (sorted): every one of them passes through the
    /// point, whether or not its plane does within the contact distance (a polygon is planar
    /// only to the validation's tolerance, and its mesh lies in the plane through one of its
    /// corners). What one of them hides depends on the receiver ([`PieceView`]).
    Group(&'s [SurfaceId]),
}

impl Viewer<'_> {
    /// Whether faces of `surface` are no occluders at all.
    fn ignores(self, surface: SurfaceId) -> bool {
        matches!(self, Viewer::Receiver(r) if r == surface)
    }

    /// Whether `surface` is one of a group's own.
    fn owns(self, surface: SurfaceId) -> bool {
        matches!(self, Viewer::Group(surfaces) if surfaces.binary_search(&surface).is_ok())
    }
}

impl std::fmt::Debug for DirectLight<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DirectLight")
            .field("emitters", &self.emitters.len())
            .field("occluders", &self.occluders.len())
            .finish()
    }
}

impl<'a> DirectLight<'a> {
    /// The evaluator of `scene`'s emitters, with `visibility` the scene's index.
    pub fn new(scene: &Scene, visibility: &'a Visibility) -> DirectLight<'a> {
        let emitters = scene
            .emitters()
            .filter_map(|(surface, s)| {
                Some(Emitter {
                    surface,
                    emission: s.emission,
                    frame: PlaneFrame::of_polygon(&s.polygon)?,
                    pieces: convex_pieces(&s.polygon),
                    magnitude: s
                        .polygon
                        .iter()
                        .map(|p| p.abs().max_element())
                        .fold(0.0, f64::max),
                    merge_distance: MERGE_FRACTION * polygon::diameter(&s.polygon),
                })
            })
            .collect();

        // Occluders are whole convex surfaces where possible (fewer, larger pieces fragment the
        // visible region less), else the visibility index's own triangles. A whole surface must
        // be flat to the contact distance, since its plane decides which points lie on it
        // (`ConvexPiece::holds`): a polygon planar only to the validation's tolerance (an OBJ
        // corner rounded to six decimals) has corners that far off the plane through its first
        // corner, as are its neighbours' vertices along their junctions with it, while its
        // triangles pass through its corners.
        let tol = visibility.contact_distance();
        let orientation = closed_solid_orientation(scene, visibility);
        let mut corners = CornerIds::default();
        let mut occluders = Vec::new();
        let mut whole: Vec<Option<usize>> = vec![None; scene.surfaces.len()];
        for (surface, s) in scene.surfaces.iter().enumerate() {
            let pieces = convex_pieces(&s.polygon);
            let normal = s.normal();
            let flat = s
                .polygon
                .iter()
                .all(|&p| normal.dot(p - s.polygon[0]).abs() <= tol);
            if pieces.len() == 1 && flat {
                whole[surface] = Some(occluders.len());
                occluders.push(ConvexPiece::new(
                    surface,
                    s.polygon.clone(),
                    s.normal(),
                    orientation[surface],
                    &mut corners,
                ));
            }
        }
        for t in visibility.triangles() {
            if whole[t.surface].is_none() {
                occluders.push(ConvexPiece::new(
                    t.surface,
                    t.vertices.to_vec(),
                    (t.vertices[1] - t.vertices[0])
                        .cross(t.vertices[2] - t.vertices[0])
                        .normalize_or_zero(),
                    orientation[t.surface],
                    &mut corners,
                ));
            }
        }
        let mut tree = OccluderTree::build(
            &occluders
                .iter()
                .map(|o| TreeFace {
                    polygon: &o.polygon,
                    keys: &o.keys,
                    facing: o.outward.unwrap_or(o.normal).normalize_or_zero(),
                    closed: o.outward.is_some(),
                })
                .collect::<Vec<_>>(),
        );
        // Stored in the tree's order, each copied afresh: a shaft's thousands of candidates are
        // then read nearly in memory order (scattered, they cost a cache miss each).
        let mut occluders: Vec<ConvexPiece> = (tree.renumber_in_order().into_iter())
            .map(|old| occluders[old].clone())
            .collect();
        // Their corners numbered in that order too: fusing a shaft's faces into outlines then
        // reads per-corner tables nearly in order.
        let mut renumbered = vec![CornerKey::MAX; corners.0.len()];
        let mut next = 0;
        for key in occluders.iter_mut().flat_map(|o| o.keys.iter_mut()) {
            let new = &mut renumbered[*key as usize];
            if *new == CornerKey::MAX {
                *new = next;
                next += 1;
            }
            *key = *new;
        }
        tree.renumber_keys(&renumbered);
        DirectLight {
            visibility,
            emitters,
            occluders,
            tree,
            tol,
            sequential_shadows: SEQUENTIAL_SHADOWS,
            window_faces: WINDOW_FACES,
            overlay_limit: OverlayLimit::NONE,
        }
    }

    /// The same evaluator, giving up (NaN) where the visible part of a light would need a
    /// polygon difference of more than `edges` edges at once: a large light seen through a
    /// lattice of thin occluders can need millions, and as much memory.
    pub fn with_overlay_cap(self, edges: usize) -> Self {
        DirectLight {
            overlay_limit: OverlayLimit {
                edges,
                ..self.overlay_limit
            },
            ..self
        }
    }

    /// The same evaluator, giving up (NaN) on a point whose polygon difference is still going
    /// at `deadline` (it works in batches, and checks between them).
    pub fn with_deadline(self, deadline: Option<std::time::Instant>) -> Self {
        DirectLight {
            overlay_limit: OverlayLimit {
                deadline,
                ..self.overlay_limit
            },
            ..self
        }
    }

    /// The same evaluator, subtracting up to `count` shadows one by one (and more at once): the
    /// two ways agree to rounding, which tests check.
    pub fn with_sequential_shadows(self, count: usize) -> Self {
        DirectLight {
            sequential_shadows: count,
            ..self
        }
    }

    /// The same evaluator, narrowing only shafts that hold more than `faces` faces (4,096 by
    /// default; `usize::MAX` never narrows): the two agree to rounding.
    pub fn with_window_faces(self, faces: usize) -> Self {
        DirectLight {
            window_faces: faces,
            ..self
        }
    }

    /// The diagonal of the scene's bounding box.
    pub fn scene_diagonal(&self) -> f64 {
        self.tol / penumbra_scenes::CONTACT_TOLERANCE
    }

    /// The emitters evaluated; `k` in the per-emitter methods counts them in scene order.
    pub fn emitter_count(&self) -> usize {
        self.emitters.len()
    }

    /// Irradiance H(x) = Σ_e E_e F(x → visible part of e) at a point of surface `receiver`.
    pub fn irradiance(&self, x: &ReceivingPoint, receiver: SurfaceId) -> Rgb {
        (0..self.emitters.len())
            .map(|k| self.emitters[k].emission * self.form_factor_visible(x, receiver, k))
            .sum()
    }

    /// The irradiance at receivers that share the point `at` (the faces of a mesh meeting at a
    /// vertex, each at its own rounding of `at`), each as [`Self::irradiance`] gives it to
    /// rounding. What the occluders other than the faces through `at` and the receivers' own
    /// surfaces hide of each light is found once for all of them; each receiver then keeps the
    /// part in front of it and loses what the faces through the point hide on its side, and
    /// what the other receivers' surfaces hide of it. A receiver's value depends on `at` and
    /// itself, not on the others.
    pub fn irradiance_group(&self, at: DVec3, group: &[(ReceivingPoint, SurfaceId)]) -> Vec<Rgb> {
        let mut out = vec![Rgb::ZERO; group.len()];
        if group.is_empty() {
            return out;
        }
        let mut surfaces: SmallVec<[SurfaceId; 8]> = group.iter().map(|&(_, r)| r).collect();
        surfaces.sort_unstable();
        surfaces.dedup();
        for (k, e) in self.emitters.iter().enumerate() {
            let shared = self.shared_view(at, &surfaces, e);
            for ((x, r), h) in group.iter().zip(&mut out) {
                let sees =
                    *r != e.surface && x.in_front_of(e.frame.origin, e.frame.normal, self.tol);
                let f = match &shared {
                    Ok(Some(view)) if sees => self.form_factor_of_view(view, x, *r, e),
                    Err(TooComplex) if sees => f64::NAN,
                    _ => self.form_factor_visible(x, *r, k),
                };
                *h += e.emission * f;
            }
        }
        out
    }

    /// What the occluders not through `point` leave visible of each piece of emitter `e`, when
    /// enough of them are in the way to be subtracted at once (else `None`: each receiver is
    /// evaluated on its own, one shadow at a time). `surfaces` are the receivers' own, sorted:
    /// they pass through the point.
    fn shared_view(
        &self,
        point: DVec3,
        surfaces: &[SurfaceId],
        e: &Emitter,
    ) -> Result<Option<Vec<PieceView>>, TooComplex> {
        let h_x = e.frame.height(point);
        if h_x <= self.tol {
            return Ok(None);
        }
        let min_width = e.sliver_width(point);
        let mut views = Vec::with_capacity(e.pieces.len());
        for full in &e.pieces {
            let mut piece: Vec<DVec2> = full.iter().map(|&p| e.frame.to_2d(p)).collect();
            if signed_area_2d(&piece) < 0.0 {
                piece.reverse();
            }
            let Some(Blocked { blockings, start }) =
                self.blockings(point, Viewer::Group(surfaces), e, full, h_x, &piece, true)
            else {
                views.push(PieceView {
                    piece,
                    visible: Vec::new(),
                    touching: Vec::new(),
                    own: Vec::new(),
                });
                continue;
            };
            if start.is_none()
                && blockings.len() <= self.sequential_shadows
                && !blockings
                    .iter()
                    .any(|b| matches!(b, Blocking::Outline { .. }))
            {
                return Ok(None);
            }
            let (mut touching, mut own) = (Vec::new(), Vec::new());
            for b in &blockings {
                match *b {
                    Blocking::Touching(index) => touching.push(index),
                    Blocking::Own(index) => own.push(index),
                    _ => {}
                }
            }
            let visible = match subtract_at_once(
                &piece,
                start,
                &blockings,
                e,
                min_width,
                &self.overlay_limit,
            ) {
                Ok(visible) => visible,
                Err(Refusal::NotFinite | Refusal::Inconsistent) => return Ok(None),
                Err(Refusal::TooComplex) => return Err(TooComplex),
            };
            views.push(PieceView {
                piece,
                visible,
                touching,
                own,
            });
        }
        Ok(Some(views))
    }

    /// The form factor from receiver x (at the shared view's point) to what it sees of `e`.
    fn form_factor_of_view(
        &self,
        views: &[PieceView],
        x: &ReceivingPoint,
        receiver: SurfaceId,
        e: &Emitter,
    ) -> f64 {
        let tol = self.tol;
        // Points of the emitter's plane in front of x: n . (p - x) >= 0.
        let n = x.normal;
        let front = HalfPlane {
            normal: DVec2::new(n.dot(e.frame.u), n.dot(e.frame.v)),
            offset: n.dot(e.frame.origin - x.point),
        };
        let signed_sum = |contours: &[Vec<DVec2>]| -> f64 {
            let contours: Vec<Vec<DVec3>> = contours
                .iter()
                .map(|c| c.iter().map(|&q| e.frame.to_3d(q)).collect())
                .collect();
            signed_sum(x, &contours, e.frame.normal, tol)
        };
        let mut total = 0.0;
        for view in views {
            // What the faces through x hide on the receiver's side, and the shadows of the other
            // receivers' faces whose planes miss x, as the receiver on its own sees them.
            let others = |list: &'_ [usize]| {
                list.iter()
                    .map(|&index| &self.occluders[index])
                    .filter(|occ| occ.surface != receiver)
                    .collect::<Vec<_>>()
            };
            let mut hidden: Vec<Vec<DVec2>> = others(&view.touching)
                .into_iter()
                .flat_map(|occ| contact_shadow(x, occ, e, tol))
                .map(|region| {
                    region
                        .iter()
                        .fold(view.piece.clone(), |part, h| clip_half_plane(&part, h))
                })
                .filter(|part| part.len() >= 3)
                .collect();
            hidden.extend(
                others(&view.own)
                    .into_iter()
                    .flat_map(|occ| self.own_shadow(x, occ, e, &view.piece))
                    .filter(|part| part.len() >= 3),
            );
            let seen: Vec<Vec<DVec2>> = if hidden.is_empty() {
                view.visible
                    .iter()
                    .flatten()
                    .map(|c| clip_half_plane(c, &front))
                    .filter(|c| c.len() >= 3)
                    .collect()
            } else {
                // One difference, as for a receiver on its own: the hidden parts overlap each
                // other and the part behind the receiver.
                let mut union = ShadowUnion::default();
                let behind = HalfPlane {
                    normal: -front.normal,
                    offset: -front.offset,
                };
                for part in hidden
                    .into_iter()
                    .chain(std::iter::once(clip_half_plane(&view.piece, &behind)))
                {
                    if part.len() >= 3 {
                        union.add_contour(part);
                    }
                }
                match union.subtract_within(view.visible.clone(), &view.piece, &self.overlay_limit)
                {
                    Ok(shapes) => shapes.into_iter().flatten().collect(),
                    Err(_) => return f64::NAN,
                }
            };
            if !seen.is_empty() {
                total += signed_sum(&seen).max(0.0);
            }
        }
        total / (2.0 * PI)
    }

    /// An estimate of [`Self::irradiance`] for when the exact value cannot wait: each emitter's
    /// form factor (exact, unoccluded) times the share of it visible along about `rays` rays to
    /// stratified points, weighted by the point-to-point kernel.
    pub fn irradiance_sampled(&self, x: &ReceivingPoint, receiver: SurfaceId, rays: usize) -> Rgb {
        let tol = self.tol;
        let origin = x.point + x.inward * self.visibility.junction_offset();
        let mut total = Rgb::ZERO;
        for e in &self.emitters {
            if e.surface == receiver || !x.in_front_of(e.frame.origin, e.frame.normal, tol) {
                continue;
            }
            let fronts: Vec<Vec<DVec3>> = e
                .pieces
                .iter()
                .map(|piece| clip_polygon_3d(piece, |p| x.height(p, tol)))
                .filter(|front| front.len() >= 3)
                .collect();
            let unoccluded: f64 = fronts
                .iter()
                .map(|f| contour_sum(x, f, tol).abs())
                .sum::<f64>()
                / (2.0 * PI);
            let (mut seen, mut all) = (0.0, 0.0);
            let triangles = fronts.iter().map(|f| f.len() - 2).sum::<usize>();
            for (q, weight) in stratified_points(&fronts, rays.div_ceil(triangles.max(1))) {
                let d = q - x.point;
                let kernel = weight * x.normal.dot(d).max(0.0) * e.frame.normal.dot(-d).max(0.0)
                    / d.length_squared().powi(2);
                all += kernel;
                if !self.visibility.occluded(origin, q, [receiver, e.surface]) {
                    seen += kernel;
                }
            }
            if all > 0.0 {
                total += e.emission * (unoccluded * seen / all);
            }
        }
        total
    }

    /// The surface id of emitter `k`.
    pub fn emitter_surface(&self, k: usize) -> SurfaceId {
        self.emitters[k].surface
    }

    /// The form factor from x to the part of emitter `k` that x sees (NaN where that part is
    /// beyond the evaluator's overlay cap, [`Self::with_overlay_cap`]).
    pub fn form_factor_visible(&self, x: &ReceivingPoint, receiver: SurfaceId, k: usize) -> f64 {
        let tol = self.tol;
        let Ok(parts) = self.visible_parts_within_cap(x, receiver, k) else {
            return f64::NAN;
        };
        let normal = self.emitters[k].frame.normal;
        signed_sum(x, parts.iter().flatten(), normal, tol).max(0.0) / (2.0 * PI)
    }

    /// The part of emitter `k` visible from x, in 3D on the emitter's plane: shapes, each an
    /// outline followed by its holes (convex outlines without holes where few occluders are in
    /// the way); empty where that part is beyond the evaluator's overlay cap. A contour turning
    /// clockwise about the emitter's normal removes its inside: where the overlay leaves a
    /// degenerate part, it may come as an outline and a reversed copy of it, on its own.
    pub fn visible_parts(
        &self,
        x: &ReceivingPoint,
        receiver: SurfaceId,
        k: usize,
    ) -> Vec<Vec<Vec<DVec3>>> {
        self.visible_parts_within_cap(x, receiver, k)
            .unwrap_or_default()
    }

    fn visible_parts_within_cap(
        &self,
        x: &ReceivingPoint,
        receiver: SurfaceId,
        k: usize,
    ) -> Result<Vec<Vec<Vec<DVec3>>>, TooComplex> {
        let e = &self.emitters[k];
        let tol = self.tol;
        if e.surface == receiver || !x.in_front_of(e.frame.origin, e.frame.normal, tol) {
            return Ok(Vec::new());
        }
        let h_x = e.frame.height(x.point);
        let mut out = Vec::new();
        for piece in &e.pieces {
            // Only the part of the emitter above x's tangent plane is seen at all.
            let front = clip_polygon_3d(piece, |p| x.height(p, tol));
            if front.len() < 3 {
                continue;
            }
            if h_x <= tol {
                // x lies in the emitter's plane (a surface meeting the emitter): the shaft is flat,
                // and the one-sided limit sees the emitter unoccluded.
                out.push(vec![front]);
                continue;
            }
            let visible = self.unblocked(x, receiver, e, &front, h_x, true)?;
            out.extend(visible.into_iter().map(|shape| {
                shape
                    .into_iter()
                    .map(|c| c.into_iter().map(|p| e.frame.to_3d(p)).collect::<Vec<_>>())
                    .collect::<Vec<_>>()
            }));
        }
        Ok(out)
    }

    /// `front` (a convex piece of the emitter, in front of x) minus the projections of the
    /// occluders in the shaft, in the emitter's 2D frame; narrowing the shaft where it is full
    /// (`narrow`, [`Self::blockings`]).
    fn unblocked(
        &self,
        x: &ReceivingPoint,
        receiver: SurfaceId,
        e: &Emitter,
        front: &[DVec3],
        h_x: f64,
        narrow: bool,
    ) -> Result<Vec<VisibleShape>, TooComplex> {
        // The rounding scale of this evaluation: coordinates as large as these carry this error.
        let min_width = e.sliver_width(x.point);
        let mut piece = front.iter().map(|&p| e.frame.to_2d(p)).collect::<Vec<_>>();
        if signed_area_2d(&piece) < 0.0 {
            piece.reverse();
        }
        let Some(Blocked {
            mut blockings,
            start,
        }) = self.blockings(
            x.point,
            Viewer::Receiver(receiver),
            e,
            front,
            h_x,
            &piece,
            narrow,
        )
        else {
            return Ok(Vec::new());
        };
        let narrowed = start.is_some();
        for b in &mut blockings {
            if let Blocking::Touching(index) = *b {
                *b = Blocking::Contact(contact_shadow(x, &self.occluders[index], e, self.tol));
            }
        }
        let at_once = narrowed
            || blockings.len() > self.sequential_shadows
            || blockings
                .iter()
                .any(|b| matches!(b, Blocking::Outline { .. }));
        if at_once {
            match subtract_at_once(&piece, start, &blockings, e, min_width, &self.overlay_limit) {
                Ok(visible) => return Ok(visible),
                Err(Refusal::TooComplex) => return Err(TooComplex),
                // The narrowed shaft's blockings alone do not cover the rest of the piece.
                Err(Refusal::NotFinite | Refusal::Inconsistent) if narrowed => {
                    return self.unblocked(x, receiver, e, front, h_x, false);
                }
                Err(Refusal::NotFinite | Refusal::Inconsistent) => {}
            }
        }
        let blockings = self.faces_of_outlines(blockings, x.point, e, h_x);
        Ok(subtract_one_by_one(piece, blockings, e, min_width)
            .into_iter()
            .map(|p| vec![p])
            .collect())
    }

    /// What each occluder in the shaft from x to `front` hides of it, or `None` when they hide
    /// all of it. With `narrow` and many faces in the shaft, the faces filling the largest solid
    /// angles are subtracted first and the shaft narrows to the hull of what they leave
    /// ([`Blocked::start`]).
    #[allow(clippy::too_many_arguments)]
    fn blockings(
        &self,
        point: DVec3,
        viewer: Viewer,
        e: &Emitter,
        front: &[DVec3],
        h_x: f64,
        piece: &[DVec2],
        narrow: bool,
    ) -> Option<Blocked<'_>> {
        let tol = self.tol;
        let min_width = e.sliver_width(point);
        let mut sides = shaft_sides(point, front);
        // Faces wholly between the two planes and not too close to x are projected whole.
        let reach = h_x * (1.0 - 1.0 / PROJECTION_REACH);
        let project = |p: DVec3| project_onto(e, point, h_x, p);
        let (mut candidates, mut outlines) = self.reached(point, viewer, e, &sides, reach);
        let mut start = None;
        if narrow && candidates.len() > self.window_faces {
            match self.window(point, viewer, e, h_x, reach, piece, &candidates, &outlines) {
                Window::Covered => return None,
                Window::Narrowed { visible, hull } => {
                    let corners: Vec<DVec3> = hull.iter().map(|&q| e.frame.to_3d(q)).collect();
                    sides = shaft_sides(point, &corners);
                    (candidates, outlines) = self.reached(point, viewer, e, &sides, reach);
                    start = Some((visible, hull));
                }
                Window::Wide => {}
            }
        }
        let at_once =
            start.is_some() || !outlines.is_empty() || candidates.len() > self.sequential_shadows;

        let mut blockings = Vec::with_capacity(candidates.len() + outlines.len());
        for (sheet, reversed) in outlines {
            let edges = self.outline_edges(sheet, reversed, project);
            blockings.push(Blocking::Outline { sheet, edges });
        }
        for index in candidates {
            let occ = &self.occluders[index];
            // A plane through x is seen edge-on: it hides nothing, unless x lies on the occluder
            // itself (a blocker standing on the receiver); then the limit from inside the
            // receiving surface sees it hide everything across its plane, within its corner.
            if occ.holds(point, tol) {
                blockings.push(Blocking::Touching(index));
                continue;
            }
            if viewer.owns(occ.surface) {
                blockings.push(Blocking::Own(index));
                continue;
            }
            let Some((corners, whole)) =
                self.shadow(occ, point, e, h_x, &sides, at_once.then_some(reach))
            else {
                continue;
            };
            // Only a shadow whose box holds the piece's can cover it; most are far smaller.
            if box_holds(&corners, piece)
                && tidy_shadow(&corners, e, min_width).is_some_and(|shadow| covers(&shadow, piece))
            {
                return None;
            }
            blockings.push(Blocking::Shadow {
                corners,
                keys: whole.then_some(&occ.keys[..]),
            });
        }
        Some(Blocked { blockings, start })
    }

    /// The shadow of `occ` from `point` (at height `h_x` above the emitter's plane) in the shaft
    /// with these `sides`, projected onto the emitter's plane, and whether the face went whole
    /// (keeping its own corners: faces between the two planes within `reach` of the emitter,
    /// when given, and faces wholly inside the shaft); `None` when it casts none there.
    fn shadow(
        &self,
        occ: &ConvexPiece,
        point: DVec3,
        e: &Emitter,
        h_x: f64,
        sides: &[DVec3],
        reach: Option<f64>,
    ) -> Option<(FaceCorners, bool)> {
        // Wholly outside one side of the shaft, or beyond the emitter's plane: no shadow.
        let (lowest, highest) = e.height_range(&occ.polygon);
        if highest < 0.0
            || sides
                .iter()
                .any(|m| occ.polygon.iter().all(|&p| m.dot(p - point) < 0.0))
        {
            return None;
        }
        let inside = lowest >= 0.0
            && occ
                .polygon
                .iter()
                .all(|&p| sides.iter().all(|m| m.dot(p - point) >= 0.0));
        // Shadows subtracted at once may reach past the piece: a face between the two planes
        // and not too close to x is projected whole, keeping its own corners.
        let whole = inside || reach.is_some_and(|reach| lowest >= 0.0 && highest <= reach);
        let poly = if whole {
            std::borrow::Cow::Borrowed(&occ.polygon)
        } else {
            let mut poly = clip_polygon_3d(&occ.polygon, |p| e.frame.height(p));
            for &m in sides {
                if poly.len() < 3 {
                    break;
                }
                poly = clip_polygon_3d(&poly, |p| m.dot(p - point));
            }
            std::borrow::Cow::Owned(poly)
        };
        if poly.len() < 3 {
            return None;
        }
        let corners = poly
            .iter()
            .map(|&p| project_onto(e, point, h_x, p))
            .collect();
        Some((corners, whole))
    }

    /// What a face of another receiver's surface, whose plane misses the shared point, hides of
    /// `piece` (in the emitter's 2D frame) from x: as for x on its own ([`Self::blockings`]),
    /// what it hides on x's side where its plane holds x, else its shadow.
    fn own_shadow(
        &self,
        x: &ReceivingPoint,
        occ: &ConvexPiece,
        e: &Emitter,
        piece: &[DVec2],
    ) -> Vec<Vec<DVec2>> {
        let h_x = e.frame.height(x.point);
        if occ.holds(x.point, self.tol) {
            return contact_shadow(x, occ, e, self.tol)
                .iter()
                .map(|region| {
                    region
                        .iter()
                        .fold(piece.to_vec(), |part, h| clip_half_plane(&part, h))
                })
                .collect();
        }
        if h_x <= self.tol {
            return Vec::new();
        }
        let corners: Vec<DVec3> = piece.iter().map(|&q| e.frame.to_3d(q)).collect();
        let sides = shaft_sides(x.point, &corners);
        self.shadow(occ, x.point, e, h_x, &sides, None)
            .and_then(|(corners, _)| tidy_shadow(&corners, e, e.sliver_width(x.point)))
            .into_iter()
            .collect()
    }

    /// A sheet's outline, turned as its faces face x, with each edge's first corner projected.
    fn outline_edges(
        &self,
        sheet: usize,
        reversed: bool,
        project: impl Fn(DVec3) -> DVec2,
    ) -> Vec<(CornerKey, CornerKey, DVec2)> {
        let edges = self.tree.outline(sheet).iter();
        if reversed {
            edges.map(|e| (e.to, e.from, project(e.to_at))).collect()
        } else {
            edges.map(|e| (e.from, e.to, project(e.from_at))).collect()
        }
    }

    /// The faces (in the tree's order) and outline sheets of the occluder tree in the shaft with
    /// these sides, less the receiver's own faces, the emitter's, and faces of closed solids
    /// turned away.
    fn reached(
        &self,
        point: DVec3,
        viewer: Viewer,
        e: &Emitter,
        sides: &[DVec3],
        reach: f64,
    ) -> (Vec<usize>, Vec<(usize, bool)>) {
        let tol = self.tol;
        let mut candidates = Vec::new();
        let mut outlines = Vec::new();
        self.tree.walk(
            &ShaftTest {
                point,
                sides,
                emitter_origin: e.frame.origin,
                emitter_normal: e.frame.normal,
                lowest: tol,
                highest: reach,
                margin: OUTLINE_MARGIN * tol,
            },
            &mut |reached| match reached {
                Reached::Face(index) => candidates.push(index),
                Reached::Outline { sheet, reversed } => outlines.push((sheet, reversed)),
            },
        );
        candidates.retain(|&index| {
            let occ = &self.occluders[index];
            // A face of a closed solid turned away from x is behind another face of it.
            !viewer.ignores(occ.surface)
                && occ.surface != e.surface
                && !occ
                    .outward
                    .is_some_and(|n| n.dot(point - occ.polygon[0]) < -tol)
        });
        (candidates, outlines)
    }

    /// What the faces and outline sheets filling the largest solid angles from x
    /// ([`WINDOW_SHADOWS`]) leave visible of `piece`, when its hull is much smaller than the
    /// piece: no other face matters outside that hull.
    #[allow(clippy::too_many_arguments)]
    fn window(
        &self,
        point: DVec3,
        viewer: Viewer,
        e: &Emitter,
        h_x: f64,
        reach: f64,
        piece: &[DVec2],
        candidates: &[usize],
        outlines: &[(usize, bool)],
    ) -> Window {
        let solid_angle = |index: usize| {
            let occ = &self.occluders[index];
            let d = occ.centroid - point;
            let r2 = d.length_squared();
            occ.area * occ.normal.dot(d).abs() / (r2 * r2.sqrt())
        };
        let faces = candidates
            .iter()
            .map(|&i| (solid_angle(i), Narrowing::Face(i)));
        let sheets = outlines.iter().map(|&(sheet, reversed)| {
            let angle = self.tree.solid_angle(sheet, point);
            (angle, Narrowing::Sheet(sheet, reversed))
        });
        let mut ranked: Vec<(f64, Narrowing)> = faces.chain(sheets).collect();
        let count = WINDOW_SHADOWS.min(ranked.len());
        if count == 0 {
            return Window::Wide;
        }
        ranked.select_nth_unstable_by(count - 1, |a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let project = |p: DVec3| project_onto(e, point, h_x, p);
        let mut union = ShadowUnion::default();
        for &(_, narrowing) in &ranked[..count] {
            let index = match narrowing {
                Narrowing::Sheet(sheet, reversed) => {
                    union.add_edges(&self.outline_edges(sheet, reversed, project));
                    continue;
                }
                Narrowing::Face(index) => index,
            };
            let occ = &self.occluders[index];
            // Faces through x, or not wholly between the planes within reach, wait for the
            // full pass.
            let (lowest, highest) = e.height_range(&occ.polygon);
            if lowest < 0.0
                || highest > reach
                || occ.holds(point, self.tol)
                || viewer.owns(occ.surface)
            {
                continue;
            }
            let corners: Vec<DVec2> = occ.polygon.iter().map(|&p| project(p)).collect();
            union.add_face(&occ.keys, &corners);
        }
        let Ok(visible) = union.subtract_from(piece, &self.overlay_limit) else {
            return Window::Wide;
        };
        if visible.is_empty() {
            return Window::Covered;
        }
        let hull = convex_hull_2d(visible_points(&visible).copied().collect());
        if hull.len() < 3 || signed_area_2d(&hull) > WINDOW_SHRINK * signed_area_2d(piece) {
            return Window::Wide;
        }
        Window::Narrowed { visible, hull }
    }
}

impl DirectLight<'_> {
    /// The blockings with each outline replaced by its sheet's faces, projected whole, for the
    /// one-by-one subtraction.
    fn faces_of_outlines<'b>(
        &self,
        blockings: Vec<Blocking<'b>>,
        point: DVec3,
        e: &Emitter,
        h_x: f64,
    ) -> Vec<Blocking<'b>> {
        let mut out = Vec::with_capacity(blockings.len());
        for b in blockings {
            let Blocking::Outline { sheet, .. } = b else {
                out.push(b);
                continue;
            };
            for &index in self.tree.faces_of(sheet) {
                let corners = self.occluders[index]
                    .polygon
                    .iter()
                    .map(|&p| project_onto(e, point, h_x, p))
                    .collect();
                out.push(Blocking::Shadow {
                    corners,
                    keys: None,
                });
            }
        }
        out
    }
}

/// What the occluders in a shaft hide: the blockings, and, when the shaft was narrowed, what the
/// largest of them left visible (the start of the subtraction) with its hull (the narrowed
/// shaft's cross-section, holding every blocking that still matters).
struct Blocked<'a> {
    blockings: Vec<Blocking<'a>>,
    start: Option<(Vec<VisibleShape>, Vec<DVec2>)>,
}

/// A face or an outline sheet (reversed or not) that may narrow a shaft.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Narrowing {
    Face(usize),
    Sheet(usize, bool),
}

/// How far the largest faces in a shaft narrow it.
enum Window {
    /// They hide all of the piece.
    Covered,
    /// They leave these shapes, whose hull is much smaller than the piece.
    Narrowed {
        visible: Vec<VisibleShape>,
        hull: Vec<DVec2>,
    },
    /// Not enough to be worth a second walk.
    Wide,
}

/// The side planes of the shaft from `point` to a convex polygon, oriented to contain it.
fn shaft_sides(point: DVec3, front: &[DVec3]) -> Vec<DVec3> {
    let center = front.iter().copied().sum::<DVec3>() / front.len() as f64;
    (0..front.len())
        .map(|i| {
            let m = (front[i] - point).cross(front[(i + 1) % front.len()] - point);
            if m.dot(center - point) < 0.0 { -m } else { m }
        })
        .collect()
}

/// One convex piece of an emitter seen from a point: what the occluders not through the point
/// leave of it (shapes of an outline and holes), the occluders through the point, and the faces
/// of the receivers' own surfaces whose planes miss it ([`Viewer::Group`]): each receiver
/// loses what the others' hide on its side, or their shadows as it sees them on its own.
struct PieceView {
    piece: Vec<DVec2>,
    visible: Vec<VisibleShape>,
    touching: Vec<usize>,
    own: Vec<usize>,
}

/// Lambert's contour sum over contours on an emitter's plane, each counted with the sign of its
/// turn about the emitter's normal (counter-clockwise adds, clockwise removes). The overlay may
/// give a part of no area as an outline and a reversed copy of it, not as a hole inside it:
/// those cancel.
fn signed_sum<'c>(
    x: &ReceivingPoint,
    contours: impl IntoIterator<Item = &'c Vec<DVec3>>,
    normal: DVec3,
    tol: f64,
) -> f64 {
    contours
        .into_iter()
        .map(|c| polygon::newell_normal(c).dot(normal).signum() * contour_sum(x, c, tol).abs())
        .sum()
}

/// `p` projected from `point` (at height `h_x` above the emitter's plane) onto that plane, in
/// the emitter's 2D frame.
fn project_onto(e: &Emitter, point: DVec3, h_x: f64, p: DVec3) -> DVec2 {
    let s = h_x / (h_x - e.frame.height(p));
    e.frame.to_2d(point + (p - point) * s)
}

/// Points spread evenly over convex polygons (fanned into triangles, each cut into about
/// `per_triangle` similar triangles whose centroids are taken), with the area each stands for.
fn stratified_points(polygons: &[Vec<DVec3>], per_triangle: usize) -> Vec<(DVec3, f64)> {
    let m = (per_triangle as f64).sqrt().ceil().max(1.0) as usize;
    let mut out = Vec::new();
    for polygon in polygons {
        for k in 1..polygon.len() - 1 {
            let (a, b, c) = (polygon[0], polygon[k], polygon[k + 1]);
            let (u, v) = ((b - a) / m as f64, (c - a) / m as f64);
            let area = u.cross(v).length() / 2.0;
            // Sub-triangles pointing up (i + j < m) and down (i + j < m - 1).
            for i in 0..m {
                for j in 0..m - i {
                    let corner = a + u * i as f64 + v * j as f64;
                    out.push((corner + (u + v) / 3.0, area));
                    if i + j + 1 < m {
                        out.push((corner + (u + v) * (2.0 / 3.0), area));
                    }
                }
            }
        }
    }
    out
}

/// Whether the bounding box of `outer` holds every point of `inner`.
fn box_holds(outer: &[DVec2], inner: &[DVec2]) -> bool {
    let (lo, hi) = outer
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    inner.iter().all(|p| p.cmpge(lo).all() && p.cmple(hi).all())
}

/// Whether a shadow (a convex counter-clockwise polygon, tidied by [`tidy_shadow`]) covers all
/// of a convex piece.
fn covers(shadow: &[DVec2], piece: &[DVec2]) -> bool {
    piece.iter().all(|&p| inside_convex(p, shadow))
}

/// A projected shadow as a counter-clockwise convex polygon without near-duplicate corners, or
/// `None` if nothing wider than a rounding sliver is left.
fn tidy_shadow(corners: &[DVec2], e: &Emitter, min_width: f64) -> Option<Vec<DVec2>> {
    let mut shadow = corners.to_vec();
    merge_close_vertices(&mut shadow, e.merge_distance);
    if shadow.len() < 3 {
        return None;
    }
    if signed_area_2d(&shadow) < 0.0 {
        shadow.reverse();
    }
    wider_than(&shadow, min_width).then_some(shadow)
}

/// `piece` minus each blocking in turn, as convex pieces.
fn subtract_one_by_one(
    piece: Vec<DVec2>,
    blockings: Vec<Blocking<'_>>,
    e: &Emitter,
    min_width: f64,
) -> Vec<Vec<DVec2>> {
    let mut visible = vec![piece];
    for blocking in blockings {
        let mut next = Vec::with_capacity(visible.len() + 4);
        match blocking {
            Blocking::Touching(_) | Blocking::Own(_) => {}
            Blocking::Contact(regions) => {
                for region in regions {
                    next.clear();
                    for v in &visible {
                        subtract_half_planes(v, &region, min_width, &mut next);
                    }
                    std::mem::swap(&mut visible, &mut next);
                }
            }
            Blocking::Outline { .. } => unreachable!("outlines are expanded into faces"),
            Blocking::Shadow { corners, .. } => {
                let Some(shadow) = tidy_shadow(&corners, e, min_width) else {
                    continue;
                };
                for v in &visible {
                    subtract_convex(v, &shadow, min_width, &mut next);
                }
                visible = next;
            }
        }
        if visible.is_empty() {
            break;
        }
    }
    visible
}

/// `piece` (or, in a narrowed shaft, what the largest occluders left of it) minus every blocking
/// at once ([`ShadowUnion`]), unless the overlay refuses the coordinates or would hold more than
/// `cap` edges.
fn subtract_at_once(
    piece: &[DVec2],
    start: Option<(Vec<VisibleShape>, Vec<DVec2>)>,
    blockings: &[Blocking<'_>],
    e: &Emitter,
    min_width: f64,
    limit: &OverlayLimit,
) -> Result<Vec<VisibleShape>, Refusal> {
    let mut union = ShadowUnion::with_capacity(
        blockings
            .iter()
            .map(|b| match b {
                Blocking::Shadow { corners, .. } => corners.len(),
                Blocking::Outline { edges, .. } => edges.len(),
                _ => 0,
            })
            .sum(),
    );
    for blocking in blockings {
        match blocking {
            Blocking::Touching(_) | Blocking::Own(_) => {}
            Blocking::Contact(regions) => {
                for region in regions {
                    let mut hidden = piece.to_vec();
                    for h in region {
                        hidden = clip_half_plane(&hidden, h);
                    }
                    if wider_than(&hidden, min_width) {
                        union.add_contour(hidden);
                    }
                }
            }
            Blocking::Shadow {
                corners,
                keys: Some(keys),
            } => union.add_face(keys, corners),
            Blocking::Shadow { corners, .. } => {
                if let Some(shadow) = tidy_shadow(corners, e, min_width) {
                    union.add_contour(shadow);
                }
            }
            Blocking::Outline { edges, .. } => union.add_edges(edges),
        }
    }
    match start {
        Some((visible, hull)) => union.subtract_within(visible, &hull, limit),
        None => union.subtract_from(piece, limit),
    }
}

/// What an occluder whose plane holds x hides of the emitter's plane, in the one-sided limit from
/// `x + eps * inward`: the directions that cross to the occluder's other side through its corner
/// at x. Each region is an intersection of half-planes in the emitter's 2D frame; a reflex corner
/// gives two. Empty when x is not on the occluder or the limit point stays in its plane.
fn contact_shadow(
    x: &ReceivingPoint,
    occ: &ConvexPiece,
    e: &Emitter,
    tol: f64,
) -> Vec<Vec<HalfPlane>> {
    let n = occ.normal;
    let along = n.dot(x.inward);
    if along.abs() <= 1e-12 {
        return Vec::new();
    }
    let side = along.signum();
    // Edges of the occluder passing through x, with their inward normals in its plane.
    let m = occ.polygon.len();
    let mut through = Vec::new();
    for k in 0..m {
        let (a, b) = (occ.polygon[k], occ.polygon[(k + 1) % m]);
        if closest_point_on_segment(x.point, a, b).distance(x.point) <= tol {
            through.push((k, n.cross(b - a).normalize_or_zero()));
        }
    }
    let inside = through.is_empty()
        && PlaneFrame::of_polygon(&occ.polygon).is_some_and(|frame| {
            let flat: Vec<DVec2> = occ.polygon.iter().map(|&p| frame.to_2d(p)).collect();
            inside_convex(frame.to_2d(x.point), &flat)
        });
    if through.is_empty() && !inside {
        return Vec::new();
    }
    // A direction d is hidden when it crosses the plane (side * n . d < 0) and the point where the
    // limit ray crosses lies in the occluder's corner: g_k . d >= 0 for each edge through x.
    let to_half_plane = |g: DVec3| HalfPlane {
        normal: DVec2::new(g.dot(e.frame.u), g.dot(e.frame.v)),
        offset: g.dot(e.frame.origin - x.point),
    };
    let crossing = to_half_plane(-side * n);
    let edge_condition =
        |inward: DVec3| to_half_plane(along.abs() * inward - side * inward.dot(x.inward) * n);
    match through.as_slice() {
        [] => vec![vec![crossing]],
        [(_, m0)] => vec![vec![crossing, edge_condition(*m0)]],
        [(k0, m0), (k1, m1), ..] => {
            // At a vertex: the corner between the two edges, convex or reflex.
            let (first, second) = if (k0 + 1) % m == *k1 {
                (k0, k1)
            } else {
                (k1, k0)
            };
            let d_in = occ.polygon[(first + 1) % m] - occ.polygon[*first];
            let d_out = occ.polygon[(second + 1) % m] - occ.polygon[*second];
            let convex = n.dot(d_in.cross(d_out)) >= 0.0;
            let (c0, c1) = (edge_condition(*m0), edge_condition(*m1));
            if convex {
                vec![vec![crossing, c0, c1]]
            } else {
                vec![vec![crossing, c0], vec![crossing, c1]]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::builtin;

    fn floor_point(x: f64, y: f64) -> ReceivingPoint {
        ReceivingPoint::interior(DVec3::new(x, y, 0.0), DVec3::Z)
    }

    /// `docs/closed-forms.md`, "The profile": the exact penumbra profile on the textbook floor.
    #[test]
    fn textbook_penumbra_profile() {
        let scene = builtin::textbook();
        let vis = Visibility::build(&scene);
        let direct = DirectLight::new(&scene, &vis);
        let floor = scene.surface_id("floor").expect("floor");
        for (x, e) in [
            (0.0, 0.0),
            (0.25, 0.0),
            (0.5, 0.0),
            (0.6, 0.00688007281804919),
            (0.7, 0.0133800790421904),
            (0.75, 0.0163850596402602),
            (0.8, 0.0191844957604821),
            (0.9, 0.0240846792566362),
            (1.0, 0.0279891563025598),
            (1.5, 0.0223622043845991),
            (2.0, 0.0169106400921385),
        ] {
            for p in [
                floor_point(x, 0.0),
                floor_point(-x, 0.0),
                floor_point(0.0, x),
            ] {
                let h = direct.irradiance(&p, floor).r;
                assert!(
                    (h - e).abs() <= 1e-12 + 1e-10 * e,
                    "E/M at {}: {h} vs {e}",
                    p.point
                );
            }
        }
    }

    /// `docs/closed-forms.md`, "A box standing on the floor": a 0.5 box standing on the floor under
    /// the light. On the contact line the light jumps; each side's limit is exact.
    #[test]
    fn limits_on_both_sides_of_a_contact_line() {
        use penumbra_scenes::{Rgb, Surface};
        let mut scene = builtin::textbook();
        scene.surfaces.retain(|s| s.name != "blocker");
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z) * 0.25;
        let faces = [
            vec![
                c(-1., -1., 2.),
                c(1., -1., 2.),
                c(1., 1., 2.),
                c(-1., 1., 2.),
            ],
            vec![c(1., -1., 0.), c(1., 1., 0.), c(1., 1., 2.), c(1., -1., 2.)],
            vec![
                c(-1., 1., 0.),
                c(-1., -1., 0.),
                c(-1., -1., 2.),
                c(-1., 1., 2.),
            ],
            vec![c(1., 1., 0.), c(-1., 1., 0.), c(-1., 1., 2.), c(1., 1., 2.)],
            vec![
                c(-1., -1., 0.),
                c(1., -1., 0.),
                c(1., -1., 2.),
                c(-1., -1., 2.),
            ],
        ];
        for (i, f) in faces.into_iter().enumerate() {
            scene
                .surfaces
                .push(Surface::new(format!("box{i}"), f, Rgb::splat(0.5)));
        }
        assert!(penumbra_scenes::validate(&scene).is_empty());
        let vis = Visibility::build(&scene);
        let direct = DirectLight::new(&scene, &vis);
        let floor = scene.surface_id("floor").expect("floor");
        let on_line = DVec3::new(0.25, 0.0, 0.0);
        let at = |inward: DVec3| ReceivingPoint {
            point: on_line,
            normal: DVec3::Z,
            inward,
        };
        let outside = direct.irradiance(&at(DVec3::X), floor).r;
        assert!((outside - 0.00864260029379876).abs() < 1e-12, "{outside}");
        assert_eq!(direct.irradiance(&at(-DVec3::X), floor).r, 0.0);
        // Just outside, the value tends to the limit.
        let near = direct.irradiance(&floor_point(0.25 + 1e-7, 0.0), floor).r;
        assert!((near - outside).abs() < 1e-7, "{near} vs {outside}");
        // At the box's corner, from outside along the diagonal, the limit matches nearby points.
        let corner = DVec3::new(0.25, 0.25, 0.0);
        let diagonal = DVec3::new(1.0, 1.0, 0.0).normalize();
        let limit = direct
            .irradiance(
                &ReceivingPoint {
                    point: corner,
                    normal: DVec3::Z,
                    inward: diagonal,
                },
                floor,
            )
            .r;
        let near = direct
            .irradiance(&floor_point(0.25 + 1e-7, 0.25 + 1e-7), floor)
            .r;
        assert!(
            limit > 0.0 && (limit - near).abs() < 1e-6,
            "{limit} vs {near}"
        );
        let under = direct
            .irradiance(
                &ReceivingPoint {
                    point: corner,
                    normal: DVec3::Z,
                    inward: -diagonal,
                },
                floor,
            )
            .r;
        assert_eq!(under, 0.0);
    }

    /// The estimate by rays: exact where the light is wholly seen or wholly hidden, and close
    /// to the exact value across the penumbra (`docs/closed-forms.md`, "The profile").
    #[test]
    fn the_estimate_by_rays_follows_the_exact_light() {
        let scene = builtin::textbook();
        let vis = Visibility::build(&scene);
        let direct = DirectLight::new(&scene, &vis);
        let floor = scene.surface_id("floor").expect("floor");
        let mut worst: f64 = 0.0;
        for x in [0.0, 0.25, 0.55, 0.6, 0.7, 0.8, 0.9, 1.0, 1.2, 1.5, 2.0] {
            let p = floor_point(x, 0.1);
            let exact = direct.irradiance(&p, floor).r;
            let estimate = direct.irradiance_sampled(&p, floor, 256).r;
            if exact == 0.0 || x >= 1.0 {
                assert!((estimate - exact).abs() <= 1e-12 * exact.max(1e-3), "{x}");
            }
            worst = worst.max((estimate - exact).abs());
        }
        // Against the light at the edge of the penumbra, 0.028.
        assert!(worst > 0.0 && worst < 1e-3, "{worst}");
    }

    /// Past the overlay cap a point's light is unknown (NaN), never a wrong number; points that
    /// need no overlay keep their exact value.
    #[test]
    fn the_overlay_cap_gives_up_rather_than_guess() {
        let scene = penumbra_scenes::tessellated::tessellated(7);
        let vis = Visibility::build(&scene);
        let exact = DirectLight::new(&scene, &vis);
        let capped = DirectLight::new(&scene, &vis).with_overlay_cap(8);
        let floor = scene.surface_id("floor").expect("floor");
        let (mut unknown, mut same) = (0, 0);
        for i in 0..40 {
            let p = floor_point(-2.0 + 0.1 * i as f64, 0.3);
            let (e, c) = (
                exact.irradiance(&p, floor).r,
                capped.irradiance(&p, floor).r,
            );
            assert!(e.is_finite());
            if c.is_nan() {
                unknown += 1;
            } else {
                assert_eq!(e, c);
                same += 1;
            }
        }
        assert!(unknown > 0 && same > 0, "{unknown} {same}");
    }

    /// A 4 x 4 light over a roof of 0.5 tiles with a 1 x 1 opening, and 400 small triangles
    /// scattered between them: from the floor, the tiles hide all but the opening, and
    /// narrowing the shaft to it drops most of the triangles. No value changes.
    #[test]
    fn narrowed_shafts_give_the_same_light() {
        use penumbra_scenes::{Rgb, Surface};
        let grey = Rgb::splat(0.5);
        let quad = |x: f64, y: f64, s: f64, z: f64| {
            vec![
                DVec3::new(x, y, z),
                DVec3::new(x + s, y, z),
                DVec3::new(x + s, y + s, z),
                DVec3::new(x, y + s, z),
            ]
        };
        let mut surfaces = vec![
            Surface::new(
                "light",
                quad(-2.0, -2.0, 4.0, 3.0).into_iter().rev().collect(),
                Rgb::ZERO,
            )
            .with_emission(Rgb::splat(1.0)),
        ];
        for i in 0..12 {
            for j in 0..12 {
                let (x, y) = (-3.0 + 0.5 * i as f64, -3.0 + 0.5 * j as f64);
                if (-0.5..0.5).contains(&x) && (-0.5..0.5).contains(&y) {
                    continue;
                }
                surfaces.push(Surface::new(
                    format!("tile {i} {j}"),
                    quad(x, y, 0.5, 2.0),
                    grey,
                ));
            }
        }
        let mut rng = penumbra_scenes::SplitMix64::new(7);
        for k in 0..400 {
            let c = DVec3::new(
                -2.5 + 5.0 * rng.next_f64(),
                -2.5 + 5.0 * rng.next_f64(),
                2.1 + 0.8 * rng.next_f64(),
            );
            let corners = vec![
                c,
                c + DVec3::new(0.05, 0.0, 0.01),
                c + DVec3::new(0.0, 0.05, 0.02),
            ];
            surfaces.push(Surface::new(format!("chip {k}"), corners, grey));
        }
        let scene = Scene {
            up: None,
            unit: None,
            name: "roof".into(),
            camera: None,
            surfaces,
        };
        let vis = Visibility::build(&scene);
        let wide = DirectLight::new(&scene, &vis);
        let narrow = DirectLight {
            window_faces: 0,
            ..DirectLight::new(&scene, &vis)
        };
        let receiver = scene.surfaces.len();
        let x = floor_point(0.1, -0.2);
        let e = &narrow.emitters[0];
        let mut piece: Vec<DVec2> = e.pieces[0].iter().map(|&p| e.frame.to_2d(p)).collect();
        if signed_area_2d(&piece) < 0.0 {
            piece.reverse();
        }
        let h_x = e.frame.height(x.point);
        let reach = h_x * (1.0 - 1.0 / PROJECTION_REACH);
        let sides = shaft_sides(x.point, &e.pieces[0]);
        // A viewer that leaves no surface out.
        let anyone = Viewer::Group(&[]);
        let (all, nodes) = narrow.reached(x.point, anyone, e, &sides, reach);
        let Window::Narrowed { hull, .. } =
            narrow.window(x.point, anyone, e, h_x, reach, &piece, &all, &nodes)
        else {
            panic!("the tiles narrow the shaft");
        };
        let hull3: Vec<DVec3> = hull.iter().map(|&q| e.frame.to_3d(q)).collect();
        let (kept, _) = narrow.reached(x.point, anyone, e, &shaft_sides(x.point, &hull3), reach);
        assert!(
            kept.len() * 2 < all.len(),
            "{} of {} faces kept",
            kept.len(),
            all.len()
        );
        let mut lit = 0;
        for i in 0..15 {
            for j in 0..15 {
                let p = floor_point(-1.4 + 0.2 * i as f64, -1.4 + 0.2 * j as f64);
                let (a, b) = (
                    wide.irradiance(&p, receiver).r,
                    narrow.irradiance(&p, receiver).r,
                );
                assert!((a - b).abs() <= 1e-12, "at {}: {a} against {b}", p.point);
                lit += usize::from(a > 0.0);
            }
        }
        assert!(lit > 20, "{lit} points see the light");
    }

    /// A part of no area given as a triangle and, beside it, a reversed copy with a corner
    /// repeated (as the overlay may give it) adds nothing; the triangle alone adds its sum.
    #[test]
    fn a_reversed_copy_cancels_its_outline() {
        let x = floor_point(0.1, -0.2);
        let at = |u: f64, v: f64| DVec3::new(u, v, 1.0);
        let triangle = vec![at(-0.3, 0.2), at(0.1, -0.5), at(0.4, 0.25)];
        let copy = vec![
            at(0.4, 0.25),
            at(0.1, -0.5),
            at(0.1, -0.5 + 1e-15),
            at(-0.3, 0.2),
        ];
        let tol = 1e-12;
        let alone = signed_sum(&x, [&triangle], DVec3::Z, tol);
        assert!(alone > 0.1, "{alone}");
        assert_eq!(alone, contour_sum(&x, &triangle, tol).abs());
        let both = signed_sum(&x, [&triangle, &copy], DVec3::Z, tol);
        assert!(both.abs() < 1e-12 * alone, "{both}");
    }

    #[test]
    fn points_behind_the_light_and_on_the_light_plane_get_nothing() {
        let scene = builtin::textbook();
        let vis = Visibility::build(&scene);
        let direct = DirectLight::new(&scene, &vis);
        // A ceiling point above the light, facing down.
        let above = ReceivingPoint::interior(DVec3::new(0.2, 0.1, 3.5), -DVec3::Z);
        assert_eq!(direct.irradiance(&above, usize::MAX), Rgb::ZERO);
    }
}
