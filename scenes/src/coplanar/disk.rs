//! Regions whose union is not one simple polygon (a floor around a column, a ring of faces) are
//! grown, face by face, into pieces that are: topological disks.
//!
//! A piece starts at its region's first free face and takes a neighbouring face when the result
//! is still a disk: the new face meets the piece along one run of its edges, and its other
//! corners and edges are new to the piece (so the outline neither closes around a hole nor
//! touches itself at a corner). Each face is offered once per neighbour that joins, so growing is
//! linear in the region's edges. Each piece is then traced and checked like a whole region; one
//! that fails (faces that touch without sharing an edge) falls back to its single faces.

use std::collections::{HashSet, VecDeque};

use super::{Mesh, NO_TWIN, Piece, outline};

/// Marks a face in `owner` that no piece has taken yet.
pub(super) const FREE: u32 = u32::MAX;

/// Splits `region` into disk pieces. `owner` (one slot per face of the mesh, [`FREE`] when
/// free) records which piece took a face; pieces are numbered by their first face.
pub(super) fn split_region(
    mesh: &Mesh,
    region: &[usize],
    owner: &mut [u32],
    scene_diagonal: f64,
) -> Vec<Piece> {
    let mut pieces = Vec::new();
    for &seed in region {
        if owner[seed] != FREE {
            continue;
        }
        let faces = grow(mesh, seed, owner);
        if faces.len() == 1 {
            pieces.push(mesh.single(seed));
            continue;
        }
        let piece = seed as u32;
        let outline = outline::trace(mesh, &faces, |g| owner[g] == piece)
            .and_then(|boundary| outline::polygon(mesh, &faces, &boundary, scene_diagonal));
        match outline {
            Some(polygon) => {
                let mut faces = faces;
                faces.sort_unstable();
                pieces.push(Piece { faces, polygon });
            }
            None => pieces.extend(faces.iter().map(|&f| mesh.single(f))),
        }
    }
    pieces
}

/// The faces of the disk grown from `seed`, marked in `owner` with the seed's index.
fn grow(mesh: &Mesh, seed: usize, owner: &mut [u32]) -> Vec<usize> {
    let piece = seed as u32;
    owner[seed] = piece;
    let mut disk = Disk::default();
    disk.add(mesh, seed, &[]);
    let mut faces = vec![seed];
    let mut queue: VecDeque<usize> = neighbours(mesh, seed).collect();
    while let Some(f) = queue.pop_front() {
        if owner[f] != FREE {
            continue;
        }
        if let Some(shared) = disk.joins(mesh, f) {
            disk.add(mesh, f, &shared);
            owner[f] = piece;
            faces.push(f);
            queue.extend(neighbours(mesh, f));
        }
    }
    faces
}

/// The faces that merge with `f` across one of its edges.
fn neighbours<'m>(mesh: &'m Mesh, f: usize) -> impl Iterator<Item = usize> + 'm {
    mesh.edges_of(f)
        .map(|edge| mesh.twins[edge])
        .filter(|&twin| twin != NO_TWIN)
        .map(|twin| twin as usize)
}

/// A piece as it grows: its outline's directed edges, and every corner and undirected edge of its
/// faces.
#[derive(Default)]
struct Disk {
    boundary: HashSet<(u32, u32)>,
    corners: HashSet<u32>,
    edges: HashSet<(u32, u32)>,
}

impl Disk {
    /// Which of `f`'s edges it shares with the disk, when adding it keeps the disk a disk.
    fn joins(&self, mesh: &Mesh, f: usize) -> Option<Vec<bool>> {
        let edges: Vec<usize> = mesh.edges_of(f).collect();
        let k = edges.len();
        let shared: Vec<bool> = edges
            .iter()
            .map(|&e| {
                let (a, b) = mesh.edge(e);
                self.boundary.contains(&(b, a))
            })
            .collect();
        // A shared edge must be one the faces merge across (not where three faces meet).
        if edges
            .iter()
            .zip(&shared)
            .any(|(&e, &s)| s && mesh.twins[e] == NO_TWIN)
        {
            return None;
        }
        // Exactly one run of shared edges, and not all of them.
        let runs = (0..k)
            .filter(|&i| shared[i] && !shared[(i + k - 1) % k])
            .count();
        if runs != 1 {
            return None;
        }
        for i in 0..k {
            let on_run = shared[i] || shared[(i + k - 1) % k];
            let (a, b) = mesh.edge(edges[i]);
            if !on_run && self.corners.contains(&a) {
                return None;
            }
            if !shared[i] && self.edges.contains(&(a.min(b), a.max(b))) {
                return None;
            }
        }
        Some(shared)
    }

    /// Adds face `f`, of which the edges marked in `shared` (none for the first face) close
    /// against the disk's outline.
    fn add(&mut self, mesh: &Mesh, f: usize, shared: &[bool]) {
        for (i, edge) in mesh.edges_of(f).enumerate() {
            let (a, b) = mesh.edge(edge);
            if shared.get(i).copied().unwrap_or(false) {
                self.boundary.remove(&(b, a));
            } else {
                self.boundary.insert((a, b));
            }
            self.corners.insert(a);
            self.edges.insert((a.min(b), a.max(b)));
        }
    }
}
