// The panel that shows a picked point: its surface, position and the values there.

import { luminance } from './colour.js';
import { h } from './dom.js';
import * as format from './format.js';

// `size`: the scene's size, which sets how many decimals a position needs.
export function showPick(panel, pick, size, onClose) {
  const row = (label, rgb) => h('tr', {}, h('td', {}, label),
    rgb.map((v) => h('td', {}, format.value(v))), h('td', {}, format.value(luminance(rgb))));
  const surface = pick.surface;
  const emission = Array.isArray(surface.emission) && surface.emission.some((v) => v !== 0) ? surface.emission : null;
  panel.replaceChildren(...[
    h('div', { class: 'title' },
      h('strong', { id: 'pick-surface' }, surface.name),
      h('span', { class: 'count' }, `triangle ${format.count(pick.triangle)}`),
      h('button', { type: 'button', 'aria-label': 'Close', onclick: onClose }, '×')),
    h('div', { class: 'mono' }, `at ${format.position(pick.point.toArray(), size)}`),
    pick.back ? h('p', { class: 'note' }, 'Seen from the back: light leaves the front only. The values are the front\'s.') : null,
    h('table', {},
      h('caption', {}, 'W/m², interpolated linearly from the triangle\'s corners'),
      h('tr', {}, h('th', {}, ''), h('th', {}, 'R'), h('th', {}, 'G'), h('th', {}, 'B'), h('th', {}, 'luminance')),
      row('radiosity', pick.radiosity),
      row('direct', pick.direct),
      row('indirect', pick.indirect),
      emission ? row('emission', emission) : null),
    Array.isArray(surface.reflectance)
      ? h('p', { class: 'note' }, `Reflectance of the surface: ${format.point(surface.reflectance)}.`)
      : null,
    pick.error !== null
      ? h('p', { class: 'note' }, `Error indicator of the triangle: ${format.value(pick.error)} W/m².`)
      : null,
  ].filter(Boolean));
  panel.hidden = false;
}

export function hidePick(panel) {
  panel.hidden = true;
  panel.replaceChildren();
}
