//! A bounding-volume tree over the occluder pieces, walked once per shaft.
//!
//! Two things make the cost of a shaft follow its shadow rather than the tessellation:
//! - a node wholly outside one side of the shaft, or beyond the emitter's plane, is dropped with
//!   all its faces (a point in full light meets a few nodes, not every face in a bounding box);
//! - a node whose faces all lie between the two planes, within projection reach, and all turn
//!   the same way to the point, casts the shadow of its *outline*: projecting every face and
//!   letting the welded inner edges cancel ([`crate::shadow_union`]) leaves the node's boundary
//!   edges, which are known in advance. A face-on sheet of ten thousand faces costs its rim.
//!   When the node belongs to closed solids and turns away from the point, it is skipped.
//!
//! Faces are oriented by their *facing normal*: outward for faces of closed solids, else as
//! listed. Whether a node turns towards the point is decided conservatively from a cone holding
//! its facing normals and a sphere holding its corners, and for a small node the cone cannot
//! decide, face by face; faces of a node that turns both ways are visited one by one.

use glam::DVec3;
use penumbra_scenes::polygon::newell_normal;

use crate::sheet_outline::{CornerKey, cancel_opposite};

/// Nodes with at most this many faces are leaves.
const LEAF_FACES: usize = 4;
/// Nodes with fewer faces than this keep no outline: visiting their faces costs as little.
const OUTLINE_MIN_FACES: usize = 8;
/// A node whose faces do not all turn one way keeps the outlines of its faces' planes (faces
/// whose facing normals and planes agree to [`GROUP_DEVIATION`]) when there are at most this
/// many: a tessellated box or prism is then decided whole, plane by plane, rather than opened
/// face by face along every fold.
const MAX_GROUPS: usize = 8;
/// Faces are in one plane group when their facing normals (unit) are at most this far apart and
/// each one's centroid lies within this fraction of their distance from the origin of the
/// other's plane: the rounding of a flat face's tessellation, far below any fold.
const GROUP_DEVIATION: f64 = 1e-9;
/// A node of at most this many faces whose cone cannot tell how its faces turn is decided face
/// by face: a dot product each, far less than projecting them one by one. Near a statue's
/// silhouette the cones of small nodes straddle the line of sight while every face is clear.
const EXACT_TURN_FACES: usize = 64;
/// Consecutive outline edges whose directions differ by less than this sine are one straight
/// edge: the corners between them lie within this fraction of the run's length of its chord,
/// the rounding of corners computed along a straight edge (a tessellated face's rim), so the
/// outline keeps the shape's few edges rather than every step of its tessellation.
const COLLINEAR_SINE: f64 = 1e-12;

/// One occluder face as the tree sees it.
pub(crate) struct TreeFace<'a> {
    pub polygon: &'a [DVec3],
    pub keys: &'a [CornerKey],
    /// The facing normal (unit): outward for a face of a closed solid.
    pub facing: DVec3,
    /// Whether the face belongs to a closed solid.
    pub closed: bool,
}

/// A directed boundary edge of a node's faces, along their facing orientation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct OutlineEdge {
    pub from: CornerKey,
    pub to: CornerKey,
    pub from_at: DVec3,
    pub to_at: DVec3,
}

/// What a node's faces look like from afar: the cone of their facing normals (every one within
/// `deviation` of `axis`, at most an angle `spread` from it), a sphere around their corners, and
/// their outline.
#[derive(Debug)]
struct Sheet {
    axis: DVec3,
    deviation: f64,
    /// The cosine and sine of the spread.
    spread: (f64, f64),
    center: DVec3,
    radius: f64,
    /// The least and greatest of `axis . v` over the corners.
    heights: (f64, f64),
    /// The faces' area seen along `axis`.
    area: f64,
    closed: bool,
    outline: Vec<OutlineEdge>,
    faces: Members,
}

/// The faces of a sheet.
#[derive(Debug)]
enum Members {
    /// A node's, all of them.
    Node(usize),
    /// A plane group's.
    Listed(Vec<usize>),
}

#[derive(Debug)]
struct Node {
    min: DVec3,
    max: DVec3,
    /// The node's faces: `items[start..end]`.
    start: usize,
    end: usize,
    children: Option<(usize, usize)>,
    /// Its sheets: all its faces as one, when they can all turn one way; else its plane groups,
    /// when they are few ([`MAX_GROUPS`]); else none.
    sheets: std::ops::Range<usize>,
}

/// The shaft from a point to a convex piece of an emitter, as the tree tests it.
pub(crate) struct ShaftTest<'a> {
    pub point: DVec3,
    /// Normals of the side planes through the point, pointing into the shaft.
    pub sides: &'a [DVec3],
    pub emitter_origin: DVec3,
    pub emitter_normal: DVec3,
    /// Faces whose corners' heights above the emitter's plane lie in `(lowest, highest)` go
    /// whole into the union; the outline of a node may stand for them.
    pub lowest: f64,
    pub highest: f64,
    /// A face turns towards (or away from) the point when its facing normal's product with the
    /// direction to the point exceeds this distance.
    pub margin: f64,
}

/// What a walk of the tree reaches.
pub(crate) enum Reached {
    /// An occluder, by index, to be examined on its own.
    Face(usize),
    /// A sheet (a node, or a plane group of one) whose faces all turn one way to the point: its
    /// outline, reversed when they turn away.
    Outline { sheet: usize, reversed: bool },
}

/// The tree over a scene's occluder pieces.
#[derive(Debug, Default)]
pub(crate) struct OccluderTree {
    nodes: Vec<Node>,
    items: Vec<usize>,
    /// The nodes' sheets and plane groups.
    sheets: Vec<Sheet>,
    /// Each face's facing normal and the least and greatest of its product with the corners.
    turns: Vec<FaceTurn>,
}

/// What decides which way one face turns to a point.
#[derive(Clone, Copy, Debug)]
struct FaceTurn {
    facing: DVec3,
    low: f64,
    high: f64,
}

impl FaceTurn {
    fn of(face: &TreeFace) -> FaceTurn {
        let heights = face.polygon.iter().map(|&p| face.facing.dot(p));
        FaceTurn {
            facing: face.facing,
            low: heights.clone().fold(f64::INFINITY, f64::min),
            high: heights.fold(f64::NEG_INFINITY, f64::max),
        }
    }

    /// As [`Sheet::turns_away`], for this face alone.
    fn turns_away(&self, point: DVec3, margin: f64) -> Option<bool> {
        let along = self.facing.dot(point);
        if along - self.high > margin {
            Some(false)
        } else if self.low - along > margin {
            Some(true)
        } else {
            None
        }
    }
}

impl OccluderTree {
    pub(crate) fn build(faces: &[TreeFace]) -> OccluderTree {
        let mut tree = OccluderTree {
            nodes: Vec::new(),
            items: (0..faces.len()).collect(),
            sheets: Vec::new(),
            turns: faces.iter().map(FaceTurn::of).collect(),
        };
        if !faces.is_empty() {
            let centroids: Vec<DVec3> = faces
                .iter()
                .map(|f| f.polygon.iter().sum::<DVec3>() / f.polygon.len() as f64)
                .collect();
            let meshes = Meshes::of(faces, &centroids);
            tree.split(faces, &centroids, &meshes, 0, faces.len());
        }
        tree
    }

    /// Renumbers the faces in the tree's order, so that a walk reaches them in increasing order
    /// (a shaft's candidates then lie close together in memory, where the caller stores its
    /// faces in that order); returns each new face's old index.
    pub(crate) fn renumber_in_order(&mut self) -> Vec<usize> {
        let order = std::mem::replace(&mut self.items, (0..self.turns.len()).collect());
        let mut new_index = vec![0; order.len()];
        for (k, &old) in order.iter().enumerate() {
            new_index[old] = k;
        }
        self.turns = order.iter().map(|&old| self.turns[old]).collect();
        for sheet in &mut self.sheets {
            if let Members::Listed(faces) = &mut sheet.faces {
                faces.iter_mut().for_each(|i| *i = new_index[*i]);
            }
        }
        order
    }

    /// Gives each corner key of the sheets' outlines its new number, `renumbered[old]`.
    pub(crate) fn renumber_keys(&mut self, renumbered: &[CornerKey]) {
        for edge in self.sheets.iter_mut().flat_map(|s| s.outline.iter_mut()) {
            edge.from = renumbered[edge.from as usize];
            edge.to = renumbered[edge.to as usize];
        }
    }

    /// Builds the node over `items[start..end]` and its subtree; returns its index.
    fn split(
        &mut self,
        faces: &[TreeFace],
        centroids: &[DVec3],
        meshes: &Meshes,
        start: usize,
        end: usize,
    ) -> usize {
        let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &i in &self.items[start..end] {
            for &p in faces[i].polygon {
                min = min.min(p);
                max = max.max(p);
            }
        }
        let index = self.nodes.len();
        let members = &self.items[start..end];
        let first = self.sheets.len();
        if end - start >= OUTLINE_MIN_FACES {
            match sheet_of(members.iter().map(|&i| &faces[i]), Members::Node(index)) {
                Some(whole) => self.sheets.push(whole),
                None => {
                    let planes = plane_groups(faces, members, centroids);
                    if planes.len() <= MAX_GROUPS {
                        let made: Option<Vec<Sheet>> = planes
                            .into_iter()
                            .map(|g| {
                                let of = g.iter().map(|&i| &faces[i]).collect::<Vec<_>>();
                                sheet_of(of.into_iter(), Members::Listed(g))
                            })
                            .collect();
                        if let Some(made) = made {
                            self.sheets.extend(made);
                        }
                    }
                }
            }
        }
        self.nodes.push(Node {
            min,
            max,
            start,
            end,
            children: None,
            sheets: first..self.sheets.len(),
        });
        if end - start > LEAF_FACES {
            let mid = match meshes.split(&mut self.items[start..end]) {
                Some(at) => start + at,
                None => {
                    // Median split of the centroids along their widest axis; ties by index, so
                    // the tree does not depend on the sort's stability.
                    let axis = widest_axis(self.items[start..end].iter().map(|&i| centroids[i]));
                    let mid = (start + end) / 2;
                    self.items[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
                        centroids[a][axis]
                            .total_cmp(&centroids[b][axis])
                            .then(a.cmp(&b))
                    });
                    mid
                }
            };
            let left = self.split(faces, centroids, meshes, start, mid);
            let right = self.split(faces, centroids, meshes, mid, end);
            self.nodes[index].children = Some((left, right));
        }
        index
    }

    /// The faces of sheet `sheet` (as [`Reached::Outline`] gives it).
    pub(crate) fn faces_of(&self, sheet: usize) -> &[usize] {
        match &self.sheets[sheet].faces {
            Members::Listed(faces) => faces,
            Members::Node(node) => {
                let n = &self.nodes[*node];
                &self.items[n.start..n.end]
            }
        }
    }

    /// Whether every face of sheet `sheet` turns away from `point` by more than `margin`
    /// (`Some(true)`), every one towards it (`Some(false)`), or neither.
    fn faces_turn_away(&self, sheet: usize, point: DVec3, margin: f64) -> Option<bool> {
        let mut faces = self.faces_of(sheet).iter();
        let first = self.turns[*faces.next()?].turns_away(point, margin)?;
        faces
            .all(|&i| self.turns[i].turns_away(point, margin) == Some(first))
            .then_some(first)
    }

    /// About the solid angle sheet `sheet` fills seen from `point` (from its area along its axis
    /// and its centre): for ranking sheets, not for measuring.
    pub(crate) fn solid_angle(&self, sheet: usize, point: DVec3) -> f64 {
        let s = &self.sheets[sheet];
        let d = s.center - point;
        let r2 = d.length_squared();
        s.area * s.axis.dot(d).abs() / (r2 * r2.sqrt())
    }

    /// The outline of sheet `sheet`.
    pub(crate) fn outline(&self, sheet: usize) -> &[OutlineEdge] {
        &self.sheets[sheet].outline
    }

    /// Visits what the shaft may hold: whole nodes by their outline where that is exact, else
    /// faces, in a fixed order.
    pub(crate) fn walk(&self, shaft: &ShaftTest, visit: &mut impl FnMut(Reached)) {
        if !self.nodes.is_empty() {
            self.walk_from(0, shaft, visit);
        }
    }

    fn walk_from(&self, index: usize, shaft: &ShaftTest, visit: &mut impl FnMut(Reached)) {
        let node = &self.nodes[index];
        // Heights above the emitter's plane over the box.
        let (low, high) = box_range(node.min, node.max, shaft.emitter_normal);
        let base = shaft.emitter_normal.dot(shaft.emitter_origin);
        let (low, high) = (low - base, high - base);
        if high < 0.0
            || shaft.sides.iter().any(|&m| {
                // A face through the point (within the margin) stays: it is not outside.
                box_range(node.min, node.max, m).1 < m.dot(shaft.point) - shaft.margin * m.length()
            })
        {
            return;
        }
        if low > shaft.lowest && high < shaft.highest {
            let sheets = node.sheets.clone();
            // At most MAX_GROUPS: kept inline, as this runs at every node a shaft meets.
            let turns: Option<smallvec::SmallVec<[bool; MAX_GROUPS]>> = sheets
                .clone()
                .map(|s| self.sheets[s].turns_away(shaft.point, shaft.margin))
                .collect();
            let turns = turns.or_else(|| {
                (node.end - node.start <= EXACT_TURN_FACES)
                    .then(|| {
                        sheets
                            .clone()
                            .map(|s| self.faces_turn_away(s, shaft.point, shaft.margin))
                            .collect()
                    })
                    .flatten()
            });
            if let Some(turns) = turns.filter(|t| !t.is_empty()) {
                for (s, away) in sheets.zip(turns) {
                    if !(away && self.sheets[s].closed) {
                        visit(Reached::Outline {
                            sheet: s,
                            reversed: away,
                        });
                    }
                }
                return;
            }
        }
        match node.children {
            Some((left, right)) => {
                self.walk_from(left, shaft, visit);
                self.walk_from(right, shaft, visit);
            }
            None => self.items[node.start..node.end]
                .iter()
                .for_each(|&i| visit(Reached::Face(i))),
        }
    }
}

/// The axis along which `points` spread the most.
fn widest_axis(points: impl Iterator<Item = DVec3>) -> usize {
    let (lo, hi) = points.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p), hi.max(p))
    });
    (hi - lo).max_position()
}

/// The welded meshes among the faces (faces sharing a corner key), each kept in one subtree
/// until it is alone in its node: a node then holds a whole mesh, which its outlines or plane
/// groups can stand for at once, rather than parts of several cut along arbitrary lines.
struct Meshes {
    /// Each face's mesh.
    of: Vec<usize>,
    /// Each mesh's centroid (the mean of its faces' centroids).
    centroids: Vec<DVec3>,
}

impl Meshes {
    fn of(faces: &[TreeFace], centroids: &[DVec3]) -> Meshes {
        let mut first: std::collections::HashMap<CornerKey, usize> =
            std::collections::HashMap::new();
        let mut joined = penumbra_scenes::UnionFind::new(faces.len());
        for (i, f) in faces.iter().enumerate() {
            for &k in f.keys {
                let j = *first.entry(k).or_insert(i);
                joined.join(i, j);
            }
        }
        let mut id = std::collections::HashMap::new();
        let of: Vec<usize> = (0..faces.len())
            .map(|i| {
                let root = joined.find(i);
                let next = id.len();
                *id.entry(root).or_insert(next)
            })
            .collect();
        let mut sums = vec![(DVec3::ZERO, 0.0); id.len()];
        for (i, &m) in of.iter().enumerate() {
            sums[m].0 += centroids[i];
            sums[m].1 += 1.0;
        }
        let centroids = sums.into_iter().map(|(sum, n)| sum / n).collect();
        Meshes { of, centroids }
    }

    /// When `items` hold faces of several meshes: orders them by mesh, the meshes by their
    /// centroids along the widest axis, and returns the mesh boundary nearest the middle.
    fn split(&self, items: &mut [usize]) -> Option<usize> {
        let first = self.of[*items.first()?];
        if items.iter().all(|&i| self.of[i] == first) {
            return None;
        }
        let axis = widest_axis(items.iter().map(|&i| self.centroids[self.of[i]]));
        items.sort_unstable_by(|&a, &b| {
            let (m, n) = (self.of[a], self.of[b]);
            self.centroids[m][axis]
                .total_cmp(&self.centroids[n][axis])
                .then(m.cmp(&n))
                .then(a.cmp(&b))
        });
        let middle = items.len() / 2;
        (1..items.len())
            .filter(|&k| self.of[items[k]] != self.of[items[k - 1]])
            .min_by_key(|&k| k.abs_diff(middle))
    }
}

/// The least and greatest of `m . p` over the box `[min, max]`.
fn box_range(min: DVec3, max: DVec3, m: DVec3) -> (f64, f64) {
    let lo = DVec3::select(m.cmpge(DVec3::ZERO), min, max);
    let hi = DVec3::select(m.cmpge(DVec3::ZERO), max, min);
    (m.dot(lo), m.dot(hi))
}

impl Sheet {
    /// `Some(false)` when every face turns towards `point` by more than `margin`, `Some(true)`
    /// when every face turns away, `None` when the cone and the corners cannot tell.
    fn turns_away(&self, point: DVec3, margin: f64) -> Option<bool> {
        // Flat and nearly flat sheets: for a facing normal n and a corner v, n . (point - v) lies
        // within deviation * |point - v| of axis . (point - v).
        let (low, high) = self.heights;
        let along = self.axis.dot(point);
        let far = point.distance(self.center) + self.radius;
        let slack = self.deviation * far + margin;
        if along - high > slack {
            return Some(false);
        } else if low - along > slack {
            return Some(true);
        }
        // Curved nodes seen from afar: the direction to the point from anywhere in the sphere
        // is within asin(radius / distance) of the direction to its centre.
        let to_point = point - self.center;
        let distance = to_point.length();
        if distance <= self.radius {
            return None;
        }
        // The least of n . (point - v) is at least (distance - radius) cos(angle + blur), the
        // angle from the axis to the point, the blur the spread and asin(radius / distance);
        // with sums of angles by their cosines and sines, as this runs at every node.
        let cos_angle = (self.axis.dot(to_point) / distance).clamp(-1.0, 1.0);
        let sin_angle = (1.0 - cos_angle * cos_angle).max(0.0).sqrt();
        let r = self.radius / distance;
        let (cos_spread, sin_spread) = self.spread;
        let cos_r = (1.0 - r * r).max(0.0).sqrt();
        let cos_blur = cos_spread * cos_r - sin_spread * r;
        let sin_blur = sin_spread * cos_r + cos_spread * r;
        let least = |cos_angle: f64| {
            // Both angles lie in [0, π]: their sum reaches π where cos(blur) <= -cos(angle).
            let cos_sum = if cos_blur <= -cos_angle {
                -1.0
            } else {
                cos_angle * cos_blur - sin_angle * sin_blur
            };
            (distance - self.radius) * cos_sum
        };
        if least(cos_angle) > margin {
            Some(false)
        } else if least(-cos_angle) > margin {
            Some(true)
        } else {
            None
        }
    }
}

/// The sheet of a group of faces (`members`), or `None` when their facing normals spread over a
/// half space or more (they can never all turn one way) or their outline saves nothing.
fn sheet_of<'a>(
    faces: impl Iterator<Item = &'a TreeFace<'a>> + Clone,
    members: Members,
) -> Option<Sheet> {
    let axis = faces
        .clone()
        .map(|f| f.facing)
        .sum::<DVec3>()
        .try_normalize()?;
    let deviation = faces
        .clone()
        .map(|f| f.facing.distance(axis))
        .fold(0.0, f64::max);
    // At a right angle or more, no point sees all the faces turn one way.
    if deviation >= std::f64::consts::SQRT_2 {
        return None;
    }
    let spread = 2.0 * (deviation / 2.0).min(1.0).asin();
    let spread = (spread.cos(), spread.sin());
    let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for f in faces.clone() {
        for &p in f.polygon {
            min = min.min(p);
            max = max.max(p);
        }
    }
    let center = (min + max) / 2.0;
    let radius = (max - min).length() / 2.0;
    let heights = faces
        .clone()
        .flat_map(|f| f.polygon.iter().map(|&p| axis.dot(p)))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), h| {
            (lo.min(h), hi.max(h))
        });
    let mut edges = Vec::new();
    let mut count = 0;
    let mut closed = true;
    let mut area = 0.0;
    for f in faces {
        count += 1;
        closed &= f.closed;
        let n = f.polygon.len();
        // The listed order turns the face's own normal; the facing normal may be its opposite.
        let listed = newell_normal(f.polygon);
        area += listed.dot(axis).abs() / 2.0;
        let reversed = listed.dot(f.facing) < 0.0;
        for i in 0..n {
            let (a, b) = if reversed {
                ((i + 1) % n, i)
            } else {
                (i, (i + 1) % n)
            };
            if f.keys[a] != f.keys[b] {
                edges.push(OutlineEdge {
                    from: f.keys[a],
                    to: f.keys[b],
                    from_at: f.polygon[a],
                    to_at: f.polygon[b],
                });
            }
        }
    }
    let outline = straight_runs(&cancel_opposite(edges, |e| (e.from, e.to)));
    // An outline as long as the faces' own edges saves nothing.
    (outline.len() * 2 < count * 3).then_some(Sheet {
        axis,
        deviation,
        spread,
        center,
        radius,
        heights,
        area,
        closed,
        outline,
        faces: members,
    })
}

/// The faces of `members` in groups of one plane and facing each ([`GROUP_DEVIATION`]), in the
/// order of their first face; stops counting past [`MAX_GROUPS`].
fn plane_groups(faces: &[TreeFace], members: &[usize], centroids: &[DVec3]) -> Vec<Vec<usize>> {
    let mut groups: Vec<(DVec3, DVec3, Vec<usize>)> = Vec::new();
    let same_plane = |n: DVec3, c: DVec3, m: DVec3, d: DVec3| {
        let reach = c.length() + d.length() + c.distance(d);
        n.distance(m) <= GROUP_DEVIATION && m.dot(c - d).abs() <= GROUP_DEVIATION * reach
    };
    for &i in members {
        let (n, c) = (faces[i].facing, centroids[i]);
        match groups.iter().position(|&(m, d, _)| same_plane(n, c, m, d)) {
            Some(g) => groups[g].2.push(i),
            None if groups.len() > MAX_GROUPS => break,
            None => groups.push((n, c, vec![i])),
        }
    }
    groups.into_iter().map(|(_, _, g)| g).collect()
}

/// The outline with each straight run of edges through corners that no other outline edge
/// meets ([`COLLINEAR_SINE`]) made one edge, in a fixed order.
fn straight_runs(outline: &[OutlineEdge]) -> Vec<OutlineEdge> {
    use std::collections::HashMap;
    let mut leaving: HashMap<CornerKey, (usize, u32)> = HashMap::with_capacity(outline.len());
    let mut arriving: HashMap<CornerKey, u32> = HashMap::with_capacity(outline.len());
    for (k, e) in outline.iter().enumerate() {
        leaving.entry(e.from).or_insert((k, 0)).1 += 1;
        *arriving.entry(e.to).or_default() += 1;
    }
    let direction = |e: &OutlineEdge| (e.to_at - e.from_at).normalize_or_zero();
    // The edge that continues `e` straight on through a corner of no other edge.
    let next_straight = |e: &OutlineEdge| -> Option<usize> {
        let (k, out) = *leaving.get(&e.to)?;
        let inward = arriving.get(&e.to).copied().unwrap_or(0);
        let (d, f) = (direction(e), direction(&outline[k]));
        (out == 1 && inward == 1 && d.dot(f) > 0.0 && d.cross(f).length() < COLLINEAR_SINE)
            .then_some(k)
    };
    // Runs start at edges that no straight edge leads into.
    let continued: Vec<bool> = {
        let mut c = vec![false; outline.len()];
        for e in outline {
            if let Some(k) = next_straight(e) {
                c[k] = true;
            }
        }
        c
    };
    let mut used = vec![false; outline.len()];
    let mut runs = Vec::with_capacity(outline.len());
    let mut extend = |start: usize, used: &mut Vec<bool>| {
        let mut run = outline[start];
        used[start] = true;
        while let Some(k) = next_straight(&run).filter(|&k| !used[k]) {
            used[k] = true;
            run.to = outline[k].to;
            run.to_at = outline[k].to_at;
        }
        runs.push(run);
    };
    for start in 0..outline.len() {
        if !continued[start] && !used[start] {
            extend(start, &mut used);
        }
    }
    // Loops that are straight all round do not close; what is left are such loops' edges.
    for start in 0..outline.len() {
        if !used[start] {
            extend(start, &mut used);
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A welded n x n grid of unit squares at height z, each split into two triangles listed
    /// counter-clockwise from above.
    fn grid(n: u32, z: f64) -> (Vec<Vec<DVec3>>, Vec<Vec<CornerKey>>) {
        let corner = |i: u32, j: u32| {
            (
                i * (n + 1) + j,
                DVec3::new(i as f64 - n as f64 / 2.0, j as f64 - n as f64 / 2.0, z),
            )
        };
        let (mut polygons, mut keys) = (Vec::new(), Vec::new());
        for i in 0..n {
            for j in 0..n {
                let c = [
                    corner(i, j),
                    corner(i + 1, j),
                    corner(i + 1, j + 1),
                    corner(i, j + 1),
                ];
                for t in [[c[0], c[1], c[2]], [c[0], c[2], c[3]]] {
                    polygons.push(t.iter().map(|c| c.1).collect());
                    keys.push(t.iter().map(|c| c.0).collect());
                }
            }
        }
        (polygons, keys)
    }

    fn walk(
        tree: &OccluderTree,
        point: DVec3,
        sides: &[DVec3],
    ) -> (Vec<usize>, Vec<(usize, bool)>) {
        let (mut faces, mut outlines) = (Vec::new(), Vec::new());
        tree.walk(
            &ShaftTest {
                point,
                sides,
                emitter_origin: DVec3::new(0.0, 0.0, 10.0),
                emitter_normal: -DVec3::Z,
                lowest: 1e-9,
                highest: 9.0,
                margin: 1e-9,
            },
            &mut |r| match r {
                Reached::Face(i) => faces.push(i),
                Reached::Outline { sheet, reversed } => outlines.push((sheet, reversed)),
            },
        );
        (faces, outlines)
    }

    /// The faces of a grid, all facing one way.
    fn tree_faces<'a>(
        polygons: &'a [Vec<DVec3>],
        keys: &'a [Vec<CornerKey>],
        facing: DVec3,
        closed: bool,
    ) -> Vec<TreeFace<'a>> {
        polygons
            .iter()
            .zip(keys)
            .map(|(polygon, keys)| TreeFace {
                polygon,
                keys,
                facing,
                closed,
            })
            .collect()
    }

    /// Under an emitter at z = 10, a point below a 16 x 16 sheet at z = 5 meets the sheet as one
    /// outline: its rim, the inner edges cancelled and the rim's 64 steps made its 4 sides.
    #[test]
    fn a_sheet_facing_the_point_is_one_outline() {
        let (polygons, keys) = grid(16, 5.0);
        for (facing, closed, expect_reversed) in
            [(-DVec3::Z, false, false), (DVec3::Z, false, true)]
        {
            let faces = tree_faces(&polygons, &keys, facing, closed);
            let tree = OccluderTree::build(&faces);
            // A shaft with no side planes holds everything between the planes.
            let (loose, outlines) = walk(&tree, DVec3::ZERO, &[]);
            assert!(loose.is_empty(), "{loose:?}");
            assert_eq!(outlines.len(), 1);
            let (node, reversed) = outlines[0];
            assert_eq!(reversed, expect_reversed);
            assert_eq!(tree.outline(node).len(), 4);
            for e in tree.outline(node) {
                assert_eq!((e.to_at - e.from_at).length(), 16.0, "{e:?}");
            }
            assert_eq!(tree.faces_of(node).len(), 512);
            // The rim turns counter-clockwise around +z in the facing order.
            let turn: f64 = tree
                .outline(node)
                .iter()
                .map(|e| e.from_at.x * e.to_at.y - e.to_at.x * e.from_at.y)
                .sum();
            assert!(if facing.z > 0.0 {
                turn > 0.0
            } else {
                turn < 0.0
            });
        }
    }

    /// Faces through the point, closed solids turned away, and nodes outside the shaft.
    #[test]
    fn the_walk_skips_what_cannot_cast_and_opens_what_it_cannot_decide() {
        let (polygons, keys) = grid(16, 5.0);
        let faces = tree_faces(&polygons, &keys, DVec3::Z, true);
        let tree = OccluderTree::build(&faces);
        // Below the sheet, a closed solid's faces turned away cast nothing.
        let (loose, outlines) = walk(&tree, DVec3::ZERO, &[]);
        assert!(loose.is_empty() && outlines.is_empty());
        // In the sheet's plane no face turns either way: every face is examined on its own.
        let (loose, outlines) = walk(&tree, DVec3::new(0.1, 0.2, 5.0), &[]);
        assert_eq!((loose.len(), outlines.len()), (512, 0));
        // A shaft leaning to x > 20 misses the sheet altogether.
        let (loose, outlines) = walk(&tree, DVec3::new(20.0, 0.0, 0.0), &[DVec3::X]);
        assert!(loose.is_empty() && outlines.is_empty());
    }

    /// A finely tessellated bowl (the lower half of a sphere, faces turned to its centre) seen
    /// from a point inside it close to its bottom: the cones of the nodes near the point cannot
    /// tell which way their faces turn, yet every face turns towards the point (it lies inside
    /// a convex shape), and small nodes are decided face by face as outlines.
    #[test]
    fn small_nodes_the_cone_cannot_decide_are_decided_face_by_face() {
        let (center, radius) = (DVec3::new(0.0, 0.0, 5.0), 2.0);
        let (rings, around) = (16u32, 32u32);
        let key = |i: u32, j: u32| {
            if i == 0 {
                0
            } else {
                1 + (i - 1) * around + j % around
            }
        };
        let corner = |i: u32, j: u32| {
            let (polar, azimuth) = (
                f64::from(i) / f64::from(rings) * std::f64::consts::FRAC_PI_2,
                f64::from(j % around) / f64::from(around) * 2.0 * PI,
            );
            center
                + radius
                    * DVec3::new(
                        polar.sin() * azimuth.cos(),
                        polar.sin() * azimuth.sin(),
                        -polar.cos(),
                    )
        };
        let (mut polygons, mut keys) = (Vec::new(), Vec::new());
        for i in 0..rings {
            for j in 0..around {
                let mut triangles = vec![[(i + 1, j), (i + 1, j + 1), (i, j)]];
                if i > 0 {
                    triangles.push([(i, j), (i + 1, j + 1), (i, j + 1)]);
                }
                for t in triangles {
                    polygons.push(t.iter().map(|&(a, b)| corner(a, b)).collect::<Vec<_>>());
                    keys.push(t.iter().map(|&(a, b)| key(a, b)).collect::<Vec<_>>());
                }
            }
        }
        let faces: Vec<TreeFace> = polygons
            .iter()
            .zip(&keys)
            .map(|(polygon, keys)| {
                let normal = newell_normal(polygon).normalize();
                let inward = (center - polygon[0]).dot(normal).signum();
                TreeFace {
                    polygon,
                    keys,
                    facing: normal * inward,
                    closed: false,
                }
            })
            .collect();
        let tree = OccluderTree::build(&faces);
        let point = center - DVec3::new(0.05, 0.0, 0.95 * radius);
        let (loose, outlines) = walk(&tree, point, &[]);
        assert!(loose.is_empty(), "{} faces on their own", loose.len());
        assert!(outlines.iter().all(|&(_, reversed)| !reversed));
        let covered: usize = outlines.iter().map(|&(s, _)| tree.faces_of(s).len()).sum();
        assert_eq!(covered, faces.len());
    }
}
