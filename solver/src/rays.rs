//! What the Monte Carlo parts share (the path tracer, the photon map, its final gather): a
//! cosine-distributed direction, and the surface a ray from a surface meets on its front.

use glam::DVec3;
use penumbra_scenes::{Hit, PlaneFrame, SurfaceId, Visibility};

/// A cosine-distributed direction about `frame`'s normal, picked by a point of the unit square.
pub(crate) fn cosine_direction(frame: &PlaneFrame, (r1, r2): (f64, f64)) -> DVec3 {
    let (sin_phi, cos_phi) = (2.0 * std::f64::consts::PI * r1).sin_cos();
    let radius = r2.sqrt();
    frame.u * (radius * cos_phi)
        + frame.v * (radius * sin_phi)
        + frame.normal * (1.0 - r2).max(0.0).sqrt()
}

/// The surface a ray from `x`, lifted `offset` off surface `s` along its frame's normal, meets
/// along `d`, with that surface's frame; `None` when it leaves the scene or reaches a surface's
/// back (surfaces receive on their front only). Hits closer than `offset` are ignored.
pub(crate) fn front_hit(
    visibility: &Visibility,
    frames: &[Option<PlaneFrame>],
    (x, s): (DVec3, SurfaceId),
    d: DVec3,
    offset: f64,
) -> Option<(Hit, PlaneFrame)> {
    let frame = frames.get(s).copied().flatten()?;
    let start = x + frame.normal * offset;
    let hit = visibility.closest_hit(start, d, offset, f64::INFINITY, Some(s))?;
    let hit_frame = frames.get(hit.surface).copied().flatten()?;
    (d.dot(hit_frame.normal) < 0.0).then_some((hit, hit_frame))
}
