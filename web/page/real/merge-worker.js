// The merge of the user's own maps, off the page's main thread.
//
// A module Web Worker that loads the same wasm build as the page and holds
// one `MapMerge` (crate/src/bindings/maps.rs). The page sends it the picked
// files' bytes; it reads them into maps (files.js matches each YAML to its
// image), draws each map into a small coloured picture for the page
// (preview.js), merges on request (the whole merge runs here, so the page
// never waits on it), hands back the report and the merged map's PGM,
// PNG and YAML, and draws the merged overlay (overlay.js) into the page's
// canvas, which the page hands over once. Messages in:
// `{id, type: 'add', files, resolution, colours}`, `{id, type: 'merge'}`,
// `{id, type: 'canvas', canvas}`, `{id, type: 'draw', width, height, dpr,
// alpha}`, `{id, type: 'clear'}`; out: `{id, ok, ...}` or
// `{id, ok: false, error}`, and `{type: 'progress', text}` while merging.

import init, * as wasm from '../../pkg/slamlab.js';
import { groupFiles } from './files.js';
import { previewOf } from './preview.js';
import { drawPlaced } from './overlay.js';

const ready = init();
let merger = null;
let colourIndex = 0;
/** What the overlay needs of each map read (by name), the last merge's placing, the canvas. */
let pictures = new Map();
let placed = [];
let overlay = null;

function message(e) {
  return e instanceof Error ? e.message : String(e);
}

/** Reads the picked files into maps; the good ones load even if some are bad. */
async function add({ files, resolution, colours }) {
  merger ??= new wasm.MapMerge();
  const { maps, errors } = groupFiles(files, (name, yaml) => wasm.mapImagePath(name, yaml), resolution);
  const added = [];
  const transfer = [];
  for (const m of maps) {
    let index;
    try {
      index = merger.addMap(m.name, m.yaml, m.imageName, m.image);
    } catch (e) {
      errors.push(message(e));
      continue;
    }
    const info = JSON.parse(merger.mapInfoJson(index));
    const colour = colours[colourIndex++ % colours.length];
    const { thumb, ...preview } = await previewOf(merger.mapPixels(index), info.width, info.height, colour);
    pictures.set(info.name, { ...info, preview });
    transfer.push(thumb);
    added.push({ ...info, index, imageName: m.imageName, colour, thumb });
  }
  return { result: { added, errors }, transfer };
}

/** Merges every map read so far; the merged map's files come with the report. */
function merge(id) {
  const t0 = performance.now();
  const report = JSON.parse(merger.mergeWithProgress((text) => postMessage({ type: 'progress', id, text })));
  const t1 = performance.now();
  let files = null;
  const transfer = [];
  if (report.merge.status === 'merged') {
    const pgm = merger.mergedPgm();
    const png = merger.mergedPng();
    files = { pgm, png, yaml: merger.mergedYaml('merged.pgm') };
    transfer.push(pgm.buffer, png.buffer);
  }
  report.timings_ms = { merge: t1 - t0, write: performance.now() - t1 };
  placed = report.merge.transforms
    .filter((t) => pictures.has(t.map))
    .map((t) => ({ map: pictures.get(t.map), pose: t.pose }));
  return { result: { report, files }, transfer };
}

self.onmessage = async ({ data }) => {
  const { id, type } = data;
  try {
    await ready;
    let out;
    if (type === 'add') out = await add(data);
    else if (type === 'merge') {
      if (!merger) throw new Error('open two or more maps first');
      out = merge(id);
    } else if (type === 'canvas') {
      overlay = data.canvas;
      out = { result: {}, transfer: [] };
    } else if (type === 'draw') {
      if (overlay) drawPlaced(overlay, data, placed);
      out = { result: {}, transfer: [] };
    } else if (type === 'clear') {
      merger?.free();
      merger = null;
      colourIndex = 0;
      pictures = new Map();
      placed = [];
      out = { result: {}, transfer: [] };
    } else throw new Error(`unknown request '${type}'`);
    postMessage({ id, ok: true, ...out.result }, out.transfer);
  } catch (e) {
    postMessage({ id, ok: false, error: message(e) });
  }
};
