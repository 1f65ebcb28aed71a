// The side panel: the controls, the colour scale, the line colours and the run's figures.

import { boundaryColour, decadeTicks, luminance, niceTicks, srgbEncode, viridis } from './colour.js';
import { h } from './dom.js';
import * as format from './format.js';

const MODE_LABELS = {
  radiosity: 'Radiosity B (emitted + reflected)',
  direct: 'Direct light (reflected)',
  indirect: 'Indirect light (reflected)',
  error: 'Error indicator (per triangle)',
};
const ORDER_LABELS = ['D0 (value)', 'D1 (slope)', 'D2 (curvature)'];
const BOUNDARY_LABELS = { umbra: 'umbra boundary', penumbra: 'outer penumbra boundary', inner: 'inner penumbra line' };
// Tick labels closer than this fraction of the bar are dropped.
const TICK_GAP = 0.13;
const BAR_STEPS = 256;
// The exposure control's range, in stops either side of the run's exposure.
const STOPS = 5;

// `state`: mode, stops, exposure (the run's), errorScale, classes (discontinuities), edgeCount.
// `on`: mode(name), stops(n), edges(bool), order(k, bool), reset().
export function buildSidePanel(root, data, state, on) {
  const report = data.report && typeof data.report === 'object' ? data.report : null;

  const modes = ['radiosity', 'direct', 'indirect'].concat(data.arrays.error ? ['error'] : []);
  const select = h('select', { id: 'colour-mode', 'aria-label': 'Colour by', onchange: () => on.mode(select.value) },
    modes.map((m) => h('option', { value: m }, MODE_LABELS[m])));
  const bar = h('canvas', { width: BAR_STEPS, height: 1, 'aria-hidden': 'true' });
  const threshold = h('div', { class: 'threshold', title: 'The refinement\'s threshold in its last round' });
  const ticks = h('div', { class: 'ticks' });
  const scaleNote = h('p', { class: 'note' });
  const stopsInput = h('input', {
    type: 'range', id: 'exposure-stops', min: -STOPS, max: STOPS, step: 0.25, value: 0, 'aria-label': 'Exposure in stops',
    oninput: () => on.stops(Number(stopsInput.value)),
  });
  const exposureText = h('span', { class: 'count' });
  const exposureRow = h('div', { class: 'row' }, h('span', {}, 'Exposure'), stopsInput, exposureText);

  const toggle = (id, label, n, checked, onchange) => {
    const input = h('input', { type: 'checkbox', id, checked: checked && n > 0, disabled: n === 0, onchange: () => onchange(input.checked) });
    return h('div', { class: 'row' }, h('label', { for: id }, input, ' ', h('span', {}, label)), h('span', { class: 'count' }, format.count(n)));
  };
  const lineToggles = state.classes.map((c) =>
    toggle(`toggle-d${c.order}`, ORDER_LABELS[c.order], c.count, true, (v) => on.order(c.order, v)));

  root.append(...[
    h('h1', {}, 'penumbra ', h('span', { class: 'scene' }, data.scene ?? report?.scene?.name ?? '')),
    h('div', { class: 'sub' }, report?.version ? `penumbra ${report.version}` : data.format,
      report?.partial === true ? h('span', { class: 'badge', title: 'The run was cut short: the values are the best so far.' }, 'partial') : null),
    h('h2', {}, 'Colour by'),
    select,
    h('div', { class: 'scale', style: { marginTop: '8px' } }, bar, threshold, ticks),
    scaleNote,
    exposureRow,
    h('p', { class: 'note' }, h('span', { class: 'swatch box', style: { background: '#3a3d42' } }),
      'back faces: no light leaves them'),
    h('h2', {}, 'Show'),
    toggle('toggle-edges', 'Mesh edges', state.edgeCount, false, on.edges),
    lineToggles,
    h('div', { class: 'row', style: { marginTop: '8px' } },
      h('button', { id: 'reset-view', type: 'button', onclick: on.reset }, 'Reset view')),
    linesSection(data, state.classes),
    runSection(data, report),
    h('p', { class: 'help' },
      'Drag to orbit, right-drag or shift-drag to pan, scroll to zoom. Click a surface to read the values there.'),
    h('p', { class: 'help' }, 'Drawn with three.js r187 (MIT licence).'),
  ].flat(2).filter(Boolean));

  function updateScale() {
    const mode = state.mode;
    const context = bar.getContext('2d');
    const image = context.createImageData(BAR_STEPS, 1);
    const marks = [];
    let note;
    if (mode === 'error') {
      const scale = state.errorScale;
      for (let i = 0; i < BAR_STEPS; i++) paint(image, i, viridis(i / (BAR_STEPS - 1)));
      const values = scale.log ? decadeTicks(scale.lo, scale.hi, 6) : niceTicks(0, scale.hi, 4);
      for (const v of values) marks.push([scale.position(v), v]);
      note = scale.log
        ? `W/m², log scale, ${format.value(scale.lo)} to ${format.value(scale.hi)}${scale.clipped ? '; smaller values show as the lowest colour' : ''}.`
        : `W/m², linear scale, 0 to ${format.value(scale.hi)}.`;
      note += ' One colour per triangle: the refinement\'s estimate of its interpolation error.';
      const last = report?.refinement?.rounds?.at?.(-1);
      const t = last?.threshold > 0 ? scale.position(last.threshold) : NaN;
      threshold.hidden = !(t >= 0 && t <= 1);
      if (!threshold.hidden) {
        threshold.style.left = `${(t * 100).toFixed(2)}%`;
        note += ` White mark: the last round's threshold, ${format.value(last.threshold)} W/m²`;
        note += Number.isInteger(last.over_tolerance) ? ` (${format.count(last.over_tolerance)} triangles above).` : '.';
      }
      exposureRow.style.display = 'none';
    } else {
      const exposure = state.exposure * 2 ** state.stops;
      const ambient = mode === 'radiosity' && luminance(data.display.ambient) !== 0;
      for (let i = 0; i < BAR_STEPS; i++) {
        const g = i / (BAR_STEPS - 1);
        paint(image, i, [g, g, g]);
      }
      // White from this value on; the bar is even in display value, so ticks crowd at the top.
      const white = 1 / exposure;
      for (const v of niceTicks(0, white, 5)) marks.push([srgbEncode(v * exposure), v]);
      const formula = ambient ? 'sRGB((B + ρ·ambient) × exposure)' : 'sRGB(value × exposure)';
      note = `W/m² per channel, shown as ${formula}; white at ${format.value(white)} W/m² and above.`;
      if (ambient) {
        note += ` Ambient ${format.point(data.display.ambient)} W/m², the light not shot yet, for display only;`;
        note += ' each surface adds it times its reflectance ρ, as render.png does.';
      }
      exposureRow.style.display = '';
      threshold.hidden = true;
      exposureText.textContent = `${format.value(exposure)} m²/W`;
    }
    context.putImageData(image, 0, 0);
    ticks.replaceChildren();
    let last = -Infinity;
    for (const [position, v] of marks) {
      if (!(position >= 0 && position <= 1) || position - last < TICK_GAP) continue;
      last = position;
      ticks.append(h('span', { style: { left: `${(position * 100).toFixed(2)}%` } }, format.tick(v)));
    }
    scaleNote.textContent = note;
  }

  updateScale();
  return { updateScale };
}

function paint(image, i, rgb) {
  image.data.set([rgb[0] * 255, rgb[1] * 255, rgb[2] * 255, 255].map(Math.round), i * 4);
}

function linesSection(data, classes) {
  const total = new Map();
  for (const c of classes) for (const [b, n] of c.byBoundary) total.set(b, (total.get(b) ?? 0) + n);
  const rows = data.boundaries.map((name, b) =>
    h('div', { class: 'row' },
      h('span', {}, h('span', { class: 'swatch', style: { borderColor: boundaryColour(name) } }), BOUNDARY_LABELS[name] ?? name),
      h('span', { class: 'count' }, format.count(total.get(b) ?? 0))));
  const events = data.arrays.line_event;
  const byEvent = data.events.map((name, e) => [name, events.reduce((n, x) => n + (x === e), 0)]).filter(([, n]) => n > 0);
  return [
    h('h2', {}, 'Discontinuity lines'),
    rows,
    h('div', { class: 'row' },
      h('span', {}, h('span', { class: 'swatch dashed', style: { borderColor: '#c8ccd2' } }), 'dashed: D0, a jump in value')),
    byEvent.length ? h('p', { class: 'note' }, 'By event: ', byEvent.map(([name, n]) => `${name} ${format.count(n)}`).join(' · ')) : null,
  ];
}

function runSection(data, report) {
  if (!report) {
    return [h('h2', {}, 'Run'), h('p', { class: 'note' }, 'This page holds no report of the run.')];
  }
  const rows = [];
  const add = (label, text, title) => {
    if (text !== undefined && text !== null && text !== '') rows.push(h('tr', { title }, h('td', {}, label), h('td', {}, text)));
  };
  const scene = report.scene;
  add('scene', scene?.name, scene?.source);
  const method = report.method ?? {};
  add('mesh', method.mesh);
  const solver = report.solver ?? {};
  add('solver', method.solver);
  add('iterations', [Number.isInteger(solver.iterations) ? format.count(solver.iterations) : null, solver.stop].filter((x) => x !== null && x !== undefined).join(', '));
  const counts = report.counts ?? {};
  add('triangles', counts.triangles !== undefined ? format.count(counts.triangles) : undefined);
  add('vertices', counts.vertices !== undefined ? format.count(counts.vertices) : undefined);
  add('discontinuity segments', counts.discontinuity_segments !== undefined ? format.count(counts.discontinuity_segments) : undefined);
  const refinement = report.refinement;
  if (refinement) {
    add('refinement tol.', format.value(refinement.tolerance), 'As a fraction of the mean reflected radiosity');
    add('rounds', [Array.isArray(refinement.rounds) ? format.count(refinement.rounds.length) : null, refinement.stop].filter(Boolean).join(', '));
  }
  add('total time', report.times_seconds?.total !== undefined ? format.seconds(report.times_seconds.total) : undefined);
  if (typeof method.threads === 'number') add('threads', String(method.threads));
  const energy = report.energy;
  if (energy) {
    add('absorbed', format.percent(energy.absorbed_fraction), 'Absorbed over emitted power');
    add('escaped', format.percent(energy.escaped_fraction), 'Escaped over emitted power');
    add('energy balance', `${energy.balanced ? 'closes' : 'does not close'} (${format.value(energy.closure_error, 2)})`,
      'emitted = absorbed + escaped + unshot, to this relative error');
  }
  if (report.partial === true) add('partial', 'yes, cut short', 'The run was cut short: the values are the best so far');
  if (Array.isArray(report.warnings) && report.warnings.length) add('warnings', String(report.warnings.length));
  const warnings = Array.isArray(report.warnings)
    ? report.warnings.map((w) => h('p', { class: 'note' }, typeof w === 'string' ? w : w?.message ?? JSON.stringify(w)))
    : [];
  return [h('h2', {}, 'Run'), h('table', { class: 'figures' }, rows), warnings];
}
