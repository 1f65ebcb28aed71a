//! The camera: a default view that frames a scene, and the pinhole projection to pixels.

use glam::{DQuat, DVec2, DVec3};
use penumbra_scenes::{Camera, Scene};

use crate::error::VizError;

/// Vertical field of view of [`default_camera`], in degrees.
pub const DEFAULT_FOV_DEG: f64 = 45.0;
/// Direction from the scene's centre towards the eye of [`default_camera`]: in front, a little to
/// the right and above, with +z up.
pub const DEFAULT_VIEW_DIRECTION: DVec3 = DVec3::new(0.3, -1.0, 0.6);

/// A camera that frames the scene's bounding box: it looks at the box's centre from
/// [`DEFAULT_VIEW_DIRECTION`], far enough that the box's bounding sphere fits the vertical field
/// of view ([`DEFAULT_FOV_DEG`]), with +z up (never parallel to that direction). A scene with
/// another up ([`scene_up`]: its own, or +y when its lights face -y, the convention of OBJ
/// files) is seen the same way turned to it: with +y up, from +z. An empty scene gets a view of
/// the unit sphere about the origin.
pub fn default_camera(scene: &Scene) -> Camera {
    let bounds = scene.bounds();
    let diagonal = bounds.diagonal();
    let (center, radius) = if diagonal > 0.0 && diagonal.is_finite() {
        (bounds.center(), 0.5 * diagonal)
    } else if !bounds.is_empty() && bounds.center().is_finite() {
        // A single point: any positive size will do.
        (bounds.center(), 1.0)
    } else {
        (DVec3::ZERO, 1.0)
    };
    let up = scene_up(scene);
    // The view as seen with +z up, turned to the scene's up: +y up sees it from +z.
    let direction = DQuat::from_rotation_arc(DVec3::Z, up) * DEFAULT_VIEW_DIRECTION.normalize();
    let half_fov = (0.5 * DEFAULT_FOV_DEG).to_radians();
    let distance = radius / half_fov.sin();
    Camera {
        eye: center + direction * distance,
        target: center,
        up,
        fov_deg: DEFAULT_FOV_DEG,
    }
}

/// A view whose direction's cosine with the up axis is within this of 1 runs along it.
const ALONG_UP: f64 = 1e-6;

/// A camera at `eye` looking at `target` with a vertical field of view of `fov_deg` (default
/// [`DEFAULT_FOV_DEG`]), upright as [`default_camera`] is: +z up, or +y for scenes lit along -y;
/// when the view runs along that axis, the other one.
pub fn camera_looking(scene: &Scene, eye: DVec3, target: DVec3, fov_deg: Option<f64>) -> Camera {
    let up = scene_up(scene);
    let along = (target - eye).normalize_or_zero().dot(up).abs();
    let up = if along > 1.0 - ALONG_UP {
        if up.z.abs() > 0.5 { DVec3::Y } else { DVec3::Z }
    } else {
        up
    };
    Camera {
        eye,
        target,
        up,
        fov_deg: fov_deg.unwrap_or(DEFAULT_FOV_DEG),
    }
}

/// The up direction of a scene's views: the scene's own (glTF files: +y); without one, +y when
/// its lights face -y (OBJ files), else +z.
pub fn scene_up(scene: &Scene) -> DVec3 {
    if let Some(up) = scene.up.and_then(|u| u.try_normalize()) {
        return up;
    }
    if lights_face_minus_y(scene) {
        DVec3::Y
    } else {
        DVec3::Z
    }
}

/// Whether the scene's lights, weighted by their power, face -y more than any other axis
/// direction.
fn lights_face_minus_y(scene: &Scene) -> bool {
    let facing: DVec3 = scene
        .emitters()
        .map(|(_, s)| s.normal() * s.area() * s.emission.mean())
        .sum();
    facing.y < 0.0 && -facing.y > facing.x.abs().max(facing.z.abs())
}

/// A camera set up for one image: an orthonormal basis and the projection to pixel coordinates.
///
/// Camera space has `x` to the image's right (`forward × up`), `y` up and `z` the depth along the
/// view direction. Pixel coordinates have x to the right and y down, with pixel `(i, j)` covering
/// `[i, i + 1] × [j, j + 1]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct View {
    eye: DVec3,
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    /// Distance of the image plane in pixels: square pixels, so one focal length serves both axes.
    focal: f64,
    center: DVec2,
}

impl View {
    pub(crate) fn new(camera: &Camera, width: u32, height: u32) -> Result<View, VizError> {
        let invalid = |reason| Err(VizError::InvalidCamera { reason });
        if !(camera.eye.is_finite() && camera.target.is_finite() && camera.up.is_finite()) {
            return invalid("eye, target and up must be finite");
        }
        if !(camera.fov_deg > 0.0 && camera.fov_deg < 180.0) {
            return invalid("the field of view must lie strictly between 0 and 180 degrees");
        }
        let Some(forward) = (camera.target - camera.eye).try_normalize() else {
            return invalid("eye and target coincide");
        };
        let Some(right) = forward.cross(camera.up).try_normalize() else {
            return invalid("the up vector is zero or parallel to the view direction");
        };
        let up = right.cross(forward);
        let half_fov = (0.5 * camera.fov_deg).to_radians();
        Ok(View {
            eye: camera.eye,
            right,
            up,
            forward,
            focal: 0.5 * f64::from(height) / half_fov.tan(),
            center: DVec2::new(0.5 * f64::from(width), 0.5 * f64::from(height)),
        })
    }

    pub(crate) fn eye(&self) -> DVec3 {
        self.eye
    }

    /// A world point in camera space.
    pub(crate) fn camera_space(&self, p: DVec3) -> DVec3 {
        let d = p - self.eye;
        DVec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    /// The direction (not normalized) from the eye through a point in pixel coordinates.
    #[cfg(test)]
    pub(crate) fn ray_direction(&self, pixel: DVec2) -> DVec3 {
        let d = (pixel - self.center) / self.focal;
        self.forward + self.right * d.x - self.up * d.y
    }

    /// Pixel coordinates of a camera-space point in front of the eye (`c.z > 0`).
    pub(crate) fn project(&self, c: DVec3) -> DVec2 {
        let s = self.focal / c.z;
        DVec2::new(self.center.x + c.x * s, self.center.y - c.y * s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use penumbra_scenes::builtin;

    /// A y-up scene (the textbook's light turned to face -y) is seen with +y up, from the
    /// front (+z) and above.
    #[test]
    fn a_scene_lit_from_plus_y_is_seen_with_y_up() {
        let mut scene = builtin::textbook();
        for s in &mut scene.surfaces {
            for p in &mut s.polygon {
                *p = DVec3::new(p.x, p.z, -p.y);
            }
        }
        let camera = default_camera(&scene);
        assert_eq!(camera.up, DVec3::Y);
        let to_eye = camera.eye - camera.target;
        assert!(to_eye.y > 0.0 && to_eye.z > 0.0, "{to_eye}");
        assert_eq!(default_camera(&builtin::textbook()).up, DVec3::Z);
    }

    #[test]
    fn default_camera_sees_the_whole_box() {
        let scene = builtin::textbook();
        let camera = default_camera(&scene);
        let view = View::new(&camera, 100, 100).expect("default camera is valid");
        let bounds = scene.bounds();
        for i in 0..8 {
            let corner = DVec3::new(
                if i & 1 == 0 {
                    bounds.min.x
                } else {
                    bounds.max.x
                },
                if i & 2 == 0 {
                    bounds.min.y
                } else {
                    bounds.max.y
                },
                if i & 4 == 0 {
                    bounds.min.z
                } else {
                    bounds.max.z
                },
            );
            let c = view.camera_space(corner);
            assert!(c.z > 0.0);
            let p = view.project(c);
            assert!((0.0..=100.0).contains(&p.y), "corner {corner} at {p}");
        }
    }

    #[test]
    fn cornell_right_is_minus_x() {
        let scene = builtin::cornell();
        let camera = scene.camera.expect("cornell has a camera");
        let view = View::new(&camera, 64, 64).expect("valid");
        let red_side = view.project(view.camera_space(DVec3::new(550.0, 273.0, 300.0)));
        let green_side = view.project(view.camera_space(DVec3::new(0.0, 273.0, 300.0)));
        assert!(red_side.x < 32.0 && green_side.x > 32.0);
        let floor = view.project(view.camera_space(DVec3::new(278.0, 0.0, 300.0)));
        assert!(floor.y > 32.0);
    }

    #[test]
    fn degenerate_cameras_are_errors() {
        let mut camera = default_camera(&builtin::textbook());
        camera.up = camera.target - camera.eye;
        assert!(View::new(&camera, 8, 8).is_err());
        camera.up = DVec3::Z;
        camera.fov_deg = 180.0;
        assert!(View::new(&camera, 8, 8).is_err());
        camera.fov_deg = 45.0;
        camera.target = camera.eye;
        assert!(View::new(&camera, 8, 8).is_err());
    }
}
