//! Many shadows at once: the part of an emitter piece that no shadow covers, by one polygon
//! difference instead of subtracting the shadows one by one (which splits the visible region
//! into as many convex pieces as the shadows have edges, and costs their product).
//!
//! The difference is computed by Clipper2's C++ engine (`penumbra-overlay`) on an integer grid of
//! up to 2⁴⁰ steps across the overlay's extent: a point moves by at most 2⁻⁴⁰ of that extent, and
//! the result's area is exact to that scale. Clipper2 stays fast where edges of different shadows
//! run a few rounding steps apart (shadows of faces sharing an edge, clipped in different ways),
//! which made an earlier engine split segments without end; but it decides the order of such edges
//! in f64 and now and then turns part of its result inside out, or reports that it failed. Each
//! result is checked ([`Grid::consistent_shapes`]) and, where it contradicts itself or failed,
//! computed again on another grid. Shadows are cut only to an axis-aligned box around the region
//! they are subtracted from, never to the region itself: that laid their edges along its slanted
//! sides, collinear with its own edges but for rounding, and made such failures ten times as common
//! (one Sponza vertex in 2,000 was off, by up to 4 % of its light). Degenerate parts may come back
//! as an outline with a reversed copy of it beside it (not inside it): consumers count each contour
//! with the sign of its turn.
//!
//! Shadows of occluder faces lying wholly inside the shaft are fused before the overlay: each is
//! a polygon of the face's own vertices, projected, so the faces of a welded mesh share their
//! projected corners exactly and every inner edge appears once in each direction. Those pairs
//! cancel, and what reaches the overlay is the outline of each connected sheet of faces — its
//! silhouette from the receiving point — however finely the mesh is tessellated.

use std::time::Instant;

use glam::DVec2;

use crate::clip::{bounds_2d, clip_to_box, convex_hull_2d};
pub(crate) use crate::sheet_outline::CornerKey;
use crate::sheet_outline::{Loops, SheetEdge, outlines};
use penumbra_overlay::{Engine, Path64, Point64, PolyTree64};
use penumbra_scenes::polygon::signed_area_2d;

/// Shadows go into one overlay until they have this many edges; the next batch is subtracted
/// from what the last left visible, so no overlay holds the many overlapping shadows of a large
/// light seen through a building at once, and a piece covered early is done.
const BATCH_EDGES: usize = 1024;

/// The first batch holds the largest shadows up to this many edges, and each batch may hold
/// twice as many as the last: the largest shadows often hide most of the piece, and the hull of
/// what they leave bounds what every later shadow can still hide, so later shadows shrink or
/// drop out before they reach an overlay.
const FIRST_BATCH_EDGES: usize = 16;

/// The shadows cast on one emitter piece from one receiving point.
#[derive(Debug, Default)]
pub(crate) struct ShadowUnion {
    /// Edges of faces wholly inside the shaft, oriented counter-clockwise.
    sheet: Vec<SheetEdge>,
    /// Other shadows (clipped to the shaft), counter-clockwise.
    contours: Vec<Vec<DVec2>>,
    /// Corners of one sheet that no edge joins: the loops of one fused outline (its rim and
    /// its holes).
    links: Vec<(CornerKey, CornerKey)>,
}

/// A visible part of an emitter piece: an outline (counter-clockwise) and its holes (clockwise).
pub(crate) type VisibleShape = Vec<Vec<DVec2>>;

impl ShadowUnion {
    /// Room for this many sheet edges.
    pub(crate) fn with_capacity(edges: usize) -> Self {
        ShadowUnion {
            sheet: Vec::with_capacity(edges),
            contours: Vec::new(),
            links: Vec::new(),
        }
    }

    /// Adds the shadow of a face wholly inside the shaft: its corners' keys and projections.
    pub(crate) fn add_face(&mut self, keys: &[CornerKey], corners: &[DVec2]) {
        let n = corners.len();
        let reversed = signed_area_2d(corners) < 0.0;
        for i in 0..n {
            let (a, b) = if reversed {
                (n - 1 - i, (2 * n - 2 - i) % n)
            } else {
                (i, (i + 1) % n)
            };
            if keys[a] != keys[b] {
                self.sheet.push(SheetEdge {
                    from: keys[a],
                    to: keys[b],
                    at: corners[a],
                });
            }
        }
    }

    /// Adds edges of shadows already fused (a node's outline): corner keys, and the projection
    /// of the first corner. They are one shadow: a rim and the holes in it have no edge between
    /// them, and the rim alone would cover the holes.
    pub(crate) fn add_edges(&mut self, edges: &[(CornerKey, CornerKey, DVec2)]) {
        self.sheet.extend(
            edges
                .iter()
                .map(|&(from, to, at)| SheetEdge { from, to, at }),
        );
        if let Some(&(first, _, _)) = edges.first() {
            self.links
                .extend(edges.iter().map(|&(from, _, _)| (first, from)));
        }
    }

    /// Adds a shadow given as a counter-clockwise contour.
    pub(crate) fn add_contour(&mut self, contour: Vec<DVec2>) {
        self.contours.push(contour);
    }

    /// `piece` (convex, counter-clockwise) minus every shadow, unless the overlay cannot
    /// represent the coordinates (not finite) or the work goes past `limit`.
    pub(crate) fn subtract_from(
        self,
        piece: &[DVec2],
        limit: &OverlayLimit,
    ) -> Result<Vec<VisibleShape>, Refusal> {
        self.subtract_within(vec![vec![piece.to_vec()]], piece, limit)
    }

    /// `start` (shapes lying in the convex `bound`) minus every shadow, as
    /// [`Self::subtract_from`].
    pub(crate) fn subtract_within(
        self,
        start: Vec<VisibleShape>,
        bound: &[DVec2],
        limit: &OverlayLimit,
    ) -> Result<Vec<VisibleShape>, Refusal> {
        let mut shadows: Vec<Shadow> = self.contours.into_iter().map(|c| vec![c]).collect();
        shadows.extend(outlines(&self.sheet, &self.links).ok_or(Refusal::NotFinite)?);
        if !bound
            .iter()
            .chain(visible_points(&start))
            .chain(shadows.iter().flatten().flatten())
            .all(|p| p.is_finite())
        {
            return Err(Refusal::NotFinite);
        }
        // Only shadows reaching the bound matter to the difference; the largest go first: where
        // they cover what is visible, the rest is never looked at.
        let mut shadows = largest_first(reaching(shadows, bound));
        let mut visible = start;
        let mut batch_edges = FIRST_BATCH_EDGES;
        while !shadows.is_empty() {
            if limit.deadline.is_some_and(|d| Instant::now() >= d) {
                return Err(Refusal::TooComplex);
            }
            let edges_of = |s: &Shadow| s.iter().map(Vec::len).sum::<usize>();
            let mut taken = 1;
            let mut edges = edges_of(&shadows[0]);
            while taken < shadows.len() && edges + edges_of(&shadows[taken]) <= batch_edges {
                edges += edges_of(&shadows[taken]);
                taken += 1;
            }
            let later = shadows.split_off(taken);
            let batch: Vec<Vec<DVec2>> = shadows.into_iter().flatten().collect();
            visible = difference(&visible, &batch, limit.edges)?;
            if visible.is_empty() {
                break;
            }
            // What is left visible lies in its hull: only the later shadows reaching it matter.
            let hull = convex_hull_2d(visible_points(&visible).copied().collect());
            shadows = reaching(later, &hull);
            batch_edges = (batch_edges * 2).min(BATCH_EDGES);
        }
        Ok(visible)
    }
}

/// Every corner of the shapes.
pub(crate) fn visible_points(shapes: &[VisibleShape]) -> impl Iterator<Item = &DVec2> {
    shapes.iter().flatten().flatten()
}

/// One shadow as closed loops whose winding numbers add up to its coverage, never below zero:
/// a convex shadow, or a connected sheet's outline with its holes (only together are they a
/// shadow; the outline alone would cover the holes).
type Shadow = Loops;

/// The shadows by area, largest first (ties in their given order).
fn largest_first(mut shadows: Vec<Shadow>) -> Vec<Shadow> {
    let area = |s: &Shadow| s.iter().map(|c| signed_area_2d(c)).sum::<f64>();
    let mut ranked: Vec<(f64, Shadow)> = shadows.drain(..).map(|s| (area(&s), s)).collect();
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0));
    ranked.into_iter().map(|(_, s)| s).collect()
}

/// The shadows cut to a box around the region: its bounding box widened by [`BOX_MARGIN`] of its
/// size on each side. Shadows left without a loop are dropped. The box's sides are axis-aligned
/// and lie off the region, so the cut edges are exactly collinear with each other on the grid and
/// meet none of the region's edges.
fn reaching(shadows: Vec<Shadow>, region: &[DVec2]) -> Vec<Shadow> {
    let (lo, hi) = bounds_2d(region);
    let margin = BOX_MARGIN * (hi - lo);
    let (lo, hi) = (lo - margin, hi + margin);
    shadows
        .into_iter()
        .map(|s| {
            s.into_iter()
                .filter_map(|c| clip_to_box(c, lo, hi))
                .collect::<Shadow>()
        })
        .filter(|s| !s.is_empty())
        .collect()
}

/// How far beyond the region's bounding box shadows are cut, as a share of its size: far enough
/// that the cuts stay clear of the region's edges on the grid, near enough that little of each
/// shadow is left outside (an eighth cost 20,000 Sponza points 12 % more time).
const BOX_MARGIN: f64 = 1.0 / 64.0;

/// How far one subtraction may go: edges in one overlay, and a moment after which no new batch
/// starts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct OverlayLimit {
    pub edges: usize,
    pub deadline: Option<Instant>,
}

impl OverlayLimit {
    pub(crate) const NONE: OverlayLimit = OverlayLimit {
        edges: usize::MAX,
        deadline: None,
    };
}

/// Why a difference was not computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Refusal {
    /// A coordinate is not finite.
    NotFinite,
    /// The overlay would hold more edges than allowed (the light seen through a lattice), or
    /// the deadline passed.
    TooComplex,
    /// The overlay contradicted itself on every grid tried ([`GRID_STEPS`]).
    Inconsistent,
}

/// What of the shapes `visible` (outlines counter-clockwise, holes clockwise) no contour covers
/// (non-zero winding), on Clipper2's integer grid over their common bounding box.
fn difference(
    visible: &[VisibleShape],
    contours: &[Vec<DVec2>],
    cap: usize,
) -> Result<Vec<VisibleShape>, Refusal> {
    let subject = visible.iter().flatten();
    let edges: usize = subject.clone().chain(contours.iter()).map(Vec::len).sum();
    if edges > cap {
        return Err(Refusal::TooComplex);
    }
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for p in subject.clone().chain(contours.iter()).flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let extent = (hi - lo).max_element();
    if !(lo.is_finite() && extent.is_finite()) {
        return Err(Refusal::NotFinite);
    }
    if extent == 0.0 {
        return Ok(Vec::new());
    }
    let subject: Vec<&Vec<DVec2>> = subject.collect();
    GRID_STEPS
        .iter()
        .find_map(|&steps| {
            // A power of two: corners on a binary fraction of the extent map to the grid exactly.
            let grid = Grid {
                origin: lo,
                scale: (steps / extent).log2().floor().exp2(),
            };
            grid.difference(&subject, contours)
        })
        .ok_or(Refusal::Inconsistent)
}

/// Twice the signed area of a path on the grid (exact, then rounded), and the most that moving
/// each corner by its rounding to the grid (half a step each way) can change it: the perimeter
/// times √2.
fn doubled_area(path: &Path64) -> (f64, f64) {
    let n = path.len();
    let (mut area, mut perimeter) = (0i128, 0.0);
    for i in 0..n {
        let (p, q) = (path[i], path[(i + 1) % n]);
        area += i128::from(p.x) * i128::from(q.y) - i128::from(q.x) * i128::from(p.y);
        perimeter += ((q.x - p.x) as f64).hypot((q.y - p.y) as f64);
    }
    (area as f64, std::f64::consts::SQRT_2 * perimeter)
}

thread_local! {
    static CLIPPER: std::cell::RefCell<Engine> = std::cell::RefCell::new(Engine::new());
}

/// The overlay's coordinates span up to this many integer steps (the largest power of two of a
/// step below extent / steps), tried in turn until the result is consistent: the finest moves a
/// point by at most 2⁻⁴⁰ of the overlay's extent, far below the evaluator's tolerance, and each
/// other rounds the same edges differently. (At 20,000 Sponza points, 33 overlays contradicted
/// themselves on the first grid: 2 were consistent on the second, 31 on none, and their points
/// fell back to the whole shaft or to one-by-one subtraction.)
const GRID_STEPS: [f64; 3] = [
    (1u64 << 40) as f64,
    (1u64 << 36) as f64,
    (1u64 << 32) as f64,
];

/// The map from the emitter's 2D frame to the overlay's integer grid.
struct Grid {
    origin: DVec2,
    scale: f64,
}

impl Grid {
    /// What of `subject` no contour covers, on this grid, if the overlay succeeds and is
    /// consistent ([`Self::consistent_shapes`]).
    fn difference(
        &self,
        subject: &[&Vec<DVec2>],
        contours: &[Vec<DVec2>],
    ) -> Option<Vec<VisibleShape>> {
        let subject: Vec<Path64> = subject.iter().map(|c| self.path(c)).collect();
        let clip: Vec<Path64> = contours.iter().map(|c| self.path(c)).collect();
        // One engine per thread: it keeps its working memory.
        let tree = CLIPPER.with_borrow_mut(|clipper| clipper.difference(&subject, &clip))?;
        self.consistent_shapes(&tree, &subject)
    }

    fn path(&self, contour: &[DVec2]) -> Path64 {
        contour
            .iter()
            .map(|&p| {
                let q = ((p - self.origin) * self.scale).round();
                Point64 {
                    x: q.x as i64,
                    y: q.y as i64,
                }
            })
            .collect()
    }

    fn contour(&self, path: &Path64) -> Vec<DVec2> {
        path.iter()
            .map(|p| self.origin + DVec2::new(p.x as f64, p.y as f64) / self.scale)
            .collect()
    }

    /// The tree's outlines (even depth below the root), each with its holes; `None` when the
    /// tree contradicts itself: an outline turned clockwise or a hole counter-clockwise by more
    /// than the rounding of its corners can turn it, or more area left than `subject` had.
    fn consistent_shapes(
        &self,
        tree: &PolyTree64,
        subject: &[Path64],
    ) -> Option<Vec<VisibleShape>> {
        let (mut left, mut slack) = (0.0, 0.0);
        let mut turned = |path: &Path64, outline: bool| {
            let (area, rounding) = doubled_area(path);
            left += area;
            slack += rounding;
            (area > 0.0) == outline || area.abs() <= rounding
        };
        let mut shapes = Vec::new();
        let mut outlines: Vec<usize> = tree.root().children.clone();
        while let Some(outline) = outlines.pop() {
            let node = &tree.nodes[outline];
            if !turned(&node.polygon, true) {
                return None;
            }
            let mut shape = vec![self.contour(&node.polygon)];
            for &hole in &node.children {
                if !turned(&tree.nodes[hole].polygon, false) {
                    return None;
                }
                shape.push(self.contour(&tree.nodes[hole].polygon));
                outlines.extend_from_slice(&tree.nodes[hole].children);
            }
            shapes.push(shape);
        }
        let (had, had_slack) = subject
            .iter()
            .map(doubled_area)
            .fold((0.0, 0.0), |(a, s), (b, t)| (a + b, s + t));
        (left <= had + slack + had_slack).then_some(shapes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sheet_outline::cancel_opposite;

    fn key(i: u32) -> CornerKey {
        i
    }

    fn area(shapes: &[VisibleShape]) -> f64 {
        shapes.iter().flatten().map(|c| signed_area_2d(c)).sum()
    }

    /// The cells of an n x n grid of squares of side `step` that `keep` keeps, each as two
    /// triangles with welded corners, the second listed clockwise on purpose (faces are oriented
    /// by their projection).
    fn welded_grid(n: u32, step: f64, keep: impl Fn(u32, u32) -> bool) -> ShadowUnion {
        let corner = |i: u32, j: u32| (key((n + 1) * i + j), DVec2::new(i as f64, j as f64) * step);
        let mut union = ShadowUnion::default();
        for i in 0..n {
            for j in (0..n).filter(|&j| keep(i, j)) {
                let (a, b, c, d) = (
                    corner(i, j),
                    corner(i + 1, j),
                    corner(i + 1, j + 1),
                    corner(i, j + 1),
                );
                union.add_face(&[a.0, b.0, c.0], &[a.1, b.1, c.1]);
                union.add_face(&[a.0, d.0, c.0], &[a.1, d.1, c.1]);
            }
        }
        union
    }

    /// A 4 x 4 grid of corners, split into 18 triangles (some listed clockwise): the sheet's
    /// inner edges cancel and its outline is the grid's square.
    #[test]
    fn a_welded_sheet_fuses_into_its_outline() {
        let union = welded_grid(3, 0.25, |_, _| true);
        let loops = outlines(&union.sheet, &[]).expect("closes");
        assert_eq!(loops.len(), 1);
        assert_eq!(loops[0].len(), 1, "one loop");
        assert_eq!(loops[0][0].len(), 12, "the outline's corners");
        let visible = union
            .subtract_from(&crate::clip::sq(-0.5, -0.5, 2.0), &OverlayLimit::NONE)
            .expect("finite");
        assert!((area(&visible) - (4.0 - 0.5625)).abs() < 1e-15);
    }

    /// A ring of faces (4 x 4 cells without the middle 2 x 2) is one shadow of two loops: its
    /// outline (16 edges, a batch of its own) and its hole. The hole stays visible, around the
    /// ring too.
    /// A ring of faces: 4 x 4 unit cells without the middle 2 x 2.
    fn ring() -> ShadowUnion {
        let middle = |i: u32| (1..3).contains(&i);
        welded_grid(4, 1.0, |i, j| !(middle(i) && middle(j)))
    }

    /// A 5 x 5 piece around the ring: what is left is its rim and the ring's hole.
    fn sees_around_and_through_the_ring(union: ShadowUnion) {
        let visible = union
            .subtract_from(&crate::clip::sq(-0.5, -0.5, 5.0), &OverlayLimit::NONE)
            .expect("finite");
        assert!(
            (area(&visible) - (25.0 - 16.0 + 4.0)).abs() < 1e-12,
            "{}",
            area(&visible)
        );
    }

    #[test]
    fn a_sheet_with_a_hole_keeps_its_hole() {
        let union = ring();
        let shadows = outlines(&union.sheet, &[]).expect("closes");
        assert_eq!(shadows.len(), 1);
        let mut loops: Vec<usize> = shadows[0].iter().map(Vec::len).collect();
        loops.sort_unstable();
        assert_eq!(loops, [8, 16]);
        const { assert!(16 <= FIRST_BATCH_EDGES && 16 + 8 > FIRST_BATCH_EDGES) };
        sees_around_and_through_the_ring(union);
    }

    /// The same ring given as a node's outline, already fused (`add_edges`: its two loops, with
    /// no inner edge joining them), still keeps its hole.
    #[test]
    fn a_fused_outline_keeps_its_hole() {
        let fused: Vec<(CornerKey, CornerKey, DVec2)> =
            cancel_opposite(ring().sheet, |e| (e.from, e.to))
                .into_iter()
                .map(|e| (e.from, e.to, e.at))
                .collect();
        assert_eq!(fused.len(), 24);
        let mut union = ShadowUnion::default();
        union.add_edges(&fused);
        sees_around_and_through_the_ring(union);
    }

    /// Overlapping shadows count once; a shadow reaching past the piece removes only what it
    /// covers; a hole is counted negative.
    #[test]
    fn overlapping_shadows_are_counted_once() {
        let mut union = ShadowUnion::default();
        union.add_contour(crate::clip::sq(0.0, 0.0, 1.0));
        union.add_contour(crate::clip::sq(0.5, 0.5, 1.0));
        union.add_contour(crate::clip::sq(3.5, 3.5, 1.0));
        let visible = union
            .subtract_from(&crate::clip::sq(-1.0, -1.0, 5.0), &OverlayLimit::NONE)
            .expect("finite");
        assert!((area(&visible) - (25.0 - 1.75 - 0.25)).abs() < 1e-13);
        assert_eq!(visible.len(), 1);
        assert_eq!(visible[0].len(), 2, "one outline with one hole");
        assert!(signed_area_2d(&visible[0][1]) < 0.0);
    }

    /// 600 squares overlapping in a row, more edges than one batch: the union is counted once,
    /// and a shadow covering the whole piece ends the work with nothing visible.
    #[test]
    fn shadows_in_batches_are_counted_once() {
        let row = |union: &mut ShadowUnion| {
            for i in 0..600 {
                union.add_contour(crate::clip::sq(i as f64 * 1e-3, 0.0, 1.0));
            }
        };
        const { assert!(600 * 4 > BATCH_EDGES) };
        let mut union = ShadowUnion::default();
        row(&mut union);
        let piece = [
            DVec2::new(-1.0, -1.0),
            DVec2::new(3.0, -1.0),
            DVec2::new(3.0, 2.0),
            DVec2::new(-1.0, 2.0),
        ];
        let visible = union
            .subtract_from(&piece, &OverlayLimit::NONE)
            .expect("finite");
        // The squares' corners (steps of 10⁻³) round to the grid, 2⁻³⁹ of the extent apart.
        assert!(
            (area(&visible) - (12.0 - 1.599)).abs() < 1e-11,
            "{}",
            area(&visible)
        );
        let mut union = ShadowUnion::default();
        row(&mut union);
        union.add_contour(crate::clip::sq(-2.0, -2.0, 6.0));
        assert!(
            union
                .subtract_from(&piece, &OverlayLimit::NONE)
                .expect("finite")
                .is_empty()
        );
    }

    /// Shadows whose edges run along the visible part's boundary and each other's, a few
    /// rounding steps apart, over a long thin strip (a skylight seen past a building's columns):
    /// the difference ends, leaving at most slivers of rounding.
    #[test]
    fn near_coincident_edges_leave_only_slivers() {
        let contour = |points: &[(f64, f64)]| -> Vec<DVec2> {
            points.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
        };
        let visible = contour(&[
            (2697.558219049137, 181.75455066166384),
            (2697.558198938187, 159.51664636911843),
            (2700.0, 155.27053673715562),
            (2700.0, 353.25297372802504),
            (2697.5583741041773, 353.20837551740226),
            (2697.5583632272296, 341.1810703046049),
            (2698.1199147430007, 340.530104253751),
            (2698.1199147430007, 329.66225387933),
            (2697.558352467968, 329.2838973425173),
            (2697.558336472492, 311.596723778614),
            (2697.938227690648, 311.160690001679),
            (2697.938227690648, 300.40801645498436),
            (2697.5583261437196, 300.17556928806744),
            (2697.5583094135523, 281.67600192284544),
            (2698.483460228885, 280.4778546062936),
            (2698.483460228885, 269.385254414163),
            (2697.5582977081995, 268.73267888733153),
            (2697.5582804093474, 249.60428188744584),
            (2698.239887558188, 248.73983749626697),
            (2698.239887558188, 237.79179472254785),
            (2697.5582693424335, 237.3669195140156),
            (2697.558253658899, 220.02467839590184),
            (2697.5954969478444, 219.98121618589263),
            (2697.5954969478444, 209.45645105016817),
            (2697.558244085558, 209.4388503065141),
            (2697.558229375688, 193.17324917392767),
            (2697.701708180257, 193.0001760463979),
            (2698.1576254308693, 182.0881804708936),
        ]);
        let shadows: Vec<Vec<DVec2>> = <[&[(f64, f64)]; 5]>::into_iter([
            &[
                (2697.558061457804, 7.496192302734678),
                (2697.9382276906476, 1.4465813205048114e-13),
                (2697.938227690648, -1.9721522630525295e-31),
                (2700.0, 0.0),
                (2700.0, 353.252973728025),
                (2697.5583741041773, 353.2083755174022),
                (2697.55821778099, 180.35228391007746),
            ],
            &[
                (2697.558061457804, 7.496192302734537),
                (2697.9382276906476, 2.182045862049462e-16),
                (2699.9999999999995, 0.0),
                (2699.9999999999995, 353.25297372802504),
                (2697.5583741041773, 353.20837551740226),
                (2697.55821778099, 180.35228391007743),
            ],
            &[
                (2697.5583225791943, 296.23405611561196),
                (2699.999999999999, 293.8537355251633),
                (2700.0, 353.25297372802504),
                (2697.5583741041773, 353.20837551740226),
            ],
            &[
                (2697.558353787013, 330.74244645965524),
                (2700.0, 330.4216235106225),
                (2700.0, 353.25297372802504),
                (2697.5583741041773, 353.20837551740226),
            ],
            &[
                (2699.999999999999, 341.70710438758965),
                (2697.5583640815794, 342.12577735264705),
                (2697.55836328242, 341.2420976610666),
                (2700.0, 340.7877655701691),
                (2700.0, 341.24743497887926),
            ],
        ])
        .map(contour)
        .collect();
        let visible_area = signed_area_2d(&visible);
        let left = difference(&[vec![visible]], &shadows, usize::MAX).expect("finite");
        assert!(area(&left).abs() < 1e-12 * visible_area, "{}", area(&left));
    }

    /// A triangle of what is still visible under three shadows, two of which share an edge whose
    /// ends differ by a few ulps (faces meeting along it, clipped in different ways). On a grid
    /// of 2⁴⁸ steps Clipper2 turned the covered part inside out: a clockwise outline of 24 units
    /// of area, where the light is hidden. The overlay now finds the contradiction and agrees
    /// with subtracting the shadows one convex polygon at a time.
    #[test]
    fn an_overlay_that_contradicts_itself_is_done_again() {
        let points =
            |c: &[(f64, f64)]| -> Vec<DVec2> { c.iter().map(|&(x, y)| DVec2::new(x, y)).collect() };
        let visible = points(&[
            (21.228825602822983, 4.308886667304591),
            (2.0798910223790186, 6.560696327940965),
            (2.079889304468443, 4.0686583335213165),
        ]);
        let shadows = [
            points(&[
                (21.228825602822948, 4.30888666730462),
                (2.079890945616742, 6.449343320036245),
                (2.079889304468443, 4.068658333263629),
            ]),
            points(&[
                (2.079890945616742, 6.449343320036388),
                (21.228825602822948, 4.30888666730462),
                (21.408083983158697, 5.88097655497981),
            ]),
            points(&[
                (20.433565374846392, 3.143510689687226),
                (21.228825602822948, 4.30888666730462),
                (8.8383270224911, 1.8362301763940962),
            ]),
            // Far off: it sets the overlay's extent, and so the grid.
            points(&[
                (23.68566710068245, 2.3112541290972226),
                (23.700334010508044, 1.8149305644500995),
                (23.89285711094045, 1.8149305822433863),
            ]),
        ];
        let counter_clockwise = |mut c: Vec<DVec2>| {
            if signed_area_2d(&c) < 0.0 {
                c.reverse();
            }
            c
        };
        let mut convex = vec![counter_clockwise(visible.clone())];
        for shadow in &shadows {
            let shadow = counter_clockwise(shadow.clone());
            let mut next = Vec::new();
            for piece in &convex {
                crate::clip::subtract_convex(piece, &shadow, 0.0, &mut next);
            }
            convex = next;
        }
        let expected: f64 = convex.iter().map(|c| signed_area_2d(c)).sum();
        // The grid that failed: the check finds it out.
        let all: Vec<DVec2> = shadows
            .iter()
            .chain([&visible])
            .flatten()
            .copied()
            .collect();
        let (lo, hi) = bounds_2d(&all);
        let finest = Grid {
            origin: lo,
            scale: (1u64 << 48) as f64 / (hi - lo).max_element(),
        };
        assert!(finest.difference(&[&visible], &shadows).is_none());
        let left = difference(&[vec![visible]], &shadows, usize::MAX).expect("consistent");
        assert!(
            (area(&left) - expected).abs() < 1e-9,
            "{} against {expected}",
            area(&left)
        );
    }

    #[test]
    fn non_finite_shadows_are_refused() {
        let mut union = ShadowUnion::default();
        union.add_contour(vec![DVec2::ZERO, DVec2::X, DVec2::new(f64::NAN, 1.0)]);
        assert!(
            union.subtract_from(&crate::clip::sq(0.0, 0.0, 1.0), &OverlayLimit::NONE)
                == Err(Refusal::NotFinite)
        );
    }
}
