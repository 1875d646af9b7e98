// CARMEN logs and ROS bags replayed off the page's main thread (issues 21
// and 53, the page).
//
// A module Web Worker that loads the same wasm build as the page and holds
// one log replay (web/log-replay.js) per robot: each log or bag opened
// is one robot, or N robots when the page cuts it into N stretches of its
// laser records (each stretch replayed on its own, as if another robot had
// driven it). The page posts the picked or dropped `File`s themselves: a
// CARMEN log is read here whole (it is small), a bag in 8 MiB pieces
// (bag-read.js) into a `BagFile` (web/bag-file.js) kept here, never its
// bytes, with `{type: 'progress', reading: {name, read, total}}` after
// each piece; its replays are made from that `BagFile` with the picks
// (scan topic, odometry, ground truth) the page asks for, and made anew,
// without reading the file again, when the user picks others. A bag's
// ground truth (laid onto the SLAM's frame) is drawn beside the SLAM path
// and its position error goes back to the page with each step.
// The page asks for a few scans at a time (its play, step and
// speed) and gets back how far the replays are and how many loops they
// have closed; the worker draws them (log-draw.js) into the page's canvas,
// handed over once with transferControlToOffscreen: each robot in a tile
// of its own, its map as it grows (redrawn from the scans so far at their
// current poses, at most every MAP_EVERY_MS), the odometry's path beside
// SLAM's and each loop closure. At the end it settles each pose graph and
// hands back each map as PGM, PNG and YAML; then `merge` joins the robots'
// maps (log-merge.js: the saved-maps merge of `merge-maps`, each map in its
// robot's own frame), hands back each group's merged map (robots of two
// buildings make two groups) and draws the joined maps of the group shown
// (`group`) into a second canvas.
// A benchmark's `.relations` file opened with a log (log-relations.js)
// is parsed by each of its robots' replays, which score the scans
// replayed so far against it (at most every RELATIONS_EVERY_MS while
// playing); the worst relations are drawn on the robot's tile, and
// `highlight` picks one of them to draw stronger.
// The page's timeline (timeline.js) looks back at any moment of what has
// been replayed: `seek` draws each robot as its SLAM had it then (the map
// of the scans up to that moment at the poses they had then, the paths
// and the loop closures found by then; web/log-replay.js's `viewAt` and
// `drawAt`), until the next step returns to the live end. Play asks for
// the scans `until` a time of the log's clock (s from each robot's first
// scan; the page runs that clock at its speed in × real time), replayed
// within STEP_BUDGET_MS of work.
// Messages in: `{id, type: 'canvas' | 'mergeCanvas' | 'open' | 'cut' |
// 'pick' | 'step' | 'seek' | 'redraw' | 'highlight' | 'finish' | 'merge' |
// 'group' | 'drawMerge' | 'clear', ...}`; out: `{id, ok, ...}` or `{id, ok: false,
// error}`, and `{type: 'progress', text}` while merging, `{type:
// 'progress', reading}` while a bag is read.

import init, * as wasm from '../../pkg/slamlab.js';
import { LogReplay } from '../../log-replay.js';
import { MAX_SAVED_MAPS } from '../../saved-maps.js';
import { readBag, sortFiles } from './bag-read.js';
import { drawMergedPaths, drawReplays, mapPicture } from './log-draw.js';
import { mergedPaths, mergeRobots, placedMaps, stretches } from './log-merge.js';
import { firstScanTime, matchRelations, relationCheckFigures, relationFigures, relationsText, setRelations, splitRelations } from './log-relations.js';
import { drawPlaced, fitView } from './overlay.js';

const ready = init();
const MAP_EVERY_MS = 400;
/** The most work one step `until` a time does (ms) before it answers. */
const STEP_BUDGET_MS = 150;
/** How often a playing replay is scored against its relations. */
const RELATIONS_EVERY_MS = 300;
/** The most robots at once (the merge's limit). */
const MAX_ROBOTS = MAX_SAVED_MAPS;
/**
 * The logs opened, each `{id, name, records}` and either a CARMEN log's
 * `bytes` (Uint8Array) or a bag's `bag` (BagFile), `info` (what it holds),
 * `lost` (what could not be read), `picks` (as the page asked), `auto`
 * and `picked` (what was picked with no picks and with them, and why),
 * `truthHidden` (the page picked no ground truth) and `spare` (a replay
 * made and not yet given to a robot), and `relations` `{name, text,
 * count}` when a relations file goes with it, `firstTime` its first scan's
 * time (log-relations.js).
 */
let logs = [];
let nextLog = 1;
/**
 * `{name, log, logId, from, to, whole, colour, replay, picture, view, truth,
 * showTruth, mapAt, finished, summary, relations, relationsAt, highlight,
 * times, at, atView, atPicture}` (`whole`: it replays all of its log;
 * `relations`: log-relations.js's `relationFigures`; `highlight`: which of
 * its worst relations to draw stronger, or -1; `times`: each scan's time,
 * s from its first; `at`: the moment looked back at, in scans, or null at
 * the live end, drawn from `atView` and `atPicture`).
 */
let robots = [];
let canvas = null;
let mergeCanvas = null;
let merged = null;

function message(e) {
  return e instanceof Error ? e.message : String(e);
}

/** A log's name without folder, `.gz` and extension. */
function stem(name) {
  return (String(name).split(/[\\/]/).pop().replace(/(\.gz)?$/i, '').replace(/\.[^.]*$/, '') || 'log').replace(/[^\w.-]+/g, '_');
}

/** A message that names `name`, unless it does already. */
function named(name, e) {
  const text = message(e);
  return text.startsWith(name) ? text : `${name}: ${text}`;
}

/** A new replay of `log` (its spare, the first time). */
function replayOf(log) {
  const spare = log.spare;
  log.spare = null;
  if (spare) return spare;
  return log.bag ? log.bag.replay(LogReplay, log.picks) : LogReplay.open(wasm, log.bytes);
}

/** Frees what a log holds in wasm memory. */
function dropLog(log) {
  log.spare?.free();
  log.bag?.free();
}

/** Makes the robots anew from the logs: each log cut into `cut` stretches. */
function layout(cut, colours) {
  tooMany(0, logs, cut);
  for (const r of robots) r.replay.free();
  robots = [];
  addRobots(logs, cut, colours);
  return describe();
}

/** Throws, before anything changes, if `some` logs cut into `cut` stretches would make more than MAX_ROBOTS with `have`. */
function tooMany(have, some, cut) {
  const n = some.reduce((s, log) => s + stretches(log.records, cut).length, have);
  if (n > MAX_ROBOTS) throw new Error(`${n} robots: at most ${MAX_ROBOTS}; open fewer logs or cut them into fewer stretches`);
}

/** Adds the robots of `some` logs (each cut into `cut` stretches); the robots there are keep their replays. */
function addRobots(some, cut, colours) {
  tooMany(robots.length, some, cut);
  merged = null;
  const names = new Set(robots.map((r) => r.name));
  for (const log of some) {
    const parts = stretches(log.records, cut);
    for (const [k, [from, to]] of parts.entries()) {
      let name = parts.length > 1 ? `${stem(log.name)}-${k + 1}` : stem(log.name);
      while (names.has(name)) name += '_';
      names.add(name);
      const colour = colours[robots.length % colours.length];
      robots.push(robotOf(log, name, colour, from, to));
    }
  }
}

/** A robot replaying laser records `from..=to` of `log`. */
function robotOf(log, name, colour, from, to) {
  const replay = replayOf(log);
  try {
    replay.setRange(from, to);
    if (log.relations) replay.setRelations(log.relations.text);
  } catch (e) {
    replay.free();
    throw e;
  }
  const showTruth = !!log.bag && !log.truthHidden;
  const clock = replay.times();
  const times = clock.map((t) => t - clock[0]);
  return {
    name, log: log.name, logId: log.id, from, to, colour, replay, showTruth, truth: null, picture: null, view: null, mapAt: -Infinity, finished: false,
    whole: from === 0 && to >= log.records - 1, relations: null, relationsAt: -Infinity, highlight: -1,
    times, start: clock[0] ?? 0, at: null, atView: null, atPicture: null,
  };
}

/** What the page shows of each robot. */
function describe() {
  return {
    records: logs.reduce((s, l) => s + l.records, 0),
    robots: robots.map(({ name, log, logId, from, to, whole, colour, finished, summary, view, truth, relations, times, at, atView, atPicture }) => ({
      name, log, logId, from, to, whole, colour, finished, summary: summary ?? null,
      done: view?.done ?? 0, total: to - from + 1, closures: view?.closures.length ?? 0,
      time: view?.done ? times[view.done - 1] : 0, duration: times[times.length - 1] ?? 0,
      at, atTime: at ? times[at - 1] : null, atClosures: at ? atView.closures.length : null, atWalls: at ? atPicture.info.occupied_cells : null,
      truth: truth ? { ate_m: truth.ate_m, errors: truth.errors } : null,
      relations,
    })),
    bags: logs.filter((l) => l.bag).map(({ id, name, records, info, lost, picks, auto, picked, truthHidden }) => ({
      id, name, records, info, lost, picks, auto, picked, truthHidden,
    })),
  };
}

/**
 * Opens picked or dropped files (`[{file, path}]`, bag-read.js sorts them
 * into logs and bags, each read here, so a bad one is named with its line
 * or record): the good ones are robots added to those there are, whose
 * replays go on. Relations files go with the logs they name, those just
 * opened or those open (`attached`), or are named in `relationErrors`.
 */
async function open({ files, cut, colours }, id) {
  const before = logs.length;
  const { relations, rest } = splitRelations(files);
  const { items, errors } = await sortFiles(wasm, rest);
  const opened = [];
  const bags = items.filter((i) => i.bag).length;
  let bagAt = 0;
  for (const item of items) {
    const name = item.log ? item.log.name : item.name;
    try {
      if (item.log) {
        const bytes = new Uint8Array(await item.log.arrayBuffer());
        const probe = LogReplay.open(wasm, bytes);
        const records = probe.laserRecords();
        probe.free();
        logs.push({ id: nextLog++, name, bytes, records });
      } else {
        bagAt++;
        const reading = (read, total) => postMessage({ type: 'progress', id, reading: { name, read, total, bag: bagAt, of: bags } });
        logs.push(await openBag(item, reading));
      }
      opened.push(name);
    } catch (e) {
      item.bag?.free();
      errors.push(named(name, e));
    }
  }
  if (opened.length) {
    try {
      addRobots(logs.slice(before), cut, colours);
    } catch (e) {
      for (const log of logs.splice(before)) dropLog(log);
      throw e;
    }
  }
  const { attached, relationErrors } = await attach(relations, logs.slice(before));
  return { ...describe(), added: opened.length, opened, errors, attached, relationErrors };
}

/**
 * Gives each relations file (`entries`, [{file, path}]) to the log it goes
 * with (log-relations.js), `openedNow` the logs opened with them: each of
 * that log's robots scores against it from now on. A file that goes with
 * none, or is malformed (named with its line), changes nothing.
 */
async function attach(entries, openedNow) {
  const { pairs, errors } = matchRelations(entries, logs, openedNow, stem);
  const attached = [];
  for (const { entry, log } of pairs) {
    const name = String(entry.path).split(/[\\/]/).pop();
    try {
      const text = await relationsText(entry);
      const mine = robots.filter((r) => r.logId === log.id);
      const count = setRelations(mine.map((r) => r.replay), name, text);
      log.relations = { name, text, count };
      for (const r of mine) scoreRelations(r, true);
      attached.push({ file: name, log: log.name, count });
    } catch (e) {
      errors.push(named(name, e));
    }
  }
  return { attached, relationErrors: errors };
}

/** Scores `robot`'s replay so far against its log's relations, if it is time (or `force`). */
function scoreRelations(robot, force) {
  const log = logs.find((l) => l.id === robot.logId);
  if (!log?.relations) {
    robot.relations = null;
    return;
  }
  const now = performance.now();
  if (!force && now - robot.relationsAt < RELATIONS_EVERY_MS) return;
  let t0 = null;
  try {
    t0 = firstScanTime(wasm, log);
  } catch {
    log.firstTime = null; // the plot's time then starts at the earliest relation's stamp
  }
  robot.relations = relationFigures(robot.replay, log.relations.name, t0);
  // Checked against the scans and wheels once the poses are settled, once
  // per relations file (it aligns two scans a relation).
  if (robot.finished && robot.checkedWith !== log.relations) {
    robot.check = relationCheckFigures(robot.replay);
    robot.checkedWith = log.relations;
  }
  robot.relations.check = robot.finished ? robot.check : null;
  robot.relationsAt = now;
}

/** Reads a bag (`item` from sortFiles) and makes its first replay with no picks: what it picks and why. */
async function openBag(item, progress) {
  const info = await readBag(item.bag, item.files, progress);
  const spare = item.bag.replay(LogReplay, {});
  const auto = spare.picked();
  const lost = [...info.lost, ...item.missing.map((n) => `${n}: listed in metadata.yaml but not picked or dropped with it`)];
  return { id: nextLog++, name: item.name, bag: item.bag, info, lost, picks: {}, auto, picked: auto, truthHidden: false, records: spare.laserRecords(), spare };
}

/**
 * Makes the replays of bag `log` (an id) anew from its BagFile with
 * `picks` (`{scan_topic, odom_topic, odom_none, truth_topic}`; and
 * `truthHidden`: no ground truth drawn), as many stretches as it had:
 * its robots start again; the others go on. A pick the bag refuses
 * throws, and nothing changes.
 */
function pick({ log: id, picks, truthHidden }) {
  const log = logs.find((l) => l.id === id && l.bag);
  if (!log) throw new Error('that bag is no longer open');
  const probe = log.bag.replay(LogReplay, picks);
  const next = { ...log, picks, truthHidden: !!truthHidden, spare: probe, picked: probe.picked(), records: probe.laserRecords(), firstTime: undefined };
  const mine = robots.filter((r) => r.logId === id);
  const made = [];
  try {
    for (const [k, [from, to]] of stretches(next.records, Math.max(1, mine.length)).entries()) {
      const like = mine[k] ?? mine[0];
      made.push(robotOf(next, mine[k]?.name ?? `${like.name}_${k + 1}`, like.colour, from, to));
    }
  } catch (e) {
    for (const r of made) r.replay.free();
    next.spare?.free();
    throw e;
  }
  log.spare?.free();
  Object.assign(log, next);
  const at = robots.indexOf(mine[0]);
  for (const r of mine) r.replay.free();
  robots.splice(at < 0 ? robots.length : at, mine.length, ...made);
  merged = null;
  return describe();
}

/** Redraws a robot's map from the scans so far, if it is time (or `force`). */
async function refreshMap(robot, force) {
  const done = robot.view?.done ?? 0;
  if (robot.drawnDone === done) return;
  const now = performance.now();
  if (!force && now - robot.mapAt < MAP_EVERY_MS) return;
  if (!robot.replay.drawLive()) return;
  robot.picture = await mapPicture(robot.replay.livePixels(), robot.replay.liveInfo());
  robot.mapAt = performance.now();
  robot.drawnDone = done;
}

/** Each robot as drawn: at the moment looked back at, or at the live end. */
function shown(r) {
  if (r.at === null) return r;
  const truth = r.truth && cutTruth(r.truth, r.start + r.times[r.at - 1]);
  return { ...r, view: r.atView, picture: r.atPicture, truth };
}

/** A truth view (`{poses, errors}`) cut to the poses at or before log time `until`. */
function cutTruth(truth, until) {
  let n = 0;
  while (2 * n < truth.errors.length && truth.errors[2 * n] <= until) n++;
  return { ...truth, poses: truth.poses.slice(0, 3 * n), errors: truth.errors.slice(0, 2 * n) };
}

function draw(size) {
  if (canvas) drawReplays(canvas, size, robots.map(shown));
}

/** How many scans of `times` (s from the first) lie at or before `t`. */
function scansUntil(times, t) {
  let [lo, hi] = [0, times.length];
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (times[mid] <= t + 1e-9) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/**
 * Shows every robot at `t` s after its first scan (each drawn as its SLAM
 * had it once its last scan at or before `t` was replayed), or at its live
 * end when it has not replayed that far.
 */
async function seek({ t, size }) {
  for (const r of robots) {
    const done = r.view?.done ?? 0;
    const k = Math.max(1, scansUntil(r.times, t));
    if (!done || k >= done) {
      r.at = null;
      continue;
    }
    if (r.at === k) continue;
    r.atView = r.replay.viewAt(k);
    r.replay.drawAt(k);
    r.atPicture = await mapPicture(r.replay.livePixels(), r.replay.liveInfo());
    r.at = k;
  }
  draw(size);
  return describe();
}

/**
 * Replays `robot`'s scans up to `until` s after its first, one at a time,
 * while performance.now() is before `deadline`; returns how many scans of
 * its stretch are left.
 */
function stepUntil(robot, until, deadline) {
  const n = scansUntil(robot.times, until) - (robot.view?.done ?? 0);
  let rest = robot.replay.step(0);
  for (let i = 0; i < n && rest > 0 && performance.now() < deadline; i++) rest = robot.replay.step(1);
  return rest;
}

async function step({ n, until, size }) {
  let left = 0;
  const deadline = performance.now() + STEP_BUDGET_MS;
  for (const r of robots) {
    r.at = null;
    const rest = until === undefined ? r.replay.step(n) : stepUntil(r, until, deadline);
    left += rest;
    r.view = r.replay.view();
    r.truth = r.showTruth ? r.replay.truth() : null;
    scoreRelations(r, n === 0 || rest === 0);
    await refreshMap(r, rest === 0);
  }
  draw(size);
  const all = describe();
  const sum = (k) => all.robots.reduce((s, r) => s + r[k], 0);
  return { ...all, done: sum('done'), total: sum('total'), closures: sum('closures'), left };
}

/** Settles every robot's pose graph; each robot's map files and summary. */
function finish() {
  const files = [];
  const transfer = [];
  for (const r of robots) {
    if (!r.finished) {
      const t0 = performance.now();
      r.replay.finish();
      r.report = r.replay.report({ finish: performance.now() - t0 });
      r.summary = { scans: r.report.scans.length, closures: r.report.loop_closures.length, map: r.report.map };
      r.view = r.replay.view();
      r.truth = r.showTruth ? r.replay.truth() : null;
      r.drawnDone = -1; // the settled poses draw a new map
      r.finished = true;
      scoreRelations(r, true);
    }
    const pgm = r.replay.mapPgm();
    const png = r.replay.mapPng();
    files.push({ pgm, png, yaml: r.replay.mapYaml('log-map.pgm') });
    transfer.push(pgm.buffer, png.buffer);
  }
  return { result: { ...describe(), files }, transfer };
}

/** Merges the finished robots' maps (log-merge.js); the merged map's files come with the report. */
async function merge(id) {
  if (robots.length < 2) throw new Error('two or more robots are needed to merge: open another log or cut this one');
  if (robots.some((r) => !r.finished)) throw new Error('finish the replays first');
  merged?.savedMaps.free();
  merged = mergeRobots(wasm, robots, (text) => postMessage({ type: 'progress', id, text }));
  merged.placed = await placedMaps(merged, robots);
  merged.paths = mergedPaths(merged.report, robots);
  const { report, files, groupFiles } = merged;
  merged.group = Math.max(0, groupFiles.findIndex((f) => f));
  const transfer = groupFiles.flatMap((f) => (f ? [f.pgm.buffer, f.png.buffer] : []));
  return { result: { report, files, groupFiles }, transfer };
}

/** The robots the overlay shows: those of the group shown (robots of two buildings make two groups). */
function shownRobots() {
  const merge = merged.report.merge;
  const transforms = merge.groups?.[merged.group]?.transforms ?? merge.transforms;
  return new Set(transforms.map((t) => t.map.replace(/\.yaml$/, '')));
}

const handlers = {
  canvas: (data) => {
    canvas = data.canvas;
    return {};
  },
  mergeCanvas: (data) => {
    mergeCanvas = data.canvas;
    return {};
  },
  cut: (data) => (logs.length ? layout(data.cut, data.colours) : describe()),
  pick: (data) => pick(data),
  step: async (data) => step(data),
  seek: async (data) => seek(data),
  redraw: (data) => {
    draw(data.size);
    return {};
  },
  highlight: (data) => {
    for (const r of robots) r.highlight = r.name === data.robot ? data.k : -1;
    draw(data.size);
    return {};
  },
  drawMerge: (data) => {
    if (mergeCanvas && merged?.placed) {
      // `data.zoom`: the user's zoom (zoom.js); `data.hidden`: the robots
      // unticked. Fitted to every map of the group shown, so hiding one
      // moves no other.
      const group = shownRobots();
      const placed = merged.placed.filter((x) => group.has(x.name));
      const shown = (x) => group.has(x.name) && !data.hidden?.includes(x.name);
      drawPlaced(mergeCanvas, data, placed.filter(shown), fitView(placed, data));
      drawMergedPaths(mergeCanvas, data, placed, merged.paths.filter(shown));
    }
    return {};
  },
  group: (data) => {
    if (merged) merged.group = data.group;
    return {};
  },
  clear: () => {
    for (const r of robots) r.replay.free();
    for (const log of logs) dropLog(log);
    merged?.savedMaps.free();
    [logs, robots, merged] = [[], [], null];
    return describe();
  },
};

/** Answers one request; the requests are answered one after another (below). */
async function answer({ data }) {
  const { id, type } = data;
  try {
    await ready;
    if ((type === 'step' || type === 'finish') && !robots.length) throw new Error('open a log first');
    let out;
    if (type === 'finish') out = finish();
    else if (type === 'merge') out = await merge(id);
    else if (type === 'open') out = { result: await open(data, id), transfer: [] };
    else {
      const handler = handlers[type];
      if (!handler) throw new Error(`unknown request '${type}'`);
      out = { result: await handler(data), transfer: [] };
    }
    postMessage({ id, ok: true, ...out.result }, out.transfer);
  } catch (e) {
    postMessage({ id, ok: false, error: message(e) });
  }
}

// A step awaits its pictures: the next request waits for it to end, so
// none changes the robots while one is under way.
let chain = Promise.resolve();
self.onmessage = (event) => {
  chain = chain.then(() => answer(event));
};
