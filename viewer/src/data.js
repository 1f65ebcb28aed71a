// The page's data block: parsing, checking and decoding into typed arrays.

export const FORMAT = 'penumbra-viewer/1';

// A problem with the data, worded for the person reading the page.
export class DataError extends Error {}

// The arrays, their element type and how many values they hold per vertex, triangle or line.
const ARRAYS = {
  position: ['f32', 'vertex_count', 3],
  radiosity: ['f32', 'vertex_count', 3],
  direct: ['f32', 'vertex_count', 3],
  indirect: ['f32', 'vertex_count', 3],
  index: ['u32', 'triangle_count', 3],
  triangle_surface: ['u32', 'triangle_count', 1],
  error: ['f32', 'triangle_count', 1],
  line_position: ['f32', 'line_count', 6],
  line_order: ['u8', 'line_count', 1],
  line_event: ['u8', 'line_count', 1],
  line_boundary: ['u8', 'line_count', 1],
  line_surface: ['u32', 'line_count', 1],
};
const OPTIONAL = new Set(['error']);
const TYPES = {
  f32: [Float32Array, 4, 'getFloat32'],
  u32: [Uint32Array, 4, 'getUint32'],
  u8: [Uint8Array, 1, 'getUint8'],
};
const LITTLE_ENDIAN = new Uint8Array(new Uint32Array([1]).buffer)[0] === 1;

// Reads the JSON in the element with id `penumbra-data` and returns it with `arrays` decoded.
export function readData(doc) {
  const element = doc.getElementById('penumbra-data');
  if (!element) throw new DataError('The page has no data block (a script element with id "penumbra-data").');
  const text = element.textContent.trim();
  // An unfilled template still holds its placeholder comment.
  if (text === '' || text.startsWith('/*')) {
    throw new DataError('The page holds no data: it is the viewer\'s template, not a page written by "penumbra run --export html".');
  }
  let json;
  try {
    json = JSON.parse(text);
  } catch (e) {
    throw new DataError(`The data block is not valid JSON (${e.message}).`);
  }
  return decode(json);
}

function decode(json) {
  if (json === null || typeof json !== 'object' || Array.isArray(json)) {
    throw new DataError('The data block is not a JSON object.');
  }
  if (json.format !== FORMAT) {
    throw new DataError(`The data's format is ${JSON.stringify(json.format)}; this viewer reads "${FORMAT}".`);
  }
  const counts = {};
  for (const key of ['vertex_count', 'triangle_count', 'line_count']) {
    const n = json[key];
    if (!Number.isInteger(n) || n < 0) throw new DataError(`"${key}" must be a count (a non-negative integer), not ${JSON.stringify(n)}.`);
    counts[key] = n;
  }
  if (counts.triangle_count === 0) throw new DataError('The data has no triangles to show.');
  for (const key of ['surfaces', 'events', 'boundaries']) {
    if (!Array.isArray(json[key])) throw new DataError(`"${key}" must be an array.`);
  }
  json.surfaces.forEach((s, i) => {
    if (!s || typeof s.name !== 'string') throw new DataError(`Surface ${i} has no name.`);
  });
  const display = json.display;
  if (!display || !(display.exposure > 0) || !Number.isFinite(display.exposure)) {
    throw new DataError('"display.exposure" must be a positive number.');
  }
  if (!isVector(display.ambient)) throw new DataError('"display.ambient" must be three numbers.');
  if (json.camera != null) checkCamera(json.camera);
  if (!json.arrays || typeof json.arrays !== 'object') throw new DataError('The data has no "arrays".');

  const arrays = {};
  for (const [name, [type, countKey, per]] of Object.entries(ARRAYS)) {
    const encoded = json.arrays[name];
    if (encoded === undefined && OPTIONAL.has(name)) continue;
    if (typeof encoded !== 'string') throw new DataError(`"arrays.${name}" is missing (it must be a base64 string).`);
    arrays[name] = decodeArray(name, encoded, type, counts[countKey] * per);
  }
  checkIndices(arrays.index, counts.vertex_count, 'arrays.index', 'vertex_count');
  checkIndices(arrays.triangle_surface, json.surfaces.length, 'arrays.triangle_surface', 'surfaces');
  checkIndices(arrays.line_order, 3, 'arrays.line_order', 'the three orders');
  checkIndices(arrays.line_event, json.events.length, 'arrays.line_event', 'events');
  checkIndices(arrays.line_boundary, json.boundaries.length, 'arrays.line_boundary', 'boundaries');
  checkIndices(arrays.line_surface, json.surfaces.length, 'arrays.line_surface', 'surfaces');
  for (const name of ['position', 'radiosity', 'direct', 'indirect', 'error', 'line_position']) {
    if (!arrays[name]) continue;
    const bad = arrays[name].findIndex((v) => !Number.isFinite(v));
    if (bad >= 0) throw new DataError(`"arrays.${name}" holds a value that is not a finite number (element ${bad}).`);
  }
  return { ...json, ...counts, arrays };
}

function isVector(v) {
  return Array.isArray(v) && v.length === 3 && v.every((x) => typeof x === 'number' && Number.isFinite(x));
}

function checkCamera(camera) {
  for (const key of ['eye', 'target', 'up']) {
    if (!isVector(camera[key])) throw new DataError(`"camera.${key}" must be three numbers.`);
  }
  if (!(camera.fov_deg > 0 && camera.fov_deg < 180)) throw new DataError('"camera.fov_deg" must be between 0 and 180 degrees.');
}

function decodeArray(name, encoded, type, length) {
  let bytes;
  try {
    const binary = atob(encoded);
    bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
  } catch {
    throw new DataError(`"arrays.${name}" is not valid base64.`);
  }
  const [Type, size, getter] = TYPES[type];
  if (bytes.length !== length * size) {
    throw new DataError(`"arrays.${name}" holds ${bytes.length} bytes; the counts call for ${length} values of ${size} byte${size > 1 ? 's' : ''} (${length * size} bytes).`);
  }
  if (LITTLE_ENDIAN || size === 1) return new Type(bytes.buffer);
  const view = new DataView(bytes.buffer);
  const out = new Type(length);
  for (let i = 0; i < length; i++) out[i] = view[getter](i * size, true);
  return out;
}

function checkIndices(values, limit, name, what) {
  for (let i = 0; i < values.length; i++) {
    if (values[i] >= limit) {
      throw new DataError(`"${name}" holds ${values[i]} at element ${i}, beyond ${what} (${limit}).`);
    }
  }
}
