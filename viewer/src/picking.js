// Picking a point on the surfaces: the triangle under the pointer, the values there interpolated
// from its corners, and a marker at the point.

import { Mesh, MeshBasicMaterial, Raycaster, SphereGeometry, Triangle, Vector2, Vector3 } from 'three';

// The marker's radius as a fraction of its distance from the eye: a constant size on screen.
const MARKER_SCALE = 0.006;

export class Picker {
  // `meshes`: the surfaces' fronts and backs (one geometry, so one triangle numbering).
  constructor(data, meshes) {
    this.data = data;
    this.meshes = meshes;
    this.raycaster = new Raycaster();
    this.marker = new Mesh(
      new SphereGeometry(1, 16, 12),
      new MeshBasicMaterial({ color: 0xff2bd6, depthTest: false }),
    );
    this.marker.renderOrder = 2;
    this.marker.visible = false;
  }

  // The pick at a point in normalized device coordinates, or null when nothing is there.
  pick(ndc, camera) {
    this.raycaster.setFromCamera(new Vector2(ndc.x, ndc.y), camera);
    const hit = this.raycaster.intersectObjects(this.meshes, false)[0];
    if (!hit) return null;
    const t = hit.faceIndex;
    const { index, position, radiosity, direct, indirect, error, triangle_surface: owner } = this.data.arrays;
    const corners = [0, 1, 2].map((k) => index[t * 3 + k]);
    const [a, b, c] = corners.map((v) => new Vector3().fromArray(position, v * 3));
    const weights = new Triangle(a, b, c).getBarycoord(hit.point, new Vector3());
    const interpolate = (values) => [0, 1, 2].map((ch) =>
      weights.x * values[corners[0] * 3 + ch] + weights.y * values[corners[1] * 3 + ch] + weights.z * values[corners[2] * 3 + ch]);
    // Light leaves the front only, the side the corners run counter-clockwise around.
    const normal = new Vector3().subVectors(b, a).cross(new Vector3().subVectors(c, a));
    return {
      triangle: t,
      surface: this.data.surfaces[owner[t]],
      point: hit.point.clone(),
      back: normal.dot(this.raycaster.ray.direction) > 0,
      radiosity: interpolate(radiosity),
      direct: interpolate(direct),
      indirect: interpolate(indirect),
      error: error ? error[t] : null,
    };
  }

  show(point) {
    this.marker.position.copy(point);
    this.marker.visible = true;
  }

  hide() {
    this.marker.visible = false;
  }

  // Before each frame: keep the marker the same size on screen.
  update(camera) {
    if (this.marker.visible) {
      this.marker.scale.setScalar(camera.position.distanceTo(this.marker.position) * MARKER_SCALE);
    }
  }
}
