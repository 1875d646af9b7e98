// The saved-maps merge of "Your maps", off the page's main thread.
//
// A module Web Worker that loads the same wasm build as the page and holds
// one set of saved maps (web/saved-maps.js, the facade over the binding's
// `MapMerge`). The page sends it the picked files' bytes; it reads them
// into maps (files.js matches each YAML to its image), draws each map into
// a small coloured picture for the page (preview.js), merges on request
// (the whole merge runs here, so the page never waits on it), hands back
// the report and each group's merged map as PGM, PNG and YAML (maps of
// two buildings make two groups, each joined in its first map's frame),
// and draws the merged overlay of the group shown (overlay.js) into the
// page's canvas, which the page hands over once. Messages in:
// `{id, type: 'add', files, resolution, colours}`, `{id, type: 'merge'}`,
// `{id, type: 'canvas', canvas}`, `{id, type: 'draw', width, height, dpr,
// alpha}`, `{id, type: 'group', group}` (the overlay shows that group of
// the report's `merge.groups`), `{id, type: 'clear'}`, and for placing a map by hand (the
// page's Refine, adjust.js): `{id, type: 'adjust', a, b, pose, fit}` (map
// b's frame at `pose` in map a's: shown, the view kept still unless
// `fit`), `{id, type: 'refine', a, b, pose}` (aligns from there, answers
// `{pair, report, files}` as a merge does), `{id, type: 'keep', a, b,
// pose}` (joins map b there as placed, not verified; answers as refine
// does), `{id, type: 'endAdjust'}`; an `adjust` with `judged` (a pose)
// also outlines, dashed, where a refused refine put map b;
// out: `{id, ok, ...}` or `{id, ok: false, error}`, and
// `{type: 'progress', text}` while merging. Draws answer with the view
// used (`{view: {k, e, f, width, height, dpr}}`).

import init, * as wasm from '../../pkg/slamlab.js';
import { SavedMaps, mapImagePath } from '../../saved-maps.js';
import { BagFile, bagKind } from '../../bag-file.js';
import { groupFiles, yamlForImage } from './files.js';
import { gridWarning } from './grid-look.js';
import { probeScales } from './scale-probe.js';
import { previewOf } from './preview.js';
import { compose, drawPlaced, fitView, outline } from './overlay.js';

const ready = init();
/** The maps read so far (a SavedMaps), null before the first. */
let savedMaps = null;
let colourIndex = 0;
/** What the overlay needs of each map read (by name), the last merge's placing, the canvas. */
let pictures = new Map();
let placed = [];
/** The last report, and which of its groups the overlay shows. */
let lastReport = null;
let shownGroup = 0;
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

/**
 * Reads the picked files into maps (a bag's map too); the good ones load
 * even if some are bad. A map named as one already open replaces it, in
 * its place and colour. Each map comes back with `assumed` (the
 * resolution an image without YAML was read at, else null) and `warning`
 * (an image that does not look like an occupancy grid).
 */
async function add({ files, resolution, colours }) {
  savedMaps ??= SavedMaps.open(wasm);
  const bags = files.filter(isBag);
  const { maps, errors } = groupFiles(files.filter((f) => !isBag(f)), (name, yaml) => mapImagePath(wasm, name, yaml), resolution);
  const added = [];
  const transfer = [];
  const reads = [
    ...maps.map((m) => [m, () => {
      const old = pictures.get(m.name);
      if (!old) return savedMaps.addMap(m.name, m.yaml, m.imageName, m.image);
      savedMaps.replaceMap(old.index, m.name, m.yaml, m.imageName, m.image);
      return old.index;
    }]),
    ...bags.map((f) => [{ name: f.name, imageName: f.name }, () => addBag(f)]),
  ];
  for (const [m, read] of reads) {
    let index;
    try {
      index = read();
    } catch (e) {
      errors.push(message(e));
      continue;
    }
    const old = pictures.get(m.name);
    const colour = old?.colour ?? colours[colourIndex++ % colours.length];
    const source = m.assumed ? { image: m.image, imageName: m.imageName } : null;
    const warning = m.image ? await gridWarning(m.imageName, m.image) : '';
    const files = m.image ? { yaml: m.yaml, image: m.image, imageName: m.imageName } : null;
    const out = await picture(index, colour, { imageName: m.imageName, assumed: m.assumed ?? null, warning, source, read: files });
    transfer.push(out.thumb);
    added.push({ ...out, replaced: !!old });
  }
  return { result: { added, errors }, transfer };
}

/** Map `index`'s picture for the overlay (kept by name) and its card's facts (with the thumbnail). */
async function picture(index, colour, extra) {
  const info = savedMaps.mapInfo(index);
  const { thumb, ...preview } = await previewOf(savedMaps.mapPixels(index), info.width, info.height, colour);
  pictures.set(info.name, { ...info, index, preview, colour, source: extra.source, read: extra.read });
  return { ...info, index, colour, thumb, imageName: extra.imageName, assumed: extra.assumed, warning: extra.warning };
}

/** Reads an image opened without YAML again at `resolution` (m per cell), in its place. */
async function reread({ name, resolution }) {
  const p = pictures.get(name);
  if (!p?.source) throw new Error(`${name}: only an image opened without a YAML is read at a resolution you give`);
  const r = Number(resolution);
  if (!(Number.isFinite(r) && r > 0)) throw new Error(`${name}: resolution: '${resolution}' is not a positive number of metres per cell`);
  const yaml = yamlForImage(p.source.imageName, r);
  savedMaps.replaceMap(p.index, name, yaml, p.source.imageName, p.source.image);
  const warning = await gridWarning(p.source.imageName, p.source.image);
  const read = { yaml, image: p.source.image, imageName: p.source.imageName };
  const out = await picture(p.index, p.colour, { imageName: p.source.imageName, assumed: r, warning, source: p.source, read });
  return { result: { map: out }, transfer: [out.thumb] };
}

/** Merges every map read so far; the merged map's files come with the report. */
function merge(id) {
  const t0 = performance.now();
  const report = savedMaps.mergeWithProgress((text) => postMessage({ type: 'progress', id, text }));
  adjusting = null; // a new merge ends any placing by hand
  view = null;
  return withFiles(report, t0);
}

/** Joins map b to map a as the page placed it, not verified; the report follows it. */
function keep({ a, b, pose }) {
  const t0 = performance.now();
  const pair = savedMaps.keepPlacement(a, b, pose);
  const out = withFiles(savedMaps.report(), t0);
  adjusting = null;
  view = null;
  out.result.pair = pair;
  return out;
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

/**
 * The report with each group's merged map (`groups[k]`, null for a map
 * alone; `files` the first joined group's, as before groups) and the
 * overlay's placing.
 */
function withFiles(report, t0) {
  const t1 = performance.now();
  const transfer = [];
  const files = savedMaps.groupFiles(report.merge);
  for (const f of files) if (f) transfer.push(f.pgm.buffer, f.png.buffer);
  report.timings_ms = { merge: t1 - t0, write: performance.now() - t1 };
  lastReport = report;
  shownGroup = Math.max(0, files.findIndex((f) => f));
  place();
  return { result: { report, files: files.find((f) => f) ?? null, groupFiles: files }, transfer };
}

/** The overlay's placing: the shown group's maps in its first map's frame. */
function place() {
  const transforms = lastReport?.merge.groups?.[shownGroup]?.transforms ?? lastReport?.merge.transforms ?? [];
  placed = transforms.filter((t) => pictures.has(t.map)).map((t) => ({ map: pictures.get(t.map), pose: t.pose, name: t.map }));
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
    } else if (type === 'reread') {
      if (!savedMaps) throw new Error('open two or more maps first');
      out = await reread(data);
    } else if (type === 'scales') {
      out = { result: { hints: lastReport ? probeScales(wasm, SavedMaps, pictures, lastReport, yamlForImage) : [] }, transfer: [] };
    } else if (type === 'keep') {
      if (!savedMaps) throw new Error('open two or more maps first');
      out = keep(data);
    } else if (type === 'group') {
      shownGroup = data.group;
      place();
      out = { result: { view: draw(lastSize) }, transfer: [] };
    } else if (type === 'draw') {
      out = { result: { view: draw(data) }, transfer: [] };
    } else if (type === 'adjust') {
      if (data.fit || !adjusting) view = null;
      adjusting = { a: data.a, b: data.b, pose: data.pose, judged: data.judged ?? null };
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
      lastReport = null;
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
  const fitted = adjusting.judged ? [...shown, { map: b, pose: adjusting.judged }] : shown;
  view = drawPlaced(overlay, lastSize, shown, view ?? fitView(fitted, lastSize, 0.15));
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
  if (adjusting.judged) outlineAt(ctx, b, adjusting.judged, size.dpr);
  return view;
}

/** The convex hull of points [x, y] (Andrew's monotone chain), counter-clockwise. */
function hull(points) {
  const p = [...points].sort((u, v) => u[0] - v[0] || u[1] - v[1]);
  const cross = (o, u, v) => (u[0] - o[0]) * (v[1] - o[1]) - (u[1] - o[1]) * (v[0] - o[0]);
  const half = (list) => {
    const out = [];
    for (const q of list) {
      while (out.length > 1 && cross(out[out.length - 2], out[out.length - 1], q) <= 0) out.pop();
      out.push(q);
    }
    out.pop();
    return out;
  };
  return [...half(p), ...half([...p].reverse())];
}

/** A dashed outline round map `b`'s known cells with its frame at `pose`: where a refused refine put it. */
function outlineAt(ctx, b, pose, dpr) {
  const corners = hull(outline(b, pose));
  ctx.setLineDash([8 * dpr, 6 * dpr]);
  ctx.lineWidth = 2.5 * dpr;
  ctx.strokeStyle = '#c2410c';
  ctx.beginPath();
  corners.forEach(([x, y], i) => (i ? ctx.lineTo : ctx.moveTo).call(ctx, view.k * x + view.e, view.f - view.k * y));
  ctx.closePath();
  ctx.stroke();
  ctx.setLineDash([]);
}
