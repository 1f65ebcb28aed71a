// Lines drawn on the surfaces (mesh edges, outlines, discontinuities): shown only on a surface's
// front, and painted onto its plane. Each line fragment takes its depth from the plane of the
// surface it lies on, at that very pixel, a hair nearer the eye: so a line wins over its own
// surface at any slant, with no depth offset on the surfaces. (An offset scaled by slope, the
// usual remedy, lets a slanted front lose to the back face behind it along a silhouette.)

import { Vector4 } from 'three';
import { LineMaterial } from 'three/examples/jsm/lines/LineMaterial.js';

// Vertex shader: lines of a surface seen from behind, where no light leaves, are moved out of
// view (a surface is planar, so that depends only on which side of its plane the eye is). Needs
// `attribute vec4 plane` ([n, n·p], n the front's unit normal) and `varying vec4 vPlane`.
export const CULL_BEHIND = /* glsl */ `
  vPlane = plane;
  if (dot(plane.xyz, cameraPosition) < plane.w) gl_Position = vec4(2.0, 2.0, 2.0, 1.0);`;

// Fragment shader: planeDepth(vPlane) is the window depth of the plane where this pixel's view
// ray meets it, brought nearer by the plane's depth change over 3/8 of a pixel (4x antialiasing
// samples the surface that far from the pixel's centre, where the line's depth is taken) and a
// hair more. A surface nearer than that in front of the line's own (a lamp just under a
// ceiling, seen at a slant) does not hide it.
export const PLANE_DEPTH = /* glsl */ `
uniform mat4 projectionMatrix;
uniform vec4 drawingViewport;
varying vec4 vPlane;
const float LINE_LIFT = 1.0 / 1048576.0;
float planeDepth(vec4 plane) {
  vec2 ndc = (gl_FragCoord.xy - drawingViewport.xy) / drawingViewport.zw * 2.0 - 1.0;
  vec3 ray = vec3((ndc.x + projectionMatrix[2][0]) / projectionMatrix[0][0],
                  (ndc.y + projectionMatrix[2][1]) / projectionMatrix[1][1], -1.0);
  vec3 normal = mat3(viewMatrix) * plane.xyz;
  float along = dot(normal, ray);
  // A ray along the plane (the line seen edge-on) meets it far away: nothing to cover then.
  along = along < 0.0 ? min(along, -1e-6) : max(along, 1e-6);
  float viewZ = -(plane.w - dot(plane.xyz, cameraPosition)) / along;
  float ndcZ = (projectionMatrix[2][2] * viewZ + projectionMatrix[3][2]) / -viewZ;
  float depth = 0.5 * ndcZ + 0.5;
  return clamp(depth - 0.375 * fwidth(depth) - LINE_LIFT, 0.0, 1.0);
}
`;

// The drawing buffer's viewport, which PLANE_DEPTH needs to turn pixels into view rays; one
// object for every line material, set before each frame.
export const drawingViewport = { value: new Vector4(0, 0, 1, 1) };

// Thin lines of one colour (the mesh edges).
export const edgeShaders = {
  vertexShader: /* glsl */ `
attribute vec4 plane;
varying vec4 vPlane;
void main() {
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);${CULL_BEHIND}
}`,
  fragmentShader: /* glsl */ `
uniform vec4 colour;
${PLANE_DEPTH}
void main() {
  gl_FragDepth = planeDepth(vPlane);
  gl_FragColor = colour;
}`,
};

// three's wide lines (LineSegments2), culled and painted onto their surface's plane like the
// others: the anchors are those of three 0.187.0's shader, pinned in package.json.
export function paintedLineMaterial(parameters) {
  const material = new LineMaterial(parameters);
  const patches = [
    ['vertexShader', 'attribute vec3 instanceEnd;', 'attribute vec3 instanceEnd;\nattribute vec4 plane;\nvarying vec4 vPlane;'],
    ['vertexShader', 'gl_Position = clip;', `gl_Position = clip;${CULL_BEHIND}`],
    ['fragmentShader', 'void main() {', `${PLANE_DEPTH}\nvoid main() {\n  gl_FragDepth = planeDepth(vPlane);`],
  ];
  for (const [shader, anchor, replacement] of patches) {
    if (material[shader].split(anchor).length !== 2) {
      throw new Error(`three.js's line shader has changed: "${anchor}" is not found once in its ${shader}`);
    }
    material[shader] = material[shader].replace(anchor, replacement);
  }
  material.uniforms.drawingViewport = drawingViewport;
  return material;
}
