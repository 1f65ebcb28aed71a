//! The render's camera from the command line: `--camera EYE:TARGET[:FOV]`, or `--eye`,
//! `--target`, `--up` and `--fov` each replacing one part of the scene's camera.

use glam::DVec3;
use penumbra_scenes::{Camera, Scene};

use crate::run_args::RunArgs;

/// An up direction within this sine of the view direction cannot orient a picture.
const UP_ALONG_VIEW_SINE: f64 = 1e-6;

/// The camera the arguments ask for, if they ask for one.
pub(crate) fn camera(args: &RunArgs, scene: &Scene) -> Result<Option<Camera>, String> {
    if let Some(text) = &args.camera {
        return camera_of(text, scene)
            .map(Some)
            .map_err(|e| format!("--camera {text:?}: {e}"));
    }
    if args.eye.is_none() && args.target.is_none() && args.up.is_none() && args.fov.is_none() {
        return Ok(None);
    }
    let base = scene
        .camera
        .unwrap_or_else(|| penumbra_viz::default_camera(scene));
    let part = |flag: &str, text: &Option<String>, base: DVec3| match text {
        Some(text) => point(text).map_err(|e| format!("{flag} {text:?}: {e}")),
        None => Ok(base),
    };
    let camera = Camera {
        eye: part("--eye", &args.eye, base.eye)?,
        target: part("--target", &args.target, base.target)?,
        up: part("--up", &args.up, base.up)?,
        fov_deg: args.fov.unwrap_or(base.fov_deg),
    };
    check(&camera)?;
    Ok(Some(camera))
}

/// Refuses a camera that cannot make a picture, naming the flag to change.
fn check(camera: &Camera) -> Result<(), String> {
    let view = camera.target - camera.eye;
    if view.length_squared() == 0.0 {
        return Err("the eye and the target are the same point (--eye, --target)".into());
    }
    if camera.up.length_squared() == 0.0 {
        return Err("--up must not be the zero vector".into());
    }
    if view.normalize().cross(camera.up.normalize()).length() < UP_ALONG_VIEW_SINE {
        return Err(
            "--up points along the view, from the eye to the target: it must say which way is \
             up across the picture"
                .into(),
        );
    }
    if !(camera.fov_deg > 0.0 && camera.fov_deg < 180.0) {
        return Err(format!(
            "--fov must lie between 0 and 180 degrees, not {}",
            camera.fov_deg
        ));
    }
    Ok(())
}

/// `X,Y,Z`: three finite numbers.
fn point(text: &str) -> Result<DVec3, String> {
    let numbers: Result<Vec<f64>, _> = text.split(',').map(|n| n.trim().parse()).collect();
    match numbers.as_deref() {
        Ok(&[x, y, z]) if [x, y, z].iter().all(|v| v.is_finite()) => Ok(DVec3::new(x, y, z)),
        _ => Err("write three finite numbers x,y,z".into()),
    }
}

/// `--camera EX,EY,EZ:TX,TY,TZ[:FOV]`.
fn camera_of(text: &str, scene: &Scene) -> Result<Camera, String> {
    let parts: Vec<&str> = text.split(':').collect();
    let at = |part: &str, what: &str| -> Result<DVec3, String> {
        point(part)
            .map_err(|_| format!("the {what} must be three finite numbers x,y,z, not {part:?}"))
    };
    let (eye, target, fov) = match parts.as_slice() {
        [eye, target] => (at(eye, "eye")?, at(target, "target")?, None),
        [eye, target, fov] => {
            let fov: f64 = fov
                .trim()
                .parse()
                .map_err(|_| format!("the field of view must be a number, not {fov:?}"))?;
            (at(eye, "eye")?, at(target, "target")?, Some(fov))
        }
        _ => return Err("write it EX,EY,EZ:TX,TY,TZ or EX,EY,EZ:TX,TY,TZ:FOV".into()),
    };
    if eye == target {
        return Err("the eye and the target are the same point".into());
    }
    if fov.is_some_and(|f| !(f > 0.0 && f < 180.0)) {
        return Err("the field of view must lie between 0 and 180 degrees".into());
    }
    Ok(penumbra_viz::camera_looking(scene, eye, target, fov))
}
