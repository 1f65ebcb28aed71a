//! Coincident critical lines merged into one: in the parallel case the EV wedges of both ends of a
//! blocker edge and the VE wedges of its emitter vertices all lie in one plane.

use std::collections::{BTreeMap, HashMap};

use glam::DVec2;
use penumbra_scenes::UnionFind;

/// A segment on a receiver in its plane-frame coordinates, with what generated it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct FlatSegment<T> {
    pub from: DVec2,
    pub to: DVec2,
    pub tag: T,
}

/// Merges segments that lie on one line (every endpoint of each within `tol` of the other's line)
/// and overlap or touch (within `tol`) into their union. Where segments overlap their tags
/// combine with `combine`; neighbouring pieces of the union join when `joins` says their tags
/// may (their tags combining too), and stay apart otherwise. The result is in a deterministic
/// order.
pub(super) fn merge_collinear<T: Copy>(
    segments: &[FlatSegment<T>],
    tol: f64,
    combine: impl Fn(T, T) -> T,
    joins: impl Fn(&T, &T) -> bool,
) -> Vec<FlatSegment<T>> {
    let segments: Vec<&FlatSegment<T>> = segments
        .iter()
        .filter(|s| s.from.distance(s.to) > tol)
        .collect();
    let mut out = Vec::new();
    for (root, members) in collinear_groups(&segments, tol) {
        let members = members.iter().map(|&m| segments[m]);
        out.extend(merge_line(segments[root], members, tol, &combine, &joins));
    }
    out
}

/// Cells of lines, by the doubled angle of their direction (the same for both orientations, so
/// no sign to canonicalize) and by their distance from the origin along the canonical normal:
/// segments on one line fall in one cell or in neighbouring ones.
struct LineCells {
    /// The width of a cell in the doubled angle (radians), and in the offset.
    angle: f64,
    offset: f64,
    /// The greatest angle cell.
    wrap: i64,
}

impl LineCells {
    /// Cells for lines that are one within `tol`.
    fn new(tol: f64) -> LineCells {
        let angle = 1e-6;
        LineCells {
            angle,
            offset: 4.0 * tol.max(f64::MIN_POSITIVE),
            wrap: (std::f64::consts::PI / angle).floor() as i64,
        }
    }

    /// The cell of the line through `s`.
    fn key<T>(&self, s: &FlatSegment<T>) -> (i64, i64) {
        let d = (s.to - s.from).normalize();
        let phi = (2.0 * d.x * d.y).atan2(d.x * d.x - d.y * d.y);
        let half = DVec2::new((phi / 2.0).cos(), (phi / 2.0).sin());
        let offset = half.perp_dot(s.from);
        (
            (phi / self.angle).floor() as i64,
            (offset / self.offset).floor() as i64,
        )
    }

    /// The cell `key` and its eight neighbours, by angle and then by offset.
    fn around(&self, (ka, ko): (i64, i64)) -> [(i64, i64); 9] {
        std::array::from_fn(|k| {
            let (da, doff) = (k as i64 / 3 - 1, k as i64 % 3 - 1);
            let mut a = ka + da;
            let mut o = ko + doff;
            // Across the doubled angle's wrap the canonical normal flips, and so does the offset.
            if a > self.wrap {
                a -= 2 * self.wrap + 2;
                o = -o - 1;
            } else if a < -self.wrap - 1 {
                a += 2 * self.wrap + 2;
                o = -o - 1;
            }
            (a, o)
        })
    }
}

/// The segments by line: each group of segments on one line under the index of its union–find
/// root, the groups in the order of their roots.
fn collinear_groups<T>(segments: &[&FlatSegment<T>], tol: f64) -> BTreeMap<usize, Vec<usize>> {
    let n = segments.len();
    let cells = LineCells::new(tol);
    let keys: Vec<(i64, i64)> = segments.iter().map(|s| cells.key(s)).collect();
    let mut buckets: HashMap<(i64, i64), Vec<usize>> = HashMap::default();
    for (i, &k) in keys.iter().enumerate() {
        buckets.entry(k).or_default().push(i);
    }
    let mut sets = UnionFind::new(n);
    for i in 0..n {
        for cell in cells.around(keys[i]) {
            let Some(others) = buckets.get(&cell) else {
                continue;
            };
            for &j in others {
                if j > i && collinear(segments[i], segments[j], tol) {
                    sets.join(i, j);
                }
            }
        }
    }
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::default();
    for i in 0..n {
        let r = sets.find(i);
        groups.entry(r).or_default().push(i);
    }
    groups
}

/// Whether every endpoint of each of `a` and `b` is within `tol` of the other's line.
fn collinear<T>(a: &FlatSegment<T>, b: &FlatSegment<T>, tol: f64) -> bool {
    let on = |s: &FlatSegment<T>, p: DVec2| {
        let d = s.to - s.from;
        d.perp_dot(p - s.from).abs() <= tol * d.length()
    };
    on(a, b.from) && on(a, b.to) && on(b, a.from) && on(b, a.to)
}

/// The union of `members`, segments on the line of `reference`, as [`merge_collinear`] merges
/// it, in order along that line.
fn merge_line<'s, T: Copy + 's>(
    reference: &FlatSegment<T>,
    members: impl Iterator<Item = &'s FlatSegment<T>>,
    tol: f64,
    combine: &impl Fn(T, T) -> T,
    joins: &impl Fn(&T, &T) -> bool,
) -> Vec<FlatSegment<T>> {
    let origin = reference.from;
    let dir = (reference.to - reference.from).normalize();
    let intervals: Vec<(f64, f64, T)> = members
        .map(|s| {
            let (a, b) = (dir.dot(s.from - origin), dir.dot(s.to - origin));
            (a.min(b), a.max(b), s.tag)
        })
        .collect();
    joined_pieces(&intervals, tol, combine, joins)
        .into_iter()
        .map(|(lo, hi, tag)| FlatSegment {
            from: origin + dir * lo,
            to: origin + dir * hi,
            tag,
        })
        .collect()
}

/// The line cut at every end of `intervals`: each piece takes the combined tag of the intervals
/// over it, and neighbouring pieces whose tags join are one again. Pieces under no interval are
/// left out.
fn joined_pieces<T: Copy>(
    intervals: &[(f64, f64, T)],
    tol: f64,
    combine: &impl Fn(T, T) -> T,
    joins: &impl Fn(&T, &T) -> bool,
) -> Vec<(f64, f64, T)> {
    let mut cuts: Vec<f64> = intervals.iter().flat_map(|&(lo, hi, _)| [lo, hi]).collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|b, a| *b - *a <= tol);
    let mut pieces = Vec::new();
    let mut current: Option<(f64, f64, T)> = None;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let tag = intervals
            .iter()
            .filter(|&&(lo, hi, _)| lo <= a + tol && hi >= b - tol)
            .map(|&(_, _, t)| t)
            .reduce(combine);
        current = match (current, tag) {
            (Some((clo, chi, ctag)), Some(tag)) if joins(&ctag, &tag) && a <= chi + tol => {
                Some((clo, b, combine(ctag, tag)))
            }
            (done, tag) => {
                pieces.extend(done);
                tag.map(|tag| (a, b, tag))
            }
        };
    }
    pieces.extend(current);
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(a: (f64, f64), b: (f64, f64), tag: u8) -> FlatSegment<u8> {
        FlatSegment {
            from: DVec2::new(a.0, a.1),
            to: DVec2::new(b.0, b.1),
            tag,
        }
    }

    #[test]
    fn overlapping_collinear_segments_become_one() {
        let input = [
            seg((0.5, 1.0), (1.0, 1.0), 2),
            seg((-1.0, 1.0), (0.0, 1.0), 1),
            seg((0.5, 1.0), (-0.5, 1.0), 2), // reversed
            seg((0.0, 0.0), (0.0, 2.0), 2),  // another line
            seg((3.0, 1.0), (4.0, 1.0), 2),  // same line, apart
            seg((0.0, 1.5), (0.0, 3.0), 1),  // continues the vertical line, reversed sign of x
            seg((-1e-17, 3.0), (1e-17, 3.5), 2),
        ];
        let out = merge_collinear(&input, 1e-9, u8::min, |a, b| a == b);
        assert_eq!(out.len(), 6, "{out:?}");
        // The vertical line: [0, 1.5] tagged 2, [1.5, 3] 1 (the lower tag where they overlap),
        // then [3, 3.5] tagged 2 again.
        let mut vertical: Vec<(f64, f64, u8)> = out
            .iter()
            .filter(|s| s.from.x.abs() < 1e-9 && s.to.x.abs() < 1e-9)
            .map(|s| (s.from.y.min(s.to.y), s.from.y.max(s.to.y), s.tag))
            .collect();
        vertical.sort_by(|a, b| a.0.total_cmp(&b.0));
        let expected = [(0.0, 1.5, 2), (1.5, 3.0, 1), (3.0, 3.5, 2)];
        assert_eq!(vertical.len(), 3, "{vertical:?}");
        for (got, want) in vertical.iter().zip(expected) {
            assert!(
                (got.0 - want.0).abs() < 1e-12 && (got.1 - want.1).abs() < 1e-12 && got.2 == want.2,
                "{vertical:?}"
            );
        }
        // The line y = 1: [-1, 0] tagged 1, [0, 1] tagged 2, and [3, 4] apart.
        let mut horizontal: Vec<(f64, f64, u8)> = out
            .iter()
            .filter(|s| (s.from.y - 1.0).abs() < 1e-12)
            .map(|s| (s.from.x.min(s.to.x), s.from.x.max(s.to.x), s.tag))
            .collect();
        horizontal.sort_by(|a, b| a.0.total_cmp(&b.0));
        let expected = [(-1.0, 0.0, 1), (0.0, 1.0, 2), (3.0, 4.0, 2)];
        assert_eq!(horizontal.len(), 3, "{horizontal:?}");
        for (got, want) in horizontal.iter().zip(expected) {
            assert!(
                (got.0 - want.0).abs() < 1e-12 && (got.1 - want.1).abs() < 1e-12 && got.2 == want.2,
                "{horizontal:?}"
            );
        }
    }
}
