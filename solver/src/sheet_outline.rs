//! The outlines of many projected faces at once: each edge met in both directions cancels, and
//! what remains is walked into closed loops, grouped into one shadow per set of connected faces.
//!
//! A point beside a scanned statue has thousands of its faces in the shaft to the light, at
//! every point evaluated. Corner keys are dense (the scene's welded corners), so the work runs
//! on per-thread tables indexed by them, cleared in constant time by a pass stamp, rather than
//! on hash maps and sorts: linear in the edges.

use std::cell::RefCell;

use glam::DVec2;

/// A corner of an occluder face, welded: faces that share a point share its key.
pub(crate) type CornerKey = u32;

/// One directed edge of a projected face, between two corners, with the first one's projection.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SheetEdge {
    pub from: CornerKey,
    pub to: CornerKey,
    pub at: DVec2,
}

/// Closed loops whose winding numbers add up to a shadow's coverage.
pub(crate) type Loops = Vec<Vec<DVec2>>;

/// The closed outlines of `edges` once each edge met in both directions cancels (the winding
/// number of what remains is that of the faces), one shadow per set of faces connected by edges
/// or `links`. The order follows the edges' order. `None` if the edges do not close, which faces
/// of distinct corners always do.
pub(crate) fn outlines(
    edges: &[SheetEdge],
    links: &[(CornerKey, CornerKey)],
) -> Option<Vec<Loops>> {
    TABLES.with_borrow_mut(|tables| tables.outlines(edges, links))
}

/// The directed edges left once each edge met in both directions cancels (only the surplus in
/// one direction stays), in a fixed order: the same cancellation as [`outlines`], by sorting,
/// for edges of any kind (the occluder tree's outlines, made once when it is built).
pub(crate) fn cancel_opposite<E: Copy>(
    mut edges: Vec<E>,
    ends: impl Fn(&E) -> (CornerKey, CornerKey),
) -> Vec<E> {
    let pair = |e: &E| {
        let (from, to) = ends(e);
        (from.min(to), from.max(to))
    };
    let forward = |e: &E| {
        let (from, to) = ends(e);
        from < to
    };
    // Each corner pair's edges together, forward ones (from the smaller key) first. Edges with
    // equal keys are the same edge, so an unstable sort keeps the result fixed.
    edges.sort_unstable_by_key(|e| {
        let (lo, hi) = pair(e);
        (u64::from(lo) << 33) | (u64::from(hi) << 1) | u64::from(!forward(e))
    });
    let mut kept = Vec::with_capacity(edges.len() / 4);
    let mut i = 0;
    while i < edges.len() {
        let j = i + edges[i..]
            .iter()
            .take_while(|e| pair(e) == pair(&edges[i]))
            .count();
        let ahead = edges[i..j].iter().filter(|e| forward(e)).count();
        let back = (j - i) - ahead;
        if ahead > back {
            kept.extend_from_slice(&edges[i..i + ahead - back]);
        } else {
            kept.extend_from_slice(&edges[i + ahead..i + back]);
        }
        i = j;
    }
    kept
}

thread_local! {
    static TABLES: RefCell<Tables> = RefCell::new(Tables::default());
}

/// Marks an empty slot of a table.
const NONE: u32 = u32::MAX;

/// The edges between one pair of corners: how many run from the smaller key, less how many run
/// back, and the projection each direction starts at.
#[derive(Clone, Copy, Debug)]
struct Pair {
    low: CornerKey,
    high: CornerKey,
    net: i32,
    forward_at: DVec2,
    backward_at: DVec2,
    /// The next pair from the same smaller corner.
    next: u32,
}

/// What a pass knows of one corner, valid while its stamp is the pass's.
#[derive(Clone, Copy, Debug, Default)]
struct Corner {
    stamp: u32,
    /// Disjoint sets of corners (union by size, path halving), by corner key.
    parent: u32,
    size: u32,
    /// The first pair whose smaller corner this is.
    pairs: u32,
    /// The next kept edge leaving this corner not taken yet.
    leaving: u32,
    /// The shadow of the set this corner is the root of.
    shadow: u32,
}

/// Per-corner entries (one cache line holds a corner's), and the pairs met in this pass.
#[derive(Debug, Default)]
struct Tables {
    pass: u32,
    corners: Vec<Corner>,
    records: Vec<Pair>,
}

impl Tables {
    fn outlines(
        &mut self,
        edges: &[SheetEdge],
        links: &[(CornerKey, CornerKey)],
    ) -> Option<Vec<Loops>> {
        self.begin();
        for e in edges {
            self.join(e.from, e.to);
            self.count(e);
        }
        for &(a, b) in links {
            self.join(a, b);
        }
        let kept = self.kept();
        // The edges leaving each corner, in the order of `kept`.
        let mut next = vec![NONE; kept.len()];
        for (k, e) in kept.iter().enumerate().rev() {
            let head = &mut self.corners[e.from as usize].leaving;
            next[k] = *head;
            *head = k as u32;
        }
        let mut used = vec![false; kept.len()];
        let mut shadows: Vec<Loops> = Vec::new();
        for start in 0..kept.len() {
            if used[start] {
                continue;
            }
            used[start] = true;
            let mut contour = vec![kept[start].at];
            let mut at = kept[start].to;
            while at != kept[start].from {
                let k = self.take(at, &next, &used)?;
                used[k] = true;
                contour.push(kept[k].at);
                at = kept[k].to;
            }
            let root = self.root(kept[start].from) as usize;
            let root = &mut self.corners[root];
            if root.shadow == NONE {
                root.shadow = shadows.len() as u32;
                shadows.push(Vec::new());
            }
            shadows[root.shadow as usize].push(contour);
        }
        Some(shadows)
    }

    /// Starts a pass: every corner's entries become stale.
    fn begin(&mut self) {
        self.pass = self.pass.wrapping_add(1);
        if self.pass == 0 {
            self.corners.iter_mut().for_each(|c| c.stamp = 0);
            self.pass = 1;
        }
        self.records.clear();
    }

    /// The corner's slot, fresh in this pass.
    fn touch(&mut self, corner: CornerKey) -> usize {
        let i = corner as usize;
        if i >= self.corners.len() {
            self.corners
                .resize((i + 1).next_power_of_two(), Corner::default());
        }
        let c = &mut self.corners[i];
        if c.stamp != self.pass {
            *c = Corner {
                stamp: self.pass,
                parent: corner,
                size: 1,
                pairs: NONE,
                leaving: NONE,
                shadow: NONE,
            };
        }
        i
    }

    fn root(&mut self, corner: CornerKey) -> u32 {
        let mut i = corner;
        while self.corners[i as usize].parent != i {
            let grand = self.corners[self.corners[i as usize].parent as usize].parent;
            self.corners[i as usize].parent = grand;
            i = grand;
        }
        i
    }

    fn join(&mut self, a: CornerKey, b: CornerKey) {
        self.touch(a);
        self.touch(b);
        let (a, b) = (self.root(a) as usize, self.root(b) as usize);
        if a != b {
            let (small, large) = if self.corners[a].size < self.corners[b].size {
                (a, b)
            } else {
                (b, a)
            };
            self.corners[small].parent = large as u32;
            self.corners[large].size += self.corners[small].size;
        }
    }

    /// Counts edge `e` on its corner pair (both corners touched).
    fn count(&mut self, e: &SheetEdge) {
        let forward = e.from < e.to;
        let (low, high) = if forward {
            (e.from, e.to)
        } else {
            (e.to, e.from)
        };
        let mut r = self.corners[low as usize].pairs;
        while r != NONE && self.records[r as usize].high != high {
            r = self.records[r as usize].next;
        }
        if r == NONE {
            r = self.records.len() as u32;
            self.records.push(Pair {
                low,
                high,
                net: 0,
                forward_at: DVec2::ZERO,
                backward_at: DVec2::ZERO,
                next: self.corners[low as usize].pairs,
            });
            self.corners[low as usize].pairs = r;
        }
        let pair = &mut self.records[r as usize];
        if forward {
            pair.net += 1;
            pair.forward_at = e.at;
        } else {
            pair.net -= 1;
            pair.backward_at = e.at;
        }
    }

    /// The surplus of each corner pair in one direction, pairs in the order first met.
    fn kept(&self) -> Vec<SheetEdge> {
        let mut kept = Vec::with_capacity(self.records.len() / 2);
        for p in &self.records {
            let edge = if p.net > 0 {
                SheetEdge {
                    from: p.low,
                    to: p.high,
                    at: p.forward_at,
                }
            } else {
                SheetEdge {
                    from: p.high,
                    to: p.low,
                    at: p.backward_at,
                }
            };
            kept.extend(std::iter::repeat_n(edge, p.net.unsigned_abs() as usize));
        }
        kept
    }

    /// The first kept edge leaving `corner` not used yet, or `None` when every one is.
    fn take(&mut self, corner: CornerKey, next: &[u32], used: &[bool]) -> Option<usize> {
        let i = corner as usize;
        let c = self.corners.get_mut(i).filter(|c| c.stamp == self.pass)?;
        loop {
            let k = c.leaving;
            if k == NONE {
                return None;
            }
            c.leaving = next[k as usize];
            if !used[k as usize] {
                return Some(k as usize);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::polygon::signed_area_2d;

    /// The edges of the unit square with corners `keys` at `origin`, counter-clockwise.
    fn square(keys: [CornerKey; 4], origin: DVec2) -> Vec<SheetEdge> {
        let at = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y].map(|p| p + origin);
        (0..4)
            .map(|i| SheetEdge {
                from: keys[i],
                to: keys[(i + 1) % 4],
                at: at[i],
            })
            .collect()
    }

    fn area(shadows: &[Loops]) -> f64 {
        shadows.iter().flatten().map(|c| signed_area_2d(c)).sum()
    }

    /// Two squares sharing an edge fuse into one shadow of six corners; a square far away is a
    /// second shadow.
    #[test]
    fn squares_sharing_an_edge_fuse() {
        let mut edges = square([0, 1, 2, 3], DVec2::ZERO);
        edges.extend(square([1, 4, 5, 2], DVec2::X));
        edges.extend(square([6, 7, 8, 9], DVec2::splat(5.0)));
        let shadows = outlines(&edges, &[]).expect("closes");
        assert_eq!(shadows.len(), 2);
        assert_eq!(shadows[0].len(), 1);
        assert_eq!(shadows[0][0].len(), 6);
        assert!((area(&shadows) - 3.0).abs() < 1e-15);
    }

    /// A face met twice covers twice: both copies stay. Passes on one thread do not see each
    /// other's corners.
    #[test]
    fn passes_are_independent_and_count_multiplicity() {
        let mut twice = square([0, 1, 2, 3], DVec2::ZERO);
        twice.extend(square([0, 1, 2, 3], DVec2::ZERO));
        let shadows = outlines(&twice, &[]).expect("closes");
        assert_eq!(shadows.len(), 1);
        assert_eq!(shadows[0].len(), 2);
        assert!((area(&shadows) - 2.0).abs() < 1e-15);
        let again = outlines(&square([2, 3, 10, 11], DVec2::ONE), &[]).expect("closes");
        assert_eq!(again.len(), 1);
        assert!((area(&again) - 1.0).abs() < 1e-15);
    }

    /// Edges that do not close give `None`, and the next pass is unaffected.
    #[test]
    fn open_edges_are_refused() {
        let mut open = square([0, 1, 2, 3], DVec2::ZERO);
        open.pop();
        assert!(outlines(&open, &[]).is_none());
        assert!(outlines(&square([0, 1, 2, 3], DVec2::ZERO), &[]).is_some());
    }

    /// Loops joined by a link are one shadow (an outline and its hole).
    #[test]
    fn linked_loops_are_one_shadow() {
        let edges: Vec<SheetEdge> = square([0, 1, 2, 3], DVec2::ZERO)
            .into_iter()
            .chain(square([4, 5, 6, 7], DVec2::splat(3.0)))
            .collect();
        assert_eq!(outlines(&edges, &[]).expect("closes").len(), 2);
        assert_eq!(outlines(&edges, &[(0, 4)]).expect("closes").len(), 1);
    }
}
