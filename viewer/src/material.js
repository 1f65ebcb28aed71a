// The surfaces' shader: linear values interpolated over each triangle, then exposure and the
// sRGB curve per fragment, as render.png does per pixel (encoding per vertex would brighten the
// insides of triangles).

import { DoubleSide, ShaderMaterial, Vector2, Vector3 } from 'three';

export const MODES = ['radiosity', 'direct', 'indirect', 'error'];

// Back faces send no light; the renderer shows them black (plus ambient). Here they are a dark
// grey, shaded by their slant, so that the geometry reads from outside the box.
const BACK_GREY = [0.16, 0.27];

const vertexShader = /* glsl */ `
attribute vec3 radiosity;
attribute vec3 direct;
attribute vec3 indirect;
attribute vec3 errorColour;
uniform int mode;
varying vec3 vLight;
varying vec3 vErrorColour;
varying vec3 vViewPosition;
void main() {
  vLight = mode == 0 ? radiosity : (mode == 1 ? direct : indirect);
  vErrorColour = errorColour;
  vec4 viewPosition = modelViewMatrix * vec4(position, 1.0);
  vViewPosition = viewPosition.xyz;
  gl_Position = projectionMatrix * viewPosition;
}
`;

const fragmentShader = /* glsl */ `
uniform int mode;
uniform float exposure;
uniform vec3 ambient;
uniform vec2 backGrey;
varying vec3 vLight;
varying vec3 vErrorColour;
varying vec3 vViewPosition;
float srgbEncode(float x) {
  x = clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}
vec3 srgbEncode(vec3 c) {
  return vec3(srgbEncode(c.r), srgbEncode(c.g), srgbEncode(c.b));
}
void main() {
  vec3 colour;
  if (!gl_FrontFacing) {
    vec3 normal = normalize(cross(dFdx(vViewPosition), dFdy(vViewPosition)));
    float slant = abs(dot(normal, normalize(vViewPosition)));
    vec3 lit = mode == 0 ? srgbEncode(ambient * exposure) : vec3(0.0);
    colour = max(vec3(mix(backGrey.x, backGrey.y, slant)), lit);
  } else if (mode == 3) {
    colour = vErrorColour;
  } else {
    vec3 light = mode == 0 ? vLight + ambient : vLight;
    colour = srgbEncode(light * exposure);
  }
  gl_FragColor = vec4(colour, 1.0);
}
`;

export function surfaceMaterial(display) {
  return new ShaderMaterial({
    vertexShader,
    fragmentShader,
    side: DoubleSide,
    uniforms: {
      mode: { value: 0 },
      exposure: { value: display.exposure },
      ambient: { value: new Vector3(...display.ambient) },
      backGrey: { value: new Vector2(...BACK_GREY) },
    },
    // Pushed back in depth so that mesh edges and discontinuity lines on a surface win.
    polygonOffset: true,
    polygonOffsetFactor: 1,
    polygonOffsetUnits: 1,
  });
}

export function setMode(material, mode) {
  material.uniforms.mode.value = MODES.indexOf(mode);
}

export function setExposure(material, exposure) {
  material.uniforms.exposure.value = exposure;
}
