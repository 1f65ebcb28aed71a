//! The outlines of many projected faces at once: each edge met in both directions cancels, and
//! what remains is walked into closed loops, grouped into one shadow per set of connected faces.
//!
//! A point beside a scanned statue has thousands of its faces in the shaft to the light, at
//! every point evaluated. Corner keys are dense (the scene's welded corners), so the work runs
//! on per-thread tables indexed by them, cleared in constant time by a pass stamp, rather than
//! on hash maps and sorts: linear in the edges.

use std::cell::RefCell;

use glam::DVec2;

use crate::shadow_union::CornerKey;

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

/// Per-corner tables, valid for a corner whose stamp is the current pass.
#[derive(Debug, Default)]
struct Tables {
    pass: u32,
    stamp: Vec<u32>,
    /// Disjoint sets of corners (union by size, path halving), by corner key.
    parent: Vec<u32>,
    size: Vec<u32>,
    /// The first pair whose smaller corner this is.
    pairs: Vec<u32>,
    /// The next kept edge leaving this corner not taken yet.
    leaving: Vec<u32>,
    /// The shadow of the set this corner is the root of.
    shadow: Vec<u32>,
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
            let head = &mut self.leaving[e.from as usize];
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
            if self.shadow[root] == NONE {
                self.shadow[root] = shadows.len() as u32;
                shadows.push(Vec::new());
            }
            shadows[self.shadow[root] as usize].push(contour);
        }
        Some(shadows)
    }

    /// Starts a pass: every corner's entries become stale.
    fn begin(&mut self) {
        self.pass = self.pass.wrapping_add(1);
        if self.pass == 0 {
            self.stamp.fill(0);
            self.pass = 1;
        }
        self.records.clear();
    }

    /// The corner's slot, fresh in this pass.
    fn touch(&mut self, corner: CornerKey) -> usize {
        let i = corner as usize;
        if i >= self.stamp.len() {
            let n = (i + 1).next_power_of_two();
            self.stamp.resize(n, 0);
            for table in [
                &mut self.parent,
                &mut self.size,
                &mut self.pairs,
                &mut self.leaving,
                &mut self.shadow,
            ] {
                table.resize(n, NONE);
            }
        }
        if self.stamp[i] != self.pass {
            self.stamp[i] = self.pass;
            self.parent[i] = corner;
            self.size[i] = 1;
            self.pairs[i] = NONE;
            self.leaving[i] = NONE;
            self.shadow[i] = NONE;
        }
        i
    }

    fn root(&mut self, corner: CornerKey) -> u32 {
        let mut i = corner;
        while self.parent[i as usize] != i {
            let grand = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = grand;
            i = grand;
        }
        i
    }

    fn join(&mut self, a: CornerKey, b: CornerKey) {
        self.touch(a);
        self.touch(b);
        let (a, b) = (self.root(a) as usize, self.root(b) as usize);
        if a != b {
            let (small, large) = if self.size[a] < self.size[b] {
                (a, b)
            } else {
                (b, a)
            };
            self.parent[small] = large as u32;
            self.size[large] += self.size[small];
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
        let mut r = self.pairs[low as usize];
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
                next: self.pairs[low as usize],
            });
            self.pairs[low as usize] = r;
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
        if i >= self.stamp.len() || self.stamp[i] != self.pass {
            return None;
        }
        loop {
            let k = self.leaving[i];
            if k == NONE {
                return None;
            }
            self.leaving[i] = next[k as usize];
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
