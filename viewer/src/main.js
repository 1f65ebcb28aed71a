// The viewer page: reads the run's data, draws the surfaces and lines, wires up the controls.
// Flags for scripts and tests: window.penumbraReady (first frame drawn), window.penumbraError
// (the message shown), window.penumbraFrame (frames drawn so far).

import { Color, Scene, Vector2, Vector3, WebGLRenderer } from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { applyView, fitAspect, fitClipping, initialView, makeCamera } from './camera.js';
import { DataError, readData } from './data.js';
import { h } from './dom.js';
import { bounds, buildDiscontinuities, buildEdges, buildSurfaces, surfacePlanes } from './geometry.js';
import { buildSidePanel } from './legend.js';
import { drawingViewport } from './lines.js';
import { setExposure, setMode } from './material.js';
import { hidePick, showPick } from './pickpanel.js';
import { Picker } from './picking.js';

const BACKGROUND = 0x16181b;
// A press that moves further than this (CSS pixels) is a drag, not a pick.
const CLICK_SLOP = 4;

function showError(message) {
  window.penumbraError = message;
  document.body.dataset.error = 'true';
  const box = document.getElementById('message');
  if (box) {
    box.replaceChildren(h('div', {}, h('h2', {}, 'The viewer cannot show this run'), h('p', {}, message)));
    box.hidden = false;
  } else {
    document.body.textContent = message;
  }
}

function start() {
  // The page's own message, for when this script does not run at all.
  document.getElementById('message').hidden = true;
  const data = readData(document);
  const view = document.getElementById('view');
  const side = document.getElementById('side');
  const pickPanel = document.getElementById('pick');

  let renderer;
  try {
    renderer = new WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    throw new DataError(`This browser could not start WebGL 2, which the viewer needs (${e.message}).`);
  }
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.setClearColor(BACKGROUND, 1);
  view.prepend(renderer.domElement);
  renderer.domElement.setAttribute('aria-label', 'The scene in 3D');

  const box = bounds(data);
  const diagonal = box.getSize(new Vector3()).length();
  const scene = new Scene();
  scene.background = new Color(BACKGROUND);
  const planes = surfacePlanes(data);
  const { meshes, fill, uniforms, errorScale } = buildSurfaces(data, planes, diagonal);
  const edges = buildEdges(data, planes);
  const classes = buildDiscontinuities(data, planes, diagonal);
  const picker = new Picker(data, meshes);
  scene.add(...meshes, fill, edges.lines, picker.marker);
  for (const c of classes) if (c.object) scene.add(c.object);

  const home = initialView(data, box);
  const camera = makeCamera(home);
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.screenSpacePanning = true;
  controls.addEventListener('change', () => requestFrame());

  const state = {
    mode: 'radiosity', stops: 0, exposure: data.display.exposure, errorScale, classes, edgeCount: edges.count,
  };
  const panel = buildSidePanel(side, data, state, {
    mode(mode) {
      state.mode = mode;
      setMode(uniforms, mode);
      panel.updateScale();
      requestFrame();
    },
    stops(stops) {
      state.stops = stops;
      setExposure(uniforms, state.exposure * 2 ** stops);
      panel.updateScale();
      requestFrame();
    },
    edges(on) {
      edges.lines.visible = on;
      requestFrame();
    },
    order(k, on) {
      classes[k].object.visible = on;
      requestFrame();
    },
    reset() {
      applyView(camera, controls, home);
      requestFrame();
    },
  });

  let frames = 0;
  const drawingSize = new Vector2();
  function draw() {
    fitClipping(camera, box);
    renderer.getDrawingBufferSize(drawingSize);
    drawingViewport.value.set(0, 0, drawingSize.x, drawingSize.y);
    picker.update(camera);
    renderer.render(scene, camera);
    window.penumbraFrame = ++frames;
  }
  let pending = false;
  function requestFrame() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      draw();
    });
  }

  function resize() {
    const { clientWidth: w, clientHeight: hgt } = view;
    renderer.setSize(w, hgt, false);
    fitAspect(camera, w, hgt);
  }

  // A click (not a drag) picks the surface under the pointer.
  const canvas = renderer.domElement;
  let down = null;
  canvas.addEventListener('pointerdown', (e) => { down = e.button === 0 ? [e.clientX, e.clientY] : null; });
  canvas.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > CLICK_SLOP) return;
    const rect = canvas.getBoundingClientRect();
    const ndc = {
      x: ((e.clientX - rect.left) / rect.width) * 2 - 1,
      y: -((e.clientY - rect.top) / rect.height) * 2 + 1,
    };
    const pick = picker.pick(ndc, camera);
    if (pick) {
      picker.show(pick.point);
      showPick(pickPanel, pick, diagonal, () => { hidePick(pickPanel); picker.hide(); requestFrame(); });
    } else {
      hidePick(pickPanel);
      picker.hide();
    }
    requestFrame();
  });

  renderer.domElement.addEventListener('webglcontextlost', (e) => {
    e.preventDefault();
    showError('The browser lost the WebGL context (too little graphics memory?). Reload the page to try again.');
  });

  // Where a scene point appears, in client coordinates (for tests that click on a known surface).
  window.penumbraViewer = {
    project(point) {
      const p = new Vector3(...point).project(camera);
      const rect = canvas.getBoundingClientRect();
      return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
    },
  };

  resize();
  applyView(camera, controls, home);
  new ResizeObserver(() => { resize(); requestFrame(); }).observe(view);
  draw();
  window.penumbraReady = true;
  document.body.dataset.ready = 'true';
}

function main() {
  try {
    start();
  } catch (e) {
    const message = e instanceof DataError ? e.message : `Unexpected error: ${e && e.message ? e.message : e}`;
    showError(message);
    if (!(e instanceof DataError)) console.error(e);
  }
}

window.addEventListener('error', (e) => {
  if (!window.penumbraError) showError(`Unexpected error: ${e.message}`);
});
main();
