// The surfaces' shader: linear values interpolated over each triangle, then exposure and the
// sRGB curve per fragment, as render.png does per pixel (encoding per vertex would brighten the
// insides of triangles).

import { BackSide, FrontSide, ShaderMaterial, Vector2 } from 'three';
import { CULL_BEHIND, PLANE_DEPTH, drawingViewport } from './lines.js';

export const MODES = ['radiosity', 'direct', 'indirect', 'error'];

// Back faces send no light; the renderer shows them black. Here they are a dark grey, shaded by
// their slant, so that the geometry reads from outside the box.
const BACK_GREY = [0.16, 0.27];

// With FILL_LINES the same shader draws the surfaces' outlines as lines (see lines.js), to fill
// the pixel-wide cracks the rasterizer leaves where one surface's vertex lies on another's edge
// (T-junctions, where two surfaces meet). Not where the plane of the surface met there lies
// between the eye and the line's surface (a block's foot seen from under the floor): painted on
// its own plane, the line would show through that surface's back along the seam.
const vertexShader = /* glsl */ `
attribute vec3 radiosity;
attribute vec3 direct;
attribute vec3 indirect;
attribute vec3 ambientShare;
attribute vec3 errorColour;
uniform int mode;
varying vec3 vLight;
varying vec3 vErrorColour;
varying vec3 vViewPosition;
#ifdef FILL_LINES
attribute vec4 plane;
attribute vec4 beyond;
varying vec4 vPlane;
#endif
void main() {
  // Radiosity is shown as render.png shows it, with the surface's share of the ambient term.
  vLight = mode == 0 ? radiosity + ambientShare : (mode == 1 ? direct : indirect);
  vErrorColour = errorColour;
  vec4 viewPosition = modelViewMatrix * vec4(position, 1.0);
  vViewPosition = viewPosition.xyz;
  gl_Position = projectionMatrix * viewPosition;
#ifdef FILL_LINES${CULL_BEHIND}
  if (dot(beyond.xyz, beyond.xyz) > 0.0 && dot(beyond.xyz, cameraPosition) < beyond.w) gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
#endif
}
`;

const fragmentShader = /* glsl */ `
uniform int mode;
uniform float exposure;
uniform vec2 backGrey;
varying vec3 vLight;
varying vec3 vErrorColour;
varying vec3 vViewPosition;
#ifdef FILL_LINES
${PLANE_DEPTH}
#endif
float srgbEncode(float x) {
  x = clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}
vec3 srgbEncode(vec3 c) {
  return vec3(srgbEncode(c.r), srgbEncode(c.g), srgbEncode(c.b));
}
void main() {
#ifdef FILL_LINES
  gl_FragDepth = planeDepth(vPlane);
#endif
  // Each material draws one side (gl_FrontFacing is flipped for three's BackSide materials).
#ifdef BACK_FACES
  bool front = false;
#else
  bool front = true;
#endif
  vec3 colour;
  if (!front) {
    vec3 normal = normalize(cross(dFdx(vViewPosition), dFdy(vViewPosition)));
    float slant = abs(dot(normal, normalize(vViewPosition)));
    colour = vec3(mix(backGrey.x, backGrey.y, slant));
  } else if (mode == 3) {
    colour = vErrorColour;
  } else {
    colour = srgbEncode(vLight * exposure);
  }
  gl_FragColor = vec4(colour, 1.0);
}
`;

// The uniforms the two materials share: a mode or exposure set once applies to both.
export function surfaceUniforms(display) {
  return {
    mode: { value: 0 },
    exposure: { value: display.exposure },
    backGrey: { value: new Vector2(...BACK_GREY) },
  };
}

// One material per side. Backs are pushed back in depth a little, so that where a front and a
// back meet along a silhouette, the front shows rather than a jagged grey seam.
export function surfaceMaterial(uniforms, back) {
  return new ShaderMaterial({
    vertexShader,
    fragmentShader,
    uniforms,
    side: back ? BackSide : FrontSide,
    defines: back ? { BACK_FACES: '' } : {},
    polygonOffset: back,
    polygonOffsetFactor: 0,
    polygonOffsetUnits: 4,
  });
}

export function fillLinesMaterial(uniforms) {
  return new ShaderMaterial({
    vertexShader,
    fragmentShader,
    uniforms: { ...uniforms, drawingViewport },
    defines: { FILL_LINES: '' },
  });
}

export function setMode(uniforms, mode) {
  uniforms.mode.value = MODES.indexOf(mode);
}

export function setExposure(uniforms, exposure) {
  uniforms.exposure.value = exposure;
}
