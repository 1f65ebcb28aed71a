//! One emitter–receiver pair as each search of its events sees it: the welded topology, the
//! visibility index, the two surfaces and their frames, and the scene's tolerances.

use glam::DVec3;
use penumbra_scenes::{PlaneFrame, SurfaceId, Visibility};

use super::topology::Topology;

#[derive(Clone, Copy, Debug)]
pub(crate) struct PairGeometry<'a> {
    pub topology: &'a Topology,
    pub visibility: &'a Visibility,
    pub emitter: SurfaceId,
    pub receiver: SurfaceId,
    pub emitter_frame: PlaneFrame,
    pub receiver_frame: PlaneFrame,
    /// Heights under this are on a plane; points closer are coincident.
    pub tol: f64,
    /// How far a line may run (a few scene diagonals).
    pub reach: f64,
}

impl PairGeometry<'_> {
    /// Whether `p` is in front of both the emitter and the receiver.
    pub(super) fn in_front(&self, p: DVec3) -> bool {
        self.emitter_frame.height(p) > self.tol && self.receiver_frame.height(p) > self.tol
    }

    /// Surfaces other than the emitter and the receiver: the faces whose outlines count.
    pub(super) fn not_pair(&self) -> impl Fn(SurfaceId) -> bool + use<> {
        let (e, r) = (self.emitter, self.receiver);
        move |s| s != e && s != r
    }
}
