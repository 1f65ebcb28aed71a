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
} from 'three';
import { LineMaterial } from 'three/examples/jsm/lines/LineMaterial.js';
import { LineSegments2 } from 'three/examples/jsm/lines/LineSegments2.js';
import { LineSegmentsGeometry } from 'three/examples/jsm/lines/LineSegmentsGeometry.js';
import { boundaryColour, errorScale, viridis } from './colour.js';
import { surfaceMaterial } from './material.js';

// Width of discontinuity lines in CSS pixels.
const LINE_WIDTH = 2.5;
// Lines on a surface are drawn only where its front can be seen: from behind, where no light
// leaves, they would show through it. A surface is planar, so that depends only on which side of
// its plane the eye is; the vertex shaders move the lines of the far side out of view.
const CULL_BEHIND = /* glsl */ `
  if (dot(plane.xyz, cameraPosition) < plane.w) gl_Position = vec4(2.0, 2.0, 2.0, 1.0);`;

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
// indicator can be flat per triangle while the light is interpolated per vertex.
export function buildSurfaces(data) {
  const { index, position, radiosity, direct, indirect, error } = data.arrays;
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
  const mesh = new Mesh(geometry, surfaceMaterial(data.display));
  return { mesh, errorScale: scale };
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
    vertexShader: `attribute vec4 plane;
void main() {
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);${CULL_BEHIND}
}`,
    fragmentShader: 'void main() { gl_FragColor = vec4(0.0, 0.0, 0.0, 0.35); }',
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
    const material = new LineMaterial({
      linewidth: LINE_WIDTH,
      vertexColors: true,
      dashed: order === 0,
      dashSize: diagonal * 0.01,
      gapSize: diagonal * 0.006,
    });
    cullBehind(material);
    const object = new LineSegments2(geometry, material);
    if (order === 0) object.computeLineDistances();
    // Drawn after the surfaces so that their depth is known.
    object.renderOrder = 1;
    classes.push({ order, count: chosen.length, byBoundary, object });
  }
  return classes;
}

// Adds CULL_BEHIND to three's fat-line shader (pinned with three, so the anchors are known).
function cullBehind(material) {
  const anchors = ['attribute vec3 instanceEnd;', 'gl_Position = clip;'];
  if (!anchors.every((a) => material.vertexShader.includes(a))) {
    throw new Error('three.js\'s line shader has changed: discontinuity lines cannot be hidden from behind');
  }
  material.vertexShader = material.vertexShader
    .replace(anchors[0], `${anchors[0]}\nattribute vec4 plane;`)
    .replace(anchors[1], `${anchors[1]}${CULL_BEHIND}`);
}

export function bounds(data) {
  const box = new Box3();
  const p = data.arrays.position;
  const v = new Vector3();
  for (let i = 0; i < p.length; i += 3) box.expandByPoint(v.set(p[i], p[i + 1], p[i + 2]));
  return box;
}
