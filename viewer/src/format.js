// Numbers as text, the same whatever the browser's locale.

// An integer with thousands separators: 24,294.
export function count(n) {
  if (!Number.isFinite(n)) return '–';
  return Math.round(n).toString().replace(/\B(?=(\d{3})+(?!\d))/g, ',');
}

// A measured value to `digits` significant figures, in exponent form when very large or small.
export function value(v, digits = 3) {
  if (typeof v !== 'number' || Number.isNaN(v)) return '–';
  if (v === 0) return '0';
  const magnitude = Math.abs(v);
  if (magnitude >= 1e6 || magnitude < 1e-3) return v.toExponential(digits - 1).replace('e+', 'e');
  return trimZeros(v.toPrecision(digits));
}

// A scale's tick label: short, exact for round numbers.
export function tick(v) {
  if (v === 0) return '0';
  const magnitude = Math.abs(v);
  if (magnitude >= 1e5 || magnitude < 1e-3) {
    const e = Math.round(Math.log10(magnitude));
    if (Math.abs(magnitude - 10 ** e) < 1e-9 * magnitude) return `1e${e}`;
    return v.toExponential(1).replace('e+', 'e');
  }
  return trimZeros(v.toPrecision(4));
}

function trimZeros(s) {
  return s.includes('.') && !s.includes('e') ? s.replace(/\.?0+$/, '') : s;
}

export function seconds(s) {
  if (typeof s !== 'number') return '–';
  if (s < 1) return `${value(s * 1000)} ms`;
  if (s < 120) return `${value(s)} s`;
  return `${Math.floor(s / 60)} min ${Math.round(s % 60)} s`;
}

export function percent(fraction) {
  if (typeof fraction !== 'number') return '–';
  return `${(fraction * 100).toFixed(1)}%`;
}

export function point(p) {
  return `(${p.map((x) => value(x, 4)).join(', ')})`;
}

// A position in the scene to a ten-thousandth of the scene's size.
export function position(p, size) {
  const decimals = Math.min(Math.max(0, 4 - Math.ceil(Math.log10(size))), 12);
  const step = 10 ** -decimals;
  return `(${p.map((x) => (Math.abs(x) < step / 2 ? 0 : x).toFixed(decimals)).join(', ')})`;
}
