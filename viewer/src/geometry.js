// The three.js objects: the surfaces' triangles, their edges and the discontinuity lines.

import {
  Box3,
  BufferAttribute,
  BufferGeometry,
  Color,
  InstancedBufferAttribute,
  LineSegments,
  Mesh,
  ShaderMaterial,
  Vector3,
  Vector4,
} from 'three';
import { LineSegments2 } from 'three/examples/jsm/lines/LineSegments2.js';
import { LineSegmentsGeometry } from 'three/examples/jsm/lines/LineSegmentsGeometry.js';
import { boundaryColour, errorScale, viridis } from './colour.js';
import { drawingViewport, edgeShaders, paintedLineMaterial } from './lines.js';
import { fillLinesMaterial, surfaceMaterial, surfaceUniforms } from './material.js';

// Width of discontinuity lines in CSS pixels.
const LINE_WIDTH = 2.5;
// Above this many edge-plane tests, outlines are not matched with the surfaces they meet.
const MAX_SEAM_TESTS = 5e7;

// Each surface's plane: unit normal (the side light leaves) and offset, [nx, ny, nz, n·p].
export function surfacePlanes(data) {
  const { index, position, triangle_surface: owner } = data.arrays;
  const normals = data.surfaces.map(() => new Vector3());
  const sums = data.surfaces.map(() => new Vector3());
  const corners = data.surfaces.map(() => 0);
  const a = new Vector3();
  const b = new Vector3();
  const c = new Vector3();
  for (let t = 0; t < owner.length; t++) {
    a.fromArray(position, index[t * 3] * 3);
    b.fromArray(position, index[t * 3 + 1] * 3);
    c.fromArray(position, index[t * 3 + 2] * 3);
    sums[owner[t]].add(a).add(b).add(c);
    corners[owner[t]] += 3;
    normals[owner[t]].add(b.sub(a).cross(c.sub(a)));
  }
  return normals.map((n, s) => {
    n.normalize();
    const centroid = sums[s].divideScalar(Math.max(corners[s], 1));
    return [n.x, n.y, n.z, n.dot(centroid)];
  });
}

// The surfaces as one mesh of separate triangles (three vertices each), so that the error
// indicator can be flat per triangle while the light is interpolated per vertex; and the
// surfaces' outlines as lines in the same colours, which fill the cracks between surfaces.
export function buildSurfaces(data, planes, diagonal) {
  const { index, position, radiosity, direct, indirect, error, triangle_surface: owner } = data.arrays;
  const corners = index.length;
  const gather = (source) => {
    const out = new Float32Array(corners * 3);
    for (let c = 0; c < corners; c++) {
      const v = index[c] * 3;
      out[c * 3] = source[v];
      out[c * 3 + 1] = source[v + 1];
      out[c * 3 + 2] = source[v + 2];
    }
    return out;
  };
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(gather(position), 3));
  geometry.setAttribute('radiosity', new BufferAttribute(gather(radiosity), 3));
  geometry.setAttribute('direct', new BufferAttribute(gather(direct), 3));
  geometry.setAttribute('indirect', new BufferAttribute(gather(indirect), 3));
  geometry.setAttribute('ambientShare', new BufferAttribute(ambientShares(data), 3));

  const colours = new Float32Array(corners * 3);
  let scale = null;
  if (error) {
    scale = errorScale(error);
    for (let t = 0; t < error.length; t++) {
      const c = viridis(scale.position(error[t]));
      colours.set(c, t * 9);
      colours.set(c, t * 9 + 3);
      colours.set(c, t * 9 + 6);
    }
  }
  geometry.setAttribute('errorColour', new BufferAttribute(colours, 3));
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  const uniforms = surfaceUniforms(data.display);
  const front = new Mesh(geometry, surfaceMaterial(uniforms, false));
  const back = new Mesh(geometry, surfaceMaterial(uniforms, true));

  const fill = buildSeams(data, geometry, planes, diagonal, uniforms);
  return { meshes: [front, back], fill, uniforms, errorScale: scale };
}

// The display-only ambient term each corner's surface reflects, ρ·ambient (as render.png adds
// it), the same at the three corners of a triangle.
function ambientShares(data) {
  const { triangle_surface: owner } = data.arrays;
  const ambient = data.display.ambient;
  const shares = new Float32Array(owner.length * 9);
  for (let t = 0; t < owner.length; t++) {
    const rho = data.surfaces[owner[t]].reflectance;
    for (let k = 0; k < 3; k++) {
      for (let c = 0; c < 3; c++) shares[t * 9 + k * 3 + c] = rho[c] * ambient[c];
    }
  }
  return shares;
}

// Every edge of the triangulation once, as thin dark lines.
export function buildEdges(data, planes) {
  const { index, position, triangle_surface: owner } = data.arrays;
  const seen = new Set();
  const ends = [];
  const surfaces = [];
  const n = data.vertex_count;
  for (let t = 0; t < index.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = index[t + k];
      const b = index[t + ((k + 1) % 3)];
      const key = Math.min(a, b) * n + Math.max(a, b);
      if (seen.has(key)) continue;
      seen.add(key);
      ends.push(a, b);
      surfaces.push(owner[t / 3]);
    }
  }
  const points = new Float32Array(ends.length * 3);
  const plane = new Float32Array(ends.length * 4);
  ends.forEach((v, i) => {
    points.set(position.subarray(v * 3, v * 3 + 3), i * 3);
    plane.set(planes[surfaces[i >> 1]], i * 4);
  });
  const geometry = new BufferGeometry();
  geometry.setAttribute('position', new BufferAttribute(points, 3));
  geometry.setAttribute('plane', new BufferAttribute(plane, 4));
  const material = new ShaderMaterial({
    ...edgeShaders,
    uniforms: { colour: { value: new Vector4(0, 0, 0, 0.35) }, drawingViewport },
    transparent: true,
  });
  const lines = new LineSegments(geometry, material);
  lines.visible = false;
  return { lines, count: ends.length / 2 };
}

// The discontinuity segments, one object per order (D0, D1, D2), coloured by boundary; D0 lines
// (value jumps) dashed, as in the SVGs.
export function buildDiscontinuities(data, planes, diagonal) {
  const { line_position: positions, line_order: orders, line_boundary: boundaries, line_surface: owner } = data.arrays;
  const palette = data.boundaries.map((name) => new Color(boundaryColour(name)));
  const classes = [];
  for (let order = 0; order < 3; order++) {
    const chosen = [];
    for (let i = 0; i < orders.length; i++) if (orders[i] === order) chosen.push(i);
    const byBoundary = new Map();
    for (const i of chosen) byBoundary.set(boundaries[i], (byBoundary.get(boundaries[i]) ?? 0) + 1);
    if (chosen.length === 0) {
      classes.push({ order, count: 0, byBoundary, object: null });
      continue;
    }
    const xyz = new Float32Array(chosen.length * 6);
    const rgb = new Float32Array(chosen.length * 6);
    const plane = new Float32Array(chosen.length * 4);
    chosen.forEach((line, j) => {
      xyz.set(positions.subarray(line * 6, line * 6 + 6), j * 6);
      plane.set(planes[owner[line]], j * 4);
      const c = palette[boundaries[line]];
      rgb.set([c.r, c.g, c.b, c.r, c.g, c.b], j * 6);
    });
    const geometry = new LineSegmentsGeometry();
    geometry.setPositions(xyz);
    geometry.setColors(rgb);
    geometry.setAttribute('plane', new InstancedBufferAttribute(plane, 4));
    const material = paintedLineMaterial({
      linewidth: LINE_WIDTH,
      vertexColors: true,
      dashed: order === 0,
      dashSize: diagonal * 0.01,
      gapSize: diagonal * 0.006,
    });
    const object = new LineSegments2(geometry, material);
    if (order === 0) object.computeLineDistances();
    classes.push({ order, count: chosen.length, byBoundary, object });
  }
  return classes;
}

// Each surface's boundary edges (those of one triangle only: a surface's own triangulation
// has no T-junctions, so cracks open only where surfaces meet) as lines with the surface's
// values. With each, the plane of a surface it lies on that has the line's surface in front
// (the floor under a block's side), or zeros. In scenes too large to match every edge with
// every plane, zeros: an outline may then show through a surface it meets, seen from behind.
function buildSeams(data, geometry, planes, diagonal, uniforms) {
  const { triangle_surface: owner } = data.arrays;
  const p = geometry.getAttribute('position').array;
  // Edges by their ends' positions: the two sides of a value jump (D0) carry separate vertices
  // at the same places, and meet without a crack.
  const at = (c) => `${p[c * 3]},${p[c * 3 + 1]},${p[c * 3 + 2]}`;
  const key = (c, d) => {
    const [u, v] = [at(c), at(d)];
    return u < v ? `${u} ${v}` : `${v} ${u}`;
  };
  const uses = new Map();
  for (let c = 0; c < p.length / 3; c += 3) {
    for (let k = 0; k < 3; k++) {
      const edge = key(c + k, c + ((k + 1) % 3));
      uses.set(edge, (uses.get(edge) ?? 0) + 1);
    }
  }
  // Each boundary edge as its two corners and the triangle's third, in the separate triangles.
  const corners = [];
  for (let c = 0; c < p.length / 3; c += 3) {
    for (let k = 0; k < 3; k++) {
      if (uses.get(key(c + k, c + ((k + 1) % 3))) === 1) corners.push(c + k, c + ((k + 1) % 3), c + ((k + 2) % 3));
    }
  }
  const count = corners.length / 3;
  const seams = new BufferGeometry();
  for (const name of ['position', 'radiosity', 'direct', 'indirect', 'ambientShare', 'errorColour']) {
    const from = geometry.getAttribute(name).array;
    const to = new Float32Array(count * 6);
    for (let e = 0; e < count; e++) {
      to.set(from.subarray(corners[e * 3] * 3, corners[e * 3] * 3 + 3), e * 6);
      to.set(from.subarray(corners[e * 3 + 1] * 3, corners[e * 3 + 1] * 3 + 3), e * 6 + 3);
    }
    seams.setAttribute(name, new BufferAttribute(to, 3));
  }
  const tolerance = 1e-5 * diagonal;
  const plane = new Float32Array(count * 8);
  const beyond = new Float32Array(count * 8);
  const a = new Vector3();
  const b = new Vector3();
  const edge = new Vector3();
  const inward = new Vector3();
  const on = (q, v) => Math.abs(q[0] * v.x + q[1] * v.y + q[2] * v.z - q[3]) <= tolerance;
  const match = count * planes.length <= MAX_SEAM_TESTS;
  for (let e = 0; e < count; e++) {
    const own = owner[Math.floor(corners[e * 3] / 3)];
    plane.set(planes[own], e * 8);
    plane.set(planes[own], e * 8 + 4);
    if (!match) continue;
    a.fromArray(p, corners[e * 3] * 3);
    b.fromArray(p, corners[e * 3 + 1] * 3);
    // Into the triangle, square to the edge.
    edge.subVectors(b, a).normalize();
    inward.fromArray(p, corners[e * 3 + 2] * 3).sub(a);
    inward.addScaledVector(edge, -inward.dot(edge));
    for (let s = 0; s < planes.length; s++) {
      const q = planes[s];
      if (s === own || !on(q, a) || !on(q, b)) continue;
      if (q[0] * inward.x + q[1] * inward.y + q[2] * inward.z > 0) {
        beyond.set(q, e * 8);
        beyond.set(q, e * 8 + 4);
        break;
      }
    }
  }
  seams.setAttribute('plane', new BufferAttribute(plane, 4));
  seams.setAttribute('beyond', new BufferAttribute(beyond, 4));
  seams.boundingBox = geometry.boundingBox;
  seams.boundingSphere = geometry.boundingSphere;
  return new LineSegments(seams, fillLinesMaterial(uniforms));
}

export function bounds(data) {
  const box = new Box3();
  const p = data.arrays.position;
  const v = new Vector3();
  for (let i = 0; i < p.length; i += 3) box.expandByPoint(v.set(p[i], p[i + 1], p[i + 2]));
  return box;
}
