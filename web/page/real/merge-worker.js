// The saved-maps merge of "Your maps", off the page's main thread.
//
// A module Web Worker that loads the same wasm build as the page and holds
// one set of saved maps (web/saved-maps.js, the facade over the binding's
// `MapMerge`). The page sends it the picked files' bytes; it reads them
// into maps (files.js matches each YAML to its image), draws each map into
// a small coloured picture for the page (preview.js), merges on request
// (the whole merge runs here, so the page never waits on it), hands back
// the report and the merged map's PGM, PNG and YAML, and draws the merged
// overlay (overlay.js) into the page's canvas, which the page hands over
// once. Messages in:
// `{id, type: 'add', files, resolution, colours}`, `{id, type: 'merge'}`,
// `{id, type: 'canvas', canvas}`, `{id, type: 'draw', width, height, dpr,
// alpha}`, `{id, type: 'clear'}`, and for placing a map by hand (the
// page's Refine, adjust.js): `{id, type: 'adjust', a, b, pose, fit}` (map
// b's frame at `pose` in map a's: shown, the view kept still unless
// `fit`), `{id, type: 'refine', a, b, pose}` (aligns from there, answers
// `{pair, report, files}` as a merge does), `{id, type: 'endAdjust'}`;
// out: `{id, ok, ...}` or `{id, ok: false, error}`, and
// `{type: 'progress', text}` while merging. Draws answer with the view
// used (`{view: {k, e, f, width, height, dpr}}`).

import init, * as wasm from '../../pkg/slamlab.js';
import { SavedMaps, mapImagePath } from '../../saved-maps.js';
import { BagFile, bagKind } from '../../bag-file.js';
import { groupFiles } from './files.js';
import { previewOf } from './preview.js';
import { compose, drawPlaced, fitView } from './overlay.js';

const ready = init();
/** The maps read so far (a SavedMaps), null before the first. */
let savedMaps = null;
let colourIndex = 0;
/** What the overlay needs of each map read (by name), the last merge's placing, the canvas. */
let pictures = new Map();
let placed = [];
let overlay = null;
/** While a map is placed by hand: `{a, b, pose}` (indices) and the still view. */
let adjusting = null;
let view = null;
let lastSize = null;

function message(e) {
  return e instanceof Error ? e.message : String(e);
}

/** True for a bag file: named as one, or starting as one. */
function isBag(f) {
  return /\.(bag|mcap|db3)$/i.test(f.name) || bagKind(wasm, new Uint8Array(f.bytes, 0, Math.min(16, f.bytes.byteLength))) !== '';
}

/** A bag's /map (or only OccupancyGrid topic), read in pieces, into the saved maps; its index. */
function addBag(f) {
  const bag = BagFile.open(wasm, f.name);
  try {
    const bytes = new Uint8Array(f.bytes);
    for (let at = 0; at < bytes.length; at += 8 << 20) bag.push(bytes.subarray(at, at + (8 << 20)));
    bag.finish();
    return savedMaps.addBagMap(bag);
  } finally {
    bag.free();
  }
}

/** Reads the picked files into maps (a bag's map too); the good ones load even if some are bad. */
async function add({ files, resolution, colours }) {
  savedMaps ??= SavedMaps.open(wasm);
  const bags = files.filter(isBag);
  const { maps, errors } = groupFiles(files.filter((f) => !isBag(f)), (name, yaml) => mapImagePath(wasm, name, yaml), resolution);
  const added = [];
  const transfer = [];
  const reads = [
    ...maps.map((m) => [m.imageName, () => savedMaps.addMap(m.name, m.yaml, m.imageName, m.image)]),
    ...bags.map((f) => [f.name, () => addBag(f)]),
  ];
  for (const [imageName, read] of reads) {
    let index;
    try {
      index = read();
    } catch (e) {
      errors.push(message(e));
      continue;
    }
    const info = savedMaps.mapInfo(index);
    const colour = colours[colourIndex++ % colours.length];
    const { thumb, ...preview } = await previewOf(savedMaps.mapPixels(index), info.width, info.height, colour);
    pictures.set(info.name, { ...info, index, preview });
    transfer.push(thumb);
    added.push({ ...info, index, imageName, colour, thumb });
  }
  return { result: { added, errors }, transfer };
}

/** Merges every map read so far; the merged map's files come with the report. */
function merge(id) {
  const t0 = performance.now();
  const report = savedMaps.mergeWithProgress((text) => postMessage({ type: 'progress', id, text }));
  adjusting = null; // a new merge ends any placing by hand
  view = null;
  return withFiles(report, t0);
}

/** Aligns map b on map a again from the page's guess; the report follows it. */
function refine({ a, b, pose }) {
  const t0 = performance.now();
  const pair = savedMaps.refine(a, b, pose);
  const out = withFiles(savedMaps.report(), t0);
  adjusting = null;
  view = null;
  out.result.pair = pair;
  return out;
}

/** The report with the merged map's files (when merged) and the overlay's placing. */
function withFiles(report, t0) {
  const t1 = performance.now();
  let files = null;
  const transfer = [];
  if (report.merge.status === 'merged') {
    const pgm = savedMaps.mergedPgm();
    const png = savedMaps.mergedPng();
    files = { pgm, png, yaml: savedMaps.mergedYaml('merged.pgm') };
    transfer.push(pgm.buffer, png.buffer);
  }
  report.timings_ms = { merge: t1 - t0, write: performance.now() - t1 };
  placed = report.merge.transforms
    .filter((t) => pictures.has(t.map))
    .map((t) => ({ map: pictures.get(t.map), pose: t.pose, name: t.map }));
  return { result: { report, files }, transfer };
}

self.onmessage = async ({ data }) => {
  const { id, type } = data;
  try {
    await ready;
    let out;
    if (type === 'add') out = await add(data);
    else if (type === 'merge') {
      if (!savedMaps) throw new Error('open two or more maps first');
      out = merge(id);
    } else if (type === 'canvas') {
      overlay = data.canvas;
      out = { result: {}, transfer: [] };
    } else if (type === 'refine') {
      if (!savedMaps) throw new Error('open two or more maps first');
      out = refine(data);
    } else if (type === 'draw') {
      out = { result: { view: draw(data) }, transfer: [] };
    } else if (type === 'adjust') {
      if (data.fit || !adjusting) view = null;
      adjusting = { a: data.a, b: data.b, pose: data.pose };
      out = { result: { view: draw(lastSize) }, transfer: [] };
    } else if (type === 'endAdjust') {
      adjusting = null;
      view = null;
      out = { result: { view: draw(lastSize) }, transfer: [] };
    } else if (type === 'clear') {
      savedMaps?.free();
      savedMaps = null;
      colourIndex = 0;
      pictures = new Map();
      placed = [];
      adjusting = null;
      view = null;
      out = { result: {}, transfer: [] };
    } else throw new Error(`unknown request '${type}'`);
    postMessage({ id, ok: true, ...out.result }, out.transfer);
  } catch (e) {
    postMessage({ id, ok: false, error: message(e) });
  }
};

/** The picture of map number `i`. */
function pictureOf(i) {
  for (const p of pictures.values()) if (p.index === i) return p;
  throw new Error(`no map number ${i}`);
}

/**
 * Draws the overlay at `size` (the page's canvas size and opacity): the
 * merge's placing, or while a map is placed by hand map a and map b at the
 * guess, in a view kept still (fitted once, with room around), and a mark
 * at b's middle, where it turns. Returns the view.
 */
function draw(size) {
  if (!overlay || !size) return null;
  lastSize = { width: size.width, height: size.height, dpr: size.dpr, alpha: size.alpha };
  if (!adjusting) {
    // The user's zoom over the fit of every joined map (hiding one moves none).
    const shown = placed.filter((p) => !size.hidden?.includes(p.name));
    return drawPlaced(overlay, { ...lastSize, zoom: size.zoom }, shown, fitView(placed, lastSize));
  }
  const a = pictureOf(adjusting.a), b = pictureOf(adjusting.b);
  const shown = [{ map: a, pose: [0, 0, 0] }, { map: b, pose: adjusting.pose }];
  view = drawPlaced(overlay, lastSize, shown, view ?? fitView(shown, lastSize, 0.15));
  const [x, y] = compose(compose(adjusting.pose, b.origin), [(b.width * b.resolution) / 2, (b.height * b.resolution) / 2, 0]);
  const ctx = overlay.getContext('2d');
  const px = view.k * x + view.e, py = view.f - view.k * y, r = 9 * size.dpr;
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.strokeStyle = '#111';
  ctx.lineWidth = 2 * size.dpr;
  ctx.beginPath();
  ctx.arc(px, py, r, 0, 2 * Math.PI);
  ctx.moveTo(px - 1.6 * r, py);
  ctx.lineTo(px + 1.6 * r, py);
  ctx.moveTo(px, py - 1.6 * r);
  ctx.lineTo(px, py + 1.6 * r);
  ctx.stroke();
  return view;
}
