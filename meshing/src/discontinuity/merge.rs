//! Coincident critical lines merged into one: in the parallel case the EV wedges of both ends of a
//! blocker edge and the VE wedges of its emitter vertices all lie in one plane.

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
    let n = segments.len();
    // Bucket lines by the doubled angle of their direction (the same for both orientations, so
    // no sign to canonicalize) and by their distance from the origin along the canonical normal.
    let angle_cell = 1e-6;
    let offset_cell = 4.0 * tol.max(f64::MIN_POSITIVE);
    let key = |s: &FlatSegment<T>| {
        let d = (s.to - s.from).normalize();
        let phi = (2.0 * d.x * d.y).atan2(d.x * d.x - d.y * d.y);
        let half = DVec2::new((phi / 2.0).cos(), (phi / 2.0).sin());
        let offset = half.perp_dot(s.from);
        (
            (phi / angle_cell).floor() as i64,
            (offset / offset_cell).floor() as i64,
        )
    };
    let keys: Vec<(i64, i64)> = segments.iter().map(|s| key(s)).collect();
    let wrap = (std::f64::consts::PI / angle_cell).floor() as i64;
    let mut buckets: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for (i, &k) in keys.iter().enumerate() {
        buckets.entry(k).or_default().push(i);
    }
    let collinear = |a: &FlatSegment<T>, b: &FlatSegment<T>| {
        let on = |s: &FlatSegment<T>, p: DVec2| {
            let d = s.to - s.from;
            d.perp_dot(p - s.from).abs() <= tol * d.length()
        };
        on(a, b.from) && on(a, b.to) && on(b, a.from) && on(b, a.to)
    };
    let mut sets = UnionFind::new(n);
    for i in 0..n {
        let (ka, ko) = keys[i];
        for da in -1..=1 {
            for doff in -1..=1 {
                let mut a = ka + da;
                let mut o = ko + doff;
                // Across the doubled angle's wrap the canonical normal flips, and so does the offset.
                if a > wrap {
                    a -= 2 * wrap + 2;
                    o = -o - 1;
                } else if a < -wrap - 1 {
                    a += 2 * wrap + 2;
                    o = -o - 1;
                }
                let Some(others) = buckets.get(&(a, o)) else {
                    continue;
                };
                for &j in others {
                    if j > i && collinear(segments[i], segments[j]) {
                        sets.join(i, j);
                    }
                }
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for i in 0..n {
        let r = sets.find(i);
        groups.entry(r).or_default().push(i);
    }

    let mut out = Vec::new();
    for (root, members) in groups {
        let reference = segments[root];
        let origin = reference.from;
        let dir = (reference.to - reference.from).normalize();
        let intervals: Vec<(f64, f64, T)> = members
            .iter()
            .map(|&m| {
                let s = segments[m];
                let (a, b) = (dir.dot(s.from - origin), dir.dot(s.to - origin));
                (a.min(b), a.max(b), s.tag)
            })
            .collect();
        let emit = |(lo, hi, tag): (f64, f64, T), out: &mut Vec<FlatSegment<T>>| {
            out.push(FlatSegment {
                from: origin + dir * lo,
                to: origin + dir * hi,
                tag,
            });
        };
        // The line cut at every end: each piece takes the combined tag of the segments over it,
        // and neighbouring pieces with one tag join again.
        let mut cuts: Vec<f64> = intervals.iter().flat_map(|&(lo, hi, _)| [lo, hi]).collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|b, a| *b - *a <= tol);
        let mut current: Option<(f64, f64, T)> = None;
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let tag = intervals
                .iter()
                .filter(|&&(lo, hi, _)| lo <= a + tol && hi >= b - tol)
                .map(|&(_, _, t)| t)
                .reduce(&combine);
            current = match (current, tag) {
                (Some((clo, chi, ctag)), Some(tag)) if joins(&ctag, &tag) && a <= chi + tol => {
                    Some((clo, b, combine(ctag, tag)))
                }
                (done, tag) => {
                    if let Some(done) = done {
                        emit(done, &mut out);
                    }
                    tag.map(|tag| (a, b, tag))
                }
            };
        }
        if let Some(done) = current {
            emit(done, &mut out);
        }
    }
    out
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
