// From values to display colours: the renderer's sRGB curve, luminance, the error colour map.

// The sRGB transfer curve (IEC 61966-2-1), clamped to [0, 1], as viz/src/tonemap.rs has it.
export function srgbEncode(linear) {
  if (!(linear > 0)) return 0;
  if (linear >= 1) return 1;
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * Math.pow(linear, 1 / 2.4) - 0.055;
}

// Relative luminance of linear RGB (Rec. 709 primaries).
export function luminance(rgb) {
  return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

// Discontinuity lines by boundary, as in the surfaces' SVGs (viz/src/surface_svg.rs).
export const BOUNDARY_COLOURS = {
  umbra: '#6a1b9a',
  penumbra: '#e65100',
  inner: '#2e7d32',
};
const OTHER_BOUNDARY = '#9e9e9e';

export function boundaryColour(name) {
  return BOUNDARY_COLOURS[name] ?? OTHER_BOUNDARY;
}

// matplotlib's viridis at eleven even stops (sRGB): perceptually uniform and readable in grey.
const VIRIDIS = [
  0x440154, 0x482475, 0x414487, 0x355f8d, 0x2a788e, 0x21918c,
  0x22a884, 0x44bf70, 0x7ad151, 0xbddf26, 0xfde725,
].map((c) => [(c >> 16) / 255, ((c >> 8) & 255) / 255, (c & 255) / 255]);

// Viridis at t in [0, 1] as encoded sRGB in [0, 1].
export function viridis(t) {
  const x = Math.min(Math.max(t, 0), 1) * (VIRIDIS.length - 1);
  const i = Math.min(Math.floor(x), VIRIDIS.length - 2);
  const f = x - i;
  const a = VIRIDIS[i];
  const b = VIRIDIS[i + 1];
  return [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])];
}

// A log scale once the positive values span this many times their smallest.
const LOG_SPAN = 100;
// A log scale shows at most this many decades below the largest value: errors far below the
// largest do not matter, and a wider range would flatten the ones that do.
const MAX_DECADES = 4;

// The error colour map's range: linear from 0, or logarithmic when the values span decades.
// `position(v)` gives t in [0, 1].
export function errorScale(values) {
  let hi = 0;
  let loPositive = Infinity;
  for (const v of values) {
    if (v > hi) hi = v;
    if (v > 0 && v < loPositive) loPositive = v;
  }
  if (!(hi > 0)) return { log: false, lo: 0, hi: 1, position: () => 0 };
  if (hi / loPositive < LOG_SPAN) {
    return { log: false, lo: 0, hi, position: (v) => v / hi };
  }
  const lo = Math.max(loPositive, hi * 10 ** -MAX_DECADES);
  const logLo = Math.log10(lo);
  const span = Math.log10(hi) - logLo;
  return {
    log: true,
    lo,
    hi,
    clipped: loPositive < lo || values.some((v) => !(v > 0)),
    position: (v) => (v > 0 ? (Math.log10(v) - logLo) / span : 0),
  };
}

// Round numbers between lo and hi, about `count` of them (linear scales).
export function niceTicks(lo, hi, count) {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / count;
  const magnitude = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * magnitude).find((s) => s >= raw);
  const ticks = [];
  for (let k = Math.ceil(lo / step - 1e-9); k * step <= hi * (1 + 1e-9); k++) ticks.push(k * step);
  return ticks;
}

// Powers of ten between lo and hi (log scales), thinned to at most `count`.
export function decadeTicks(lo, hi, count) {
  const first = Math.ceil(Math.log10(lo) - 1e-9);
  const last = Math.floor(Math.log10(hi) + 1e-9);
  const every = Math.max(1, Math.ceil((last - first + 1) / count));
  const ticks = [];
  for (let e = last; e >= first; e -= every) ticks.unshift(10 ** e);
  return ticks;
}
