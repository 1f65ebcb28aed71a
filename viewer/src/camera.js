// The initial view: the run's camera when the data has one, else the renderer's default framing
// (viz/src/camera.rs), and the camera's clipping planes as the user moves about.

import { MathUtils, PerspectiveCamera, Vector3 } from 'three';

const DEFAULT_FOV_DEG = 45;
const DEFAULT_VIEW_DIRECTION = [0.3, -1.0, 0.6];

// eye, target, up (Vector3) and the vertical field of view in degrees.
export function initialView(data, box) {
  const center = box.getCenter(new Vector3());
  if (data.camera) {
    const c = data.camera;
    const eye = new Vector3(...c.eye);
    const target = new Vector3(...c.target);
    // The same view, but the controls orbit about the point of the line of sight nearest the
    // scene's centre rather than wherever the target was put (the Cornell box's open front).
    const forward = target.clone().sub(eye).normalize();
    const depth = center.clone().sub(eye).dot(forward);
    return {
      eye,
      target: depth > 0 ? eye.clone().addScaledVector(forward, depth) : target,
      up: new Vector3(...c.up).normalize(),
      fov: c.fov_deg,
    };
  }
  const radius = Math.max(0.5 * box.getSize(new Vector3()).length(), 1e-9);
  const [x, y, z] = DEFAULT_VIEW_DIRECTION;
  const yUp = lightsFaceMinusY(data);
  const direction = (yUp ? new Vector3(x, z, -y) : new Vector3(x, y, z)).normalize();
  const distance = radius / Math.sin(MathUtils.degToRad(DEFAULT_FOV_DEG / 2));
  return {
    eye: center.clone().addScaledVector(direction, distance),
    target: center,
    up: yUp ? new Vector3(0, 1, 0) : new Vector3(0, 0, 1),
    fov: DEFAULT_FOV_DEG,
  };
}

// Whether the emitters, weighted by power, face -y more than any other axis direction: scenes
// from y-up tools, which the renderer shows with +y up.
function lightsFaceMinusY(data) {
  const { index, position, triangle_surface: owner } = data.arrays;
  const facing = new Vector3();
  const a = new Vector3();
  const b = new Vector3();
  const c = new Vector3();
  for (let t = 0; t < owner.length; t++) {
    const e = data.surfaces[owner[t]].emission;
    const power = Array.isArray(e) ? (e[0] + e[1] + e[2]) / 3 : 0;
    if (!(power > 0)) continue;
    a.fromArray(position, index[t * 3] * 3);
    b.fromArray(position, index[t * 3 + 1] * 3).sub(a);
    c.fromArray(position, index[t * 3 + 2] * 3).sub(a);
    // Twice the area along the normal.
    facing.addScaledVector(b.cross(c), power);
  }
  return facing.y < 0 && -facing.y > Math.max(Math.abs(facing.x), Math.abs(facing.z));
}

export function makeCamera(view) {
  const camera = new PerspectiveCamera(view.fov, 1, 1, 2);
  camera.userData.fov = view.fov;
  return camera;
}

// Puts the camera at `view` (the target is the controls').
export function applyView(camera, controls, view) {
  camera.position.copy(view.eye);
  camera.up.copy(view.up);
  controls.target.copy(view.target);
  camera.lookAt(view.target);
  controls.update();
}

// The run's field of view is vertical; in a portrait window it is kept across the width instead,
// so that what the render shows stays in view.
export function fitAspect(camera, width, height) {
  const aspect = width / Math.max(height, 1);
  camera.aspect = aspect;
  const fov = camera.userData.fov;
  camera.fov = aspect >= 1
    ? fov
    : MathUtils.radToDeg(2 * Math.atan(Math.tan(MathUtils.degToRad(fov / 2)) / aspect));
  camera.updateProjectionMatrix();
}

// Near and far planes that hold the scene from wherever the camera is, keeping depth precision.
export function fitClipping(camera, box) {
  const sphereCenter = box.getCenter(new Vector3());
  const radius = Math.max(0.5 * box.getSize(new Vector3()).length(), 1e-9);
  const distance = camera.position.distanceTo(sphereCenter);
  camera.near = Math.max(distance - radius, radius * 1e-3) * 0.5;
  camera.far = distance + radius * 2;
  camera.updateProjectionMatrix();
}
