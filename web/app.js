// The lab page: wires the controls of index.html to the Rust `Lab` (wasm).
//
// Data flow, as in wasm-bindgen's "without a bundler" example:
//   - `init()` fetches and instantiates web/pkg/slamlab_bg.wasm;
//   - this module keeps the *scenario object* (the JSON of interfaces.md) as
//     the source of truth while editing, and pushes it to the Lab with
//     `lab.setScenario(JSON.stringify(s))` after every edit;
//   - the simulation lives in wasm: the page calls `lab.step(n)` from a
//     requestAnimationFrame loop (as many 0.1 s steps as the speed asks,
//     capped so a frame stays short) and reads small JSON results back
//     (`stateJson`, `problemsJson`, `viewMetrics`);
//   - `lab.draw(ctx)` renders the world with tiny-skia straight into the
//     canvas; this module then draws the text the renderer leaves out (robot
//     names, the scale-bar label, the grid spacing, the turning handle).
//
// Every call into wasm that can throw runs inside `guard`, which shows the
// message in the status line: the page never throws an uncaught exception.
//
// A link carries the scenario and its seed in the URL (web/share.js):
// opening one restores them, ahead of the autosave, and from then on (or
// once the user pressed Copy link) the address bar follows every edit, so a
// reload or a bookmark keeps the current scenario. The guided mode (web/guided.js) and the printable summary
// (web/summary.js) are wired here too.

import init, { Lab, validateScenario, version, simdEnabled, robotColours } from './pkg/slamlab.js';
import {
  View,
  clamp,
  handlePoint,
  hitRobot,
  hitWall,
  snap,
  snapAngle,
  snapPoint,
  wallEnd,
  wrapAngle,
} from './geometry.js';
import { deg, fmt } from './dom.js';
import { RobotsPanel, robotColour, setRobotColours } from './robots-panel.js';
import { CameraPanel } from './camera-panel.js';
import { MapsPanel } from './maps-panel.js';
import { MergePanel } from './merge-panel.js';
import { GuidedTour } from './guided.js';
import { decodeShare, encodeShare } from './share.js';
import { buildSummary } from './summary.js';

const STORAGE_KEY = 'slamlab.scenario.v1';
const LAYERS_KEY = 'slamlab.layers.v1';
const DEFAULT_PRESET = 'thesis';
const CONTROL_DT_S = 0.1; // one Lab step
const MAX_ROBOTS = 16;
const FRAME_BUDGET_MS = 12; // time per frame we allow for simulation steps
const READOUT_INTERVAL_MS = 100;

const $ = (id) => document.getElementById(id);
const canvas = $('world');
const ctx = canvas.getContext('2d');

/** Everything the page knows; the Lab holds the rest. */
const app = {
  lab: null,
  scenario: null, // source of truth while editing
  preset: DEFAULT_PRESET, // the preset the scenario is (seed and duration aside); '' once edited
  origin: DEFAULT_PRESET, // the preset it was loaded from, kept through edits ('' for New / Import)
  presetDurations: {}, // preset name → its own duration_s, as fetched
  shareHash: '', // the URL fragment last written (see web/share.js)
  shareInUrl: false, // keep the address bar's fragment in step with the scenario
  currentLink: '', // the link to the current scenario, as last computed
  guideMarkers: null, // selected frames the guided mode marks on the map
  view: new View(),
  dpr: 1,
  sized: false,
  autoFit: true, // refit on resize until the user zooms or pans
  layers: { grid: true, laser: true, sonar: false, truth_path: true, odometry_path: true },
  tool: 'select', // 'select' | 'wall'
  selection: null, // {kind: 'wall' | 'robot', index}
  drag: null,
  preview: null, // wall being drawn [x0, y0, x1, y1]
  pointer: null, // last pointer position, CSS px on the canvas
  running: false,
  speed: 10, // simulated seconds per real second
  lastFrameMs: 0,
  stepCarry: 0,
  maxStepsPerFrame: 100,
  problems: [],
  state: null,
  lastReadoutMs: 0,
  dirty: true,
  undo: [],
  spaceDown: false,
  spaceUsed: false,
};

// ---------------------------------------------------------------------------
// Status line and error handling

function setStatus(text, kind = 'info') {
  const s = $('status');
  s.textContent = text;
  s.className = `status ${kind}`;
  s.title = text;
}

function message(e) {
  if (e instanceof Error) return e.message;
  return String(e);
}

/** Wraps a handler so anything it throws lands in the status line. */
function guard(fn) {
  return (...args) => {
    try {
      return fn(...args);
    } catch (e) {
      app.running = false;
      app.drag = null;
      app.preview = null;
      setStatus(message(e), 'error');
      app.dirty = true;
      refreshControls();
      return undefined;
    }
  };
}

window.addEventListener('error', (e) => {
  if (/ResizeObserver loop/.test(e.message)) return; // benign, and not ours to report
  setStatus(`Unexpected error: ${e.message}`, 'error');
});
window.addEventListener('unhandledrejection', (e) => setStatus(`Unexpected error: ${message(e.reason)}`, 'error'));

// ---------------------------------------------------------------------------
// Scenario: load, edit, autosave

const clone = (o) => JSON.parse(JSON.stringify(o));

/** Replaces the Lab's scenario with `text` (throws, keeping the old one, if bad). */
function loadScenarioText(text, { preset = '', origin = preset, fit = true } = {}) {
  if (app.lab) app.lab.setScenario(text);
  else app.lab = new Lab(text);
  app.scenario = JSON.parse(app.lab.scenarioJson());
  app.preset = preset;
  app.origin = origin;
  app.running = false;
  app.selection = null;
  app.drag = null;
  app.preview = null;
  afterScenarioChange();
  if (fit) fitView();
}

async function loadPreset(name) {
  const res = await fetch(`scenarios/${name}.json`);
  if (!res.ok) throw new Error(`could not fetch scenarios/${name}.json (HTTP ${res.status})`);
  const text = await res.text();
  pushUndo();
  loadScenarioText(text, { preset: name });
  app.presetDurations[name] = app.scenario.duration_s;
  return app.scenario;
}

/** Pushes an edited scenario to the Lab; on error nothing changes (throws). */
function commit(next, { undoFrom = JSON.stringify(app.scenario) } = {}) {
  app.lab.setScenario(JSON.stringify(next));
  app.undo.push(undoFrom);
  if (app.undo.length > 100) app.undo.shift();
  app.scenario = next;
  app.preset = '';
  afterScenarioChange();
}

/** A change during a drag: shown live, committed (with undo) on release. */
function pushLive(next) {
  try {
    app.lab.setScenario(JSON.stringify(next));
    app.drag.live = next;
    app.problems = JSON.parse(app.lab.problemsJson());
  } catch {
    // e.g. dragged beyond the ±1000 m the format allows: keep the last good one
  }
  app.dirty = true;
}

function pushUndo() {
  if (app.scenario) app.undo.push(JSON.stringify(app.scenario));
}

const undo = guard(() => {
  if (!editable()) return notEditable();
  const text = app.undo.pop();
  if (!text) return setStatus('Nothing to undo.', 'info');
  app.lab.setScenario(text);
  app.scenario = JSON.parse(text);
  app.preset = '';
  app.selection = null;
  afterScenarioChange();
  setStatus('Undone.', 'info');
});

function afterScenarioChange() {
  app.problems = JSON.parse(app.lab.problemsJson());
  if (app.selection) {
    const list = app.selection.kind === 'wall' ? app.scenario.walls : app.scenario.robots;
    if (app.selection.index >= list.length) app.selection = null;
  }
  $('seed').value = String(app.scenario.seed);
  $('duration').value = String(app.scenario.duration_s);
  $('preset').value = app.preset;
  autosave();
  scheduleShareHash();
  refreshPanels();
  refreshControls();
  app.dirty = true;
}

function autosave() {
  try {
    localStorage.setItem(
      STORAGE_KEY,
      JSON.stringify({ version: 1, preset: app.preset, origin: app.origin, scenario: app.scenario }),
    );
  } catch (e) {
    setStatus(`Could not autosave in this browser: ${message(e)}`, 'warn');
  }
}

// ---------------------------------------------------------------------------
// Sharing: the scenario and seed in the URL (web/share.js)

/** The URL fragment that restores the current scenario and seed. */
function currentShareHash() {
  return encodeShare(app.scenario, {
    preset: app.preset,
    presetDuration: app.presetDurations[app.preset],
    origin: app.origin,
  });
}

/** A link that opens this scenario with this seed. */
async function shareLink() {
  return `${location.origin}${location.pathname}#${await currentShareHash()}`;
}

let shareTimer = 0;
/** Keeps the current link ready (for the printed summary) and, once the page
 *  was opened from a link or a link was copied, the address bar's fragment in
 *  step with the scenario (debounced). */
function scheduleShareHash() {
  clearTimeout(shareTimer);
  shareTimer = setTimeout(async () => {
    try {
      const hash = await currentShareHash();
      app.currentLink = `${location.origin}${location.pathname}#${hash}`;
      if (!app.shareInUrl) return;
      app.shareHash = hash;
      if (location.hash.slice(1) !== hash || location.search) {
        history.replaceState(history.state, '', `${location.pathname}#${hash}`);
      }
    } catch (e) {
      setStatus(`Could not put the scenario in the address bar: ${message(e)}`, 'warn');
    }
  }, 250);
}

/** Opens what a shared link asks for; throws, keeping the scenario, if it cannot. */
async function openShared(shared) {
  if (shared.kind === 'preset') {
    await loadPreset(shared.preset);
    if (shared.seed != null && shared.seed !== app.scenario.seed) {
      app.lab.setSeed(shared.seed);
      app.scenario.seed = shared.seed;
    }
    if (shared.duration != null && shared.duration !== app.scenario.duration_s) {
      app.lab.setDuration(shared.duration);
      app.scenario.duration_s = shared.duration;
    }
    afterScenarioChange();
  } else {
    const before = app.scenario ? JSON.stringify(app.scenario) : null;
    loadScenarioText(shared.text, { preset: '', origin: shared.origin });
    if (before) app.undo.push(before);
  }
}

/** Loads the scenario of a shared link, else the autosave, else the thesis preset. */
async function restore() {
  let problem = '';
  try {
    const shared = await decodeShare(location.hash, location.search);
    if (shared) {
      app.shareInUrl = true;
      const saved = savedScenarioText(); // before the link replaces the autosave
      await openShared(shared);
      app.undo = [];
      const same = saved !== null && saved === validateScenario(app.lab.scenarioJson());
      setStatus(same
        ? `Restored your last scenario “${app.scenario.name}” (seed ${app.scenario.seed}) from the address bar.`
        : `Opened a shared link: “${app.scenario.name}” with seed ${app.scenario.seed}. Press Run (Space) to run it.`, 'ok');
      return;
    }
  } catch (e) {
    problem = `The link could not be opened (${message(e)}). `;
  }
  await restoreSaved();
  if (problem) setStatus(problem + $('status').textContent, 'warn');
}

/** The autosaved scenario in the Lab's canonical JSON, or null. */
function savedScenarioText() {
  try {
    const saved = JSON.parse(localStorage.getItem(STORAGE_KEY) ?? 'null');
    return saved?.scenario ? validateScenario(JSON.stringify(saved.scenario)) : null;
  } catch {
    return null;
  }
}

/** A link pasted into the address bar of an open page. */
window.addEventListener('hashchange', async () => {
  if (!app.lab || location.hash.slice(1) === app.shareHash) return;
  try {
    const shared = await decodeShare(location.hash);
    if (!shared) return;
    app.shareInUrl = true;
    await openShared(shared);
    setStatus(`Opened the link: “${app.scenario.name}” with seed ${app.scenario.seed} (Ctrl+Z goes back).`, 'ok');
  } catch (e) {
    setStatus(`The link could not be opened: ${message(e)}. The scenario is unchanged.`, 'error');
  }
});

const copyLink = async () => {
  let link;
  try {
    link = await shareLink();
  } catch (e) {
    setStatus(`Could not make a link: ${message(e)}`, 'error');
    return;
  }
  // From now on the address bar holds the link too, and follows edits.
  app.shareInUrl = true;
  scheduleShareHash();
  try {
    await navigator.clipboard.writeText(link);
    setStatus(`Link copied: it opens “${app.scenario.name}” with seed ${app.scenario.seed} (${link.length} characters).`, 'ok');
  } catch {
    setStatus('The browser did not let the page use the clipboard: copy the address bar instead, it holds the same link.', 'warn');
  }
};

const resetToPreset = async () => {
  const name = app.origin || app.preset;
  if (!name) {
    setStatus('This scenario did not come from a preset (New or Import): there is no preset to reset to.', 'info');
    return;
  }
  try {
    await loadPreset(name);
    setStatus(`Back to the ${name} preset as shipped, seed ${app.scenario.seed} (Ctrl+Z goes back to what you had).`, 'ok');
  } catch (e) {
    setStatus(`Could not load the ${name} preset: ${message(e)}`, 'error');
  }
};

/** Restores the autosaved scenario; a corrupt save is reported, never fatal. */
async function restoreSaved() {
  let saved = null;
  try {
    saved = localStorage.getItem(STORAGE_KEY);
  } catch {
    saved = null;
  }
  if (saved == null) {
    await loadPreset(DEFAULT_PRESET);
    setStatus('Loaded the thesis preset. Press Run (Space) to start, or edit the map first.', 'info');
    return;
  }
  try {
    let obj;
    try {
      obj = JSON.parse(saved);
    } catch (e) {
      throw new Error(`not valid JSON (${message(e)})`);
    }
    if (!obj || typeof obj !== 'object' || !obj.scenario) throw new Error('it holds no scenario');
    const preset = typeof obj.preset === 'string' ? obj.preset : '';
    loadScenarioText(JSON.stringify(obj.scenario), { preset, origin: typeof obj.origin === 'string' ? obj.origin : preset });
    app.undo = [];
    setStatus(`Restored your last scenario “${app.scenario.name}” from this browser.`, 'ok');
  } catch (e) {
    try {
      localStorage.setItem(`${STORAGE_KEY}.corrupt`, saved);
    } catch {
      // nothing more we can do
    }
    await loadPreset(DEFAULT_PRESET);
    app.undo = [];
    setStatus(
      `The scenario saved in this browser could not be restored: ${message(e)}. ` +
        `Loaded the thesis preset instead (the bad save is kept under "${STORAGE_KEY}.corrupt").`,
      'warn',
    );
  }
}

// ---------------------------------------------------------------------------
// Simulation

const editable = () => !!app.lab && !app.running && app.lab.timeS() === 0;

function notEditable() {
  setStatus('The scenario can only be edited at t = 0: press Reset (R) first.', 'info');
}

function readState() {
  app.state = JSON.parse(app.lab.stateJson());
  return app.state;
}

const run = guard(() => {
  if (app.running) return;
  const st = readState();
  if (st.finished) {
    setStatus('The run has reached its duration: Reset (R) to run again, or raise the duration.', 'warn');
    return;
  }
  if (st.steps === 0 && app.problems.length) {
    setStatus(`Cannot run: ${app.problems[0].text}. Move the robot clear first.`, 'error');
    return;
  }
  endDrag();
  if (app.selection?.kind === 'wall') app.selection = null;
  app.running = true;
  app.lastFrameMs = performance.now();
  app.stepCarry = 0;
  setStatus(`Running at ${app.speed}× real time.`, 'info');
  refreshPanels();
  refreshControls();
});

const pause = guard(() => {
  if (!app.running) return;
  app.running = false;
  setStatus(`Paused at t = ${fmt(app.lab.timeS(), 1)} s.`, 'info');
  updateReadouts(true);
  refreshPanels();
});

const step = guard(() => {
  app.running = false;
  endDrag();
  if (app.lab.timeS() === 0 && app.problems.length) {
    setStatus(`Cannot run: ${app.problems[0].text}. Move the robot clear first.`, 'error');
    return;
  }
  const taken = app.lab.step(1);
  afterSteps(taken, 1);
  if (taken === 1) setStatus(`Stepped to t = ${fmt(app.lab.timeS(), 1)} s.`, 'info');
  refreshPanels();
});

const reset = guard(() => {
  app.running = false;
  app.lab.reset();
  readState();
  updateReadouts(true);
  refreshPanels();
  refreshControls();
  app.dirty = true;
  setStatus(
    app.problems.length ? `Back to t = 0. ${app.problems[0].text}.` : 'Back to t = 0: you can edit the scenario.',
    app.problems.length ? 'warn' : 'info',
  );
});

function afterSteps(taken, asked) {
  const st = readState();
  app.dirty = true;
  if (st.finished || taken < asked) finish(st);
  updateReadouts(true);
  refreshControls();
}

function finish(st) {
  app.running = false;
  const parts = st.robots.map((r) => `${r.name}: ${r.bumps} bumps, odometry off by ${fmt(r.odometry_error_m)} m`);
  setStatus(`Run finished at t = ${fmt(st.time_s, 1)} s (the duration). ${parts.join('; ')}.`, 'ok');
}

/** Advances the simulation for one animation frame. */
function advance(nowMs) {
  const dt = clamp((nowMs - app.lastFrameMs) / 1000, 0, 0.1);
  app.lastFrameMs = nowMs;
  const wanted = (app.speed * dt) / CONTROL_DT_S + app.stepCarry;
  let n = Math.floor(wanted);
  app.stepCarry = wanted - n;
  if (n > app.maxStepsPerFrame) {
    n = app.maxStepsPerFrame;
    app.stepCarry = 0; // the machine cannot keep up: slow down rather than pile up
  }
  if (n <= 0) return;
  const t0 = performance.now();
  const taken = app.lab.step(n);
  const perStep = (performance.now() - t0) / Math.max(1, taken);
  app.maxStepsPerFrame = clamp(Math.floor(FRAME_BUDGET_MS / Math.max(perStep, 1e-3)), 1, 1000);
  app.dirty = true;
  if (taken < n) afterSteps(taken, n);
  else if (app.lab.timeS() + 1e-9 >= app.scenario.duration_s) afterSteps(taken, taken + 1);
}

// ---------------------------------------------------------------------------
// View and drawing

function resize() {
  const host = canvas.parentElement;
  const w = Math.max(1, host.clientWidth);
  const h = Math.max(1, host.clientHeight);
  app.dpr = clamp(window.devicePixelRatio || 1, 1, 2);
  canvas.width = Math.min(4096, Math.round(w * app.dpr));
  canvas.height = Math.min(4096, Math.round(h * app.dpr));
  app.view.width = w;
  app.view.height = h;
  if ((!app.sized || app.autoFit) && app.lab) {
    app.sized = true;
    fitView();
  }
  app.dirty = true;
  // Resizing cleared the canvas: draw now rather than show a blank frame.
  if (app.lab && app.scenario) draw();
}

function fitView() {
  if (!app.lab) return;
  app.autoFit = true;
  const v = app.view;
  if (app.scenario.walls.length === 0) {
    // Nothing to fit: show a 20 x 15 m floor to draw on.
    v.center = [10, 7.5];
    v.scale = Math.min(v.width / 22, v.height / 17);
  } else {
    const r = JSON.parse(app.lab.fitView(canvas.width, canvas.height));
    v.center = r.center;
    v.scale = r.scale / app.dpr;
  }
  app.dirty = true;
}

function pushView() {
  const v = app.view;
  const sel = app.selection;
  app.lab.setView(
    JSON.stringify({
      width: canvas.width,
      height: canvas.height,
      center: v.center,
      scale: v.scale * app.dpr,
      layers: app.layers,
      selected_wall: sel && sel.kind === 'wall' ? sel.index : null,
      selected_robot: sel && sel.kind === 'robot' ? sel.index : null,
      preview_wall: app.preview,
      // Where the camera frame picked in a film strip was taken.
      marker: app.marker ? app.marker.pose : null,
      marker_fov: app.marker ? (app.marker.fovDeg * Math.PI) / 180 : Math.PI / 3,
    }),
  );
}

/** Poses to label: live ones while a run exists, else the start poses. */
function robotPoses() {
  const st = app.state;
  if (st && st.robots.length === app.scenario.robots.length && st.steps > 0) return st.robots.map((r) => r.truth);
  return app.scenario.robots.map((r) => r.start);
}

function handleReach() {
  return Math.max(0.6, 30 / app.view.scale);
}

function draw() {
  app.dirty = false;
  if (app.running) readState(); // robot labels follow the robots every frame
  pushView();
  app.lab.draw(ctx);
  drawOverlay();
}

function label(text, x, y, colour, align = 'left') {
  // Keep labels inside the canvas.
  const w = ctx.measureText(text).width;
  if (align === 'left' && x + w > app.view.width - 4) x = Math.max(4, app.view.width - 4 - w);
  ctx.textAlign = align;
  ctx.lineJoin = 'round';
  ctx.lineWidth = 3;
  ctx.strokeStyle = 'rgba(255,255,255,0.9)';
  ctx.strokeText(text, x, y);
  ctx.fillStyle = colour;
  ctx.fillText(text, x, y);
}

/** Text and handles on top of the tiny-skia image (CSS pixels). */
function drawOverlay() {
  const v = app.view;
  ctx.save();
  ctx.setTransform(app.dpr, 0, 0, app.dpr, 0, 0);
  ctx.font = '600 12px system-ui, sans-serif';
  ctx.textBaseline = 'alphabetic';

  // The guided mode's selected frames: a triangle where each kept picture
  // was taken, pointing along the camera's axis; A', D and E labelled.
  if (app.guideMarkers) {
    for (const m of app.guideMarkers) {
      const [px, py] = v.toPx(m.pose);
      const r = m.label ? 10 : 6;
      const [dx, dy] = [Math.cos(m.pose[2]), -Math.sin(m.pose[2])]; // screen y points down
      ctx.beginPath();
      ctx.moveTo(px + dx * r, py + dy * r);
      ctx.lineTo(px - 0.6 * r * (dx + dy), py - 0.6 * r * (dy - dx));
      ctx.lineTo(px - 0.6 * r * (dx - dy), py - 0.6 * r * (dy + dx));
      ctx.closePath();
      ctx.fillStyle = robotColour(m.robot);
      ctx.fill();
      ctx.lineWidth = m.label ? 2 : 1;
      ctx.strokeStyle = m.label ? '#111' : '#fff';
      ctx.stroke();
      if (m.label) {
        // Labels sit away from the middle of the labelled group, so that
        // A', D and E (a few decimetres apart) do not overprint each other.
        const [ox, oy] = m.labelDir ?? [0.7, 0.7];
        ctx.font = '700 13px system-ui, sans-serif';
        label(m.label, px + 16 * ox, py - 16 * oy + 4, '#111', ox < -0.3 ? 'right' : ox > 0.3 ? 'left' : 'center');
        ctx.font = '600 12px system-ui, sans-serif';
      }
    }
  }

  // Robot names next to the robots.
  const poses = robotPoses();
  const reach = handleReach();
  app.scenario.robots.forEach((r, i) => {
    const [px, py] = v.toPx(poses[i]);
    const off = Math.max(10, 0.3 * v.scale);
    label(r.name, px + off, py - off, darker(i));
  });

  // The turning handle of the selected robot (editing only).
  const sel = app.selection;
  if (sel && sel.kind === 'robot' && editable()) {
    const pose = app.scenario.robots[sel.index]?.start;
    if (pose) {
      const [px, py] = v.toPx(pose);
      const [hx, hy] = v.toPx(handlePoint(pose, reach));
      ctx.strokeStyle = '#b08000';
      ctx.lineWidth = 1.5;
      ctx.setLineDash([4, 3]);
      ctx.beginPath();
      ctx.moveTo(px, py);
      ctx.lineTo(hx, hy);
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = '#ffc800';
      ctx.strokeStyle = '#5a4200';
      ctx.beginPath();
      ctx.arc(hx, hy, 6, 0, 2 * Math.PI);
      ctx.fill();
      ctx.stroke();
      label(`${fmt(deg(pose[2]), 0)}°`, hx + 9, hy + 4, '#5a4200');
    }
  }

  // The wall being drawn: its length and direction next to the pointer.
  if (app.preview) {
    const [x0, y0, x1, y1] = app.preview;
    const len = Math.hypot(x1 - x0, y1 - y0);
    const ang = deg(Math.atan2(y1 - y0, x1 - x0));
    const [px, py] = v.toPx([x1, y1]);
    label(`${fmt(len, 2)} m  ${fmt(ang, 0)}°  (${fmt(x1, 2)}, ${fmt(y1, 2)})`, px + 12, py - 10, '#123a80');
  }

  // Scale-bar label (the bar itself is drawn by the renderer at x = 14,
  // y = height - 18 device pixels) and the grid spacing beside it.
  const m = JSON.parse(app.lab.viewMetrics());
  const barX = 14 / app.dpr;
  const barY = (canvas.height - 18) / app.dpr;
  const barW = m.scale_bar_m * v.scale;
  ctx.font = '600 12px system-ui, sans-serif';
  label(metres(m.scale_bar_m), barX, barY - 4, '#1e1e1e');
  if (app.layers.grid) {
    ctx.font = '12px system-ui, sans-serif';
    label(`grid ${metres(m.grid_m)}`, barX + barW + 10, barY + 6, '#444');
  }

  // A one-line hint for the current tool in the top-left corner.
  const hint = overlayHint();
  if (hint) {
    ctx.font = '12.5px system-ui, sans-serif';
    const w = ctx.measureText(hint).width;
    ctx.fillStyle = 'rgba(255,255,255,0.85)';
    ctx.fillRect(8, 8, w + 14, 22);
    ctx.fillStyle = '#333';
    ctx.textAlign = 'left';
    ctx.fillText(hint, 15, 23);
  }
  ctx.restore();
}

function overlayHint() {
  if (app.running) return '';
  if (!editable()) {
    return app.state?.finished
      ? 'Run finished: press Reset (R) to run again or to edit the map.'
      : 'Paused: press Reset (R) to edit the map.';
  }
  if (app.tool === 'wall') return 'Wall tool: drag to draw a wall (snaps to 0.1 m and 15°; Alt or Shift: any angle). Esc: back to Select.';
  if (app.scenario.walls.length === 0) return 'Empty map: press Wall (W) and drag to draw walls.';
  if (app.selection?.kind === 'robot') return 'Drag the robot to move it; drag the yellow handle (or Shift-drag) to turn it. Delete removes it.';
  if (app.selection?.kind === 'wall') return 'Drag the wall to move it, or an end to reshape it. Delete removes it.';
  return 'Click a wall or robot to select it; drag to move it. Wall (W) draws walls.';
}

function metres(m) {
  return m < 1 ? `${Math.round(m * 100)} cm` : `${Number(m.toFixed(2))} m`;
}

function darker(i) {
  return robotColour(i).replace(/\d+/g, (c) => String(Math.round(Number(c) * 0.7)));
}

// ---------------------------------------------------------------------------
// Side panels and toolbar state

const robotsPanel = new RobotsPanel($('robots'), {
  select: (i) => {
    app.selection = { kind: 'robot', index: i };
    refreshPanels();
    app.dirty = true;
  },
  rename: guard((i, name) => editRobot(i, (r) => (r.name = name.trim()), 'renamed')),
  setFollow: guard((i, side) => editRobot(i, (r) => (r.follow = side), 'now follows the wall on its ' + side)),
  setDistance: guard((i, d) => editRobot(i, (r) => (r.distance = d), `keeps ${d} m to its wall`)),
  remove: guard((i) => removeRobot(i)),
  downloadLog: guard((i) => downloadLog(i)),
});

function editRobot(i, change, what) {
  if (!editable()) {
    robotsPanel.key = '';
    refreshPanels();
    return notEditable();
  }
  const next = clone(app.scenario);
  change(next.robots[i]);
  try {
    commit(next);
  } catch (e) {
    robotsPanel.key = ''; // show the old values again
    refreshPanels();
    throw e;
  }
  setStatus(`${next.robots[i].name} ${what}.`, 'info');
  reportProblems();
}

function problemRobots() {
  const set = new Set();
  for (const p of app.problems) {
    const m = /^robots\[(\d+)\]/.exec(p.field);
    if (m) set.add(Number(m[1]));
  }
  return set;
}

function reportProblems() {
  if (app.problems.length) setStatus(`${app.problems[0].text}: move it clear before running.`, 'warn');
}

// Camera views and film strips (web/camera-panel.js).
const cameraPanel = new CameraPanel($('cameras'), {
  lab: () => app.lab,
  onMarker: (m) => {
    app.marker = m;
    app.dirty = true;
  },
  onError: (e) => setStatus(message(e), 'error'),
});

// Each robot's map, SLAM or odometry-only (web/maps-panel.js).
const mapsPanel = new MapsPanel($('maps'), {
  lab: () => app.lab,
  onError: (e) => setStatus(message(e), 'error'),
  download: (name, data, type) => download(name, data, type),
});

// Merging the maps, with the matched-pair table (web/merge-panel.js).
const mergePanel = new MergePanel($('merge'), $('pair-overlay'), {
  lab: () => app.lab,
  canMerge: () => Boolean(app.lab && app.state && app.state.steps > 0 && !app.running && app.scenario.robots.length >= 2),
  onError: (e) => setStatus(message(e), 'error'),
  setStatus: (text, kind) => setStatus(text, kind),
  download: (name, data, type) => download(name, data, type),
  report: () => app.lab.reportJson('{}'),
});

// The guided mode: thesis §6.2.1-6.2.5 on the live lab (web/guided.js).
const guide = new GuidedTour($('guide'), $('guided-open'), {
  lab: () => app.lab,
  run: () => {
    const st = readState();
    return {
      steps: st.steps,
      time_s: st.time_s,
      finished: st.finished,
      running: app.running,
      duration_s: app.scenario.duration_s,
      robots: app.scenario.robots.map((r) => r.name),
      thesis: app.preset === 'thesis',
      name: app.scenario.name,
      seed: app.scenario.seed,
    };
  },
  loadThesisAndRun: async () => {
    await loadPreset('thesis');
    setSpeed(50);
    run();
  },
  merge: mergePanel,
  setMarkers: (m) => {
    app.guideMarkers = m;
    app.dirty = true;
  },
  reveal: (id, block = 'start') => {
    const e = $(id);
    (block === 'start' ? e?.closest('.panel') : e)?.scrollIntoView({ block, behavior: 'smooth' });
  },
  zoomTo: (points) => {
    if (!points) {
      fitView();
      return;
    }
    // World points to show, with 2.5 m around them (Figure 18's corner).
    const xs = points.map((p) => p[0]);
    const ys = points.map((p) => p[1]);
    const v = app.view;
    v.center = [(Math.min(...xs) + Math.max(...xs)) / 2, (Math.min(...ys) + Math.max(...ys)) / 2];
    const span = Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys)) + 5;
    v.scale = clamp(Math.min(v.width, v.height) / span, 2, 2000);
    app.autoFit = false;
    app.dirty = true;
  },
  onError: (e) => setStatus(message(e), 'error'),
  onToggle: (open) => {
    document.body.classList.toggle('guided', open);
    app.dirty = true;
  },
});

// ---------------------------------------------------------------------------
// The run summary (web/summary.js): a full-page view, and what the page prints

/** The whole scenario, fitted into a `w × h` image with the robots' names
 *  (PNG data URL); the on-screen view is restored on the next frame. */
function worldSnapshot(w, h) {
  const c = document.createElement('canvas');
  c.width = w;
  c.height = h;
  const fit = JSON.parse(app.lab.fitView(w, h));
  app.lab.setView(JSON.stringify({
    width: w, height: h, center: fit.center, scale: fit.scale, layers: app.layers,
    selected_wall: null, selected_robot: null, preview_wall: null, marker: null, marker_fov: Math.PI / 3,
  }));
  const g = c.getContext('2d');
  app.lab.draw(g);
  const v = new View();
  Object.assign(v, { width: w, height: h, center: fit.center, scale: fit.scale });
  g.font = '600 12px system-ui, sans-serif';
  g.lineJoin = 'round';
  g.fillStyle = '#1e1e1e';
  g.fillText(metres(JSON.parse(app.lab.viewMetrics()).scale_bar_m), 14, h - 22); // the renderer's scale bar
  robotPoses().forEach((p, i) => {
    const [px, py] = v.toPx(p);
    g.lineWidth = 3;
    g.strokeStyle = 'rgba(255,255,255,0.9)';
    g.strokeText(app.scenario.robots[i].name, px + 10, py - 10);
    g.fillStyle = darker(i);
    g.fillText(app.scenario.robots[i].name, px + 10, py - 10);
  });
  app.dirty = true; // the next frame pushes the on-screen view back
  return c.toDataURL('image/png');
}

/** Builds the summary from what the page shows now; `link` restores the scenario. */
function buildSummaryNow(link = app.currentLink || location.href) {
  const lab = app.lab;
  const st = readState();
  const started = st.steps > 0;
  const robots = app.scenario.robots.map((r, i) => ({
    name: r.name,
    follow: r.follow,
    distance: r.distance ?? 0.6,
    frames: started ? lab.frameCount(i) : 0,
    bumps: st.robots[i]?.bumps ?? 0,
    figures: started ? JSON.parse(lab.slamFiguresJson(i)) : null,
  }));
  const plots = started
    ? [...document.querySelectorAll('.map-block')].filter((b) => !b.hidden).map((b) => ({
      name: b.querySelector('.map-title').textContent.replace(/'s map$/, ''),
      src: b.querySelector('.map-plot').toDataURL('image/png'),
    }))
    : [];
  const view = mergePanel.view;
  let mergedImage = null;
  if (view?.report?.status === 'merged') {
    const c = document.createElement('canvas');
    c.width = 480;
    c.height = 350;
    lab.drawMerged(c.getContext('2d'), c.width, c.height);
    mergedImage = c.toDataURL('image/png');
  }
  buildSummary(
    $('summary'),
    {
      scenario: app.scenario,
      link,
      when: new Date(),
      run: { time_s: st.time_s, finished: st.finished, steps: st.steps },
      robots,
      worldImage: worldSnapshot(720, 540),
      plots,
      merge: view ? {
        report: view.report,
        tableImage: mergePanel.tableBox.hidden ? null : mergePanel.table.toDataURL('image/png'),
        mergedImage,
        results: mergePanel.results,
      } : { report: null, results: mergePanel.results },
    },
    { onPrint: () => window.print(), onClose: () => closeSummary() },
  );
}

async function openSummary() {
  if (app.running) pause();
  buildSummaryNow(await shareLink());
  $('summary').hidden = false;
  $('summary-print').focus();
}

function closeSummary() {
  $('summary').hidden = true;
  $('summary-open').focus({ preventScroll: true });
}

/** Keeps Tab inside `box` (the summary is modal). */
function trapFocus(e, box) {
  const items = [...box.querySelectorAll('button, a[href]')].filter((x) => !x.hidden);
  if (!items.length) return;
  const first = items[0];
  const last = items[items.length - 1];
  if (e.shiftKey && document.activeElement === first) {
    e.preventDefault();
    last.focus();
  } else if (!e.shiftKey && document.activeElement === last) {
    e.preventDefault();
    first.focus();
  }
}

// Ctrl+P anywhere prints the summary (the print stylesheet shows only it).
window.addEventListener('beforeprint', () => {
  if (!app.lab || !$('summary').hidden) return;
  try {
    buildSummaryNow();
  } catch (e) {
    setStatus(`Could not build the summary: ${message(e)}`, 'error');
  }
});

function refreshPanels() {
  if (!app.scenario) return;
  cameraPanel.sync(app.scenario);
  mapsPanel.sync(app.scenario);
  const ed = editable();
  robotsPanel.sonarRange = app.scenario.sensors?.sonar_range_m ?? 2;
  robotsPanel.sync(app.scenario, {
    editable: ed,
    selected: app.selection?.kind === 'robot' ? app.selection.index : null,
    problems: problemRobots(),
  });
  $('robot-count').textContent = `(${app.scenario.robots.length} of at most ${MAX_ROBOTS})`;
  refreshSelectionPanel(ed);
  updateReadouts(true);
}

let selectionKey = '';
function refreshSelectionPanel(ed) {
  const panel = $('selection-panel');
  const body = $('selection-body');
  const sel = app.selection;
  if (!sel || sel.kind !== 'wall' || !app.scenario.walls[sel.index]) {
    panel.hidden = true;
    selectionKey = '';
    return;
  }
  const w = app.scenario.walls[sel.index];
  const key = JSON.stringify([sel, w, ed]);
  if (key === selectionKey) return;
  selectionKey = key;
  panel.hidden = false;
  $('selection-title').textContent = `Selected wall ${sel.index + 1} of ${app.scenario.walls.length}`;
  const len = Math.hypot(w.to[0] - w.from[0], w.to[1] - w.from[1]);
  const textures = [...new Set(app.scenario.walls.map((x) => x.texture).filter(Boolean)), 'plain'];
  body.innerHTML = '';
  const coords = document.createElement('div');
  coords.className = 'field-row mono';
  coords.textContent = `(${fmt(w.from[0])}, ${fmt(w.from[1])}) → (${fmt(w.to[0])}, ${fmt(w.to[1])})  ${fmt(len)} m`;
  const row = document.createElement('div');
  row.className = 'field-row';
  row.innerHTML = `<label for="wall-texture">Texture</label>
    <input type="text" id="wall-texture" list="texture-names" placeholder="(own texture)" aria-label="Texture name of the selected wall">
    <datalist id="texture-names"></datalist>
    <button type="button" id="wall-delete" aria-label="Delete the selected wall">Delete wall</button>
    <label class="button" id="wall-picture-label" role="button" tabindex="0" aria-label="Put a PNG or JPEG picture on the selected wall">Picture…
      <input type="file" id="wall-picture" accept="image/png,image/jpeg" hidden></label>`;
  body.append(coords, row);
  const input = row.querySelector('#wall-texture');
  input.value = w.texture ?? '';
  input.disabled = !ed;
  row.querySelector('#wall-delete').disabled = !ed;
  const list = row.querySelector('#texture-names');
  for (const t of textures) {
    const o = document.createElement('option');
    o.value = t;
    list.append(o);
  }
  input.addEventListener(
    'change',
    guard(() => {
      if (!editable()) return notEditable();
      const next = clone(app.scenario);
      const t = input.value.trim();
      if (t) next.walls[sel.index].texture = t;
      else delete next.walls[sel.index].texture;
      commit(next);
      setStatus(t ? `Wall ${sel.index + 1} now has texture “${t}”.` : `Wall ${sel.index + 1} gets its own texture.`, 'info');
    }),
  );
  row.querySelector('#wall-delete').addEventListener('click', guard(deleteSelection));
  const picture = row.querySelector('#wall-picture');
  picture.disabled = !ed;
  row.querySelector('#wall-picture-label').addEventListener('keydown', (e) => {
    if (e.key === 'Enter' || e.key === ' ') {
      e.preventDefault();
      picture.click();
    }
  });
  picture.addEventListener('change', async () => {
    const file = picture.files && picture.files[0];
    picture.value = '';
    if (!file) return;
    if (!editable()) return notEditable();
    try {
      const bytes = new Uint8Array(await file.arrayBuffer());
      const name = file.name.replace(/\.[^.]*$/, '').replace(/[^\w-]+/g, '_').slice(0, 48) || 'picture';
      app.lab.addImageTexture(name, bytes); // throws with a message for a bad file
      const next = clone(app.scenario);
      next.walls[sel.index].texture = `image:${name}`;
      commit(next);
      setStatus(`Wall ${sel.index + 1} now shows ${file.name} (texture “image:${name}”).`, 'ok');
    } catch (e) {
      setStatus(`Could not use ${file.name}: ${message(e)}. The wall is unchanged.`, 'error');
    }
  });
  const note = document.createElement('p');
  note.className = 'hint';
  note.textContent =
    'Walls with the same texture name look alike; "plain" is featureless. A picture lives in this browser session; ' +
    'the scenario keeps its name, and a wall whose picture is not loaded shows a generated texture.';
  body.append(note);
}

function updateReadouts(force = false) {
  if (!app.lab) return;
  const now = performance.now();
  if (!force && now - app.lastReadoutMs < READOUT_INTERVAL_MS) return;
  app.lastReadoutMs = now;
  const st = readState();
  robotsPanel.update(st.steps > 0 ? st : null);
  $('clock').textContent = `t = ${fmt(st.time_s, 1)} s / ${Number(app.scenario.duration_s.toFixed(1))} s`;
  $('progress').value = st.total_steps ? st.steps / st.total_steps : 0;
  refreshControls(st);
}

function refreshControls(st = app.state) {
  if (!app.lab || !st) return;
  const ed = editable();
  const started = st.steps > 0;
  $('run').disabled = app.running || st.finished;
  $('pause').disabled = !app.running;
  $('step').disabled = st.finished;
  $('reset').disabled = !started && !app.running;
  $('add-robot').disabled = !ed || app.scenario.robots.length >= MAX_ROBOTS;
  $('add-robot').title =
    app.scenario.robots.length >= MAX_ROBOTS ? `At most ${MAX_ROBOTS} robots` : 'Add a robot near the middle of the view';
  $('delete').disabled = !ed || !app.selection;
  $('reset-preset').disabled = !(app.origin || app.preset);
  const badge = $('mode-badge');
  const [cls, text] = app.running
    ? ['run', 'Running']
    : st.finished
      ? ['done', 'Finished']
      : started
        ? ['pause', 'Paused']
        : ['edit', 'Editing'];
  badge.className = `badge ${cls}`;
  badge.textContent = text;
  for (const b of document.querySelectorAll('button.tool')) b.setAttribute('aria-pressed', String(b.id === `tool-${app.tool}`));
  canvas.classList.toggle('tool-wall', app.tool === 'wall' && ed);
}

// ---------------------------------------------------------------------------
// Editing: tools, selection, add/delete

function setTool(tool) {
  app.tool = tool;
  endDrag();
  if (tool === 'wall' && !editable()) notEditable();
  else if (tool === 'wall') setStatus('Wall tool: drag on the map to draw a wall; Alt or Shift for any angle.', 'info');
  refreshControls();
  app.dirty = true;
}

const deleteSelection = guard(() => {
  const sel = app.selection;
  if (!sel) return setStatus('Nothing selected: click a wall or robot first.', 'info');
  if (!editable()) return notEditable();
  if (sel.kind === 'robot') return removeRobot(sel.index);
  const next = clone(app.scenario);
  next.walls.splice(sel.index, 1);
  app.selection = null;
  commit(next);
  setStatus(`Wall deleted (${next.walls.length} left). Ctrl+Z undoes.`, 'info');
});

function removeRobot(i) {
  if (!editable()) return notEditable();
  if (app.scenario.robots.length <= 1) {
    setStatus('A scenario needs at least one robot: add another before removing this one.', 'warn');
    return;
  }
  const next = clone(app.scenario);
  const [gone] = next.robots.splice(i, 1);
  app.selection = null;
  commit(next);
  setStatus(`Removed ${gone.name}. Ctrl+Z undoes.`, 'info');
}

const addRobot = guard(() => {
  if (!editable()) return notEditable();
  if (app.scenario.robots.length >= MAX_ROBOTS) {
    setStatus(`At most ${MAX_ROBOTS} robots.`, 'warn');
    return;
  }
  const names = new Set(app.scenario.robots.map((r) => r.name));
  let k = app.scenario.robots.length + 1;
  while (names.has(`robot${k}`)) k++;
  const robot = {
    name: `robot${k}`,
    start: [0, 0, 0],
    follow: app.scenario.robots.length % 2 ? 'right' : 'left',
    distance: 0.6,
  };
  // Look for a free spot on a spiral around the middle of the view.
  const [cx, cy] = app.view.center.map((c) => snap(c, 0.5));
  let placed = null;
  for (let ring = 0; ring <= 12 && !placed; ring++) {
    for (let a = 0; a < Math.max(1, ring * 6) && !placed; a++) {
      const th = (2 * Math.PI * a) / Math.max(1, ring * 6);
      const p = [snap(cx + 0.5 * ring * Math.cos(th)), snap(cy + 0.5 * ring * Math.sin(th))];
      const trial = clone(app.scenario);
      trial.robots.push({ ...robot, start: [p[0], p[1], 0] });
      try {
        validateScenario(JSON.stringify(trial));
        placed = trial;
      } catch {
        // occupied: try the next spot
      }
    }
  }
  const next = placed ?? (() => {
    const t = clone(app.scenario);
    t.robots.push({ ...robot, start: [snap(cx), snap(cy), 0] });
    return t;
  })();
  app.selection = { kind: 'robot', index: next.robots.length - 1 };
  commit(next);
  const s = next.robots[next.robots.length - 1].start;
  setStatus(`Added ${robot.name} at (${fmt(s[0], 1)}, ${fmt(s[1], 1)}): drag it to place it, drag its yellow handle to turn it.`, 'info');
  reportProblems();
});

const newScenario = guard(() => {
  pushUndo();
  const seed = app.scenario?.seed ?? 1;
  const empty = {
    name: 'untitled',
    seed,
    duration_s: 300,
    walls: [],
    robots: [{ name: 'robot1', start: [10, 7.5, 0], follow: 'left', distance: 0.6 }],
  };
  loadScenarioText(JSON.stringify(empty), { preset: '' });
  app.tool = 'wall';
  refreshControls();
  setStatus('New empty scenario: drag on the map to draw walls (Wall tool), add robots, then Run.', 'info');
});

function nudge(dx, dy) {
  const sel = app.selection;
  if (!sel) return;
  if (!editable()) return notEditable();
  const next = clone(app.scenario);
  if (sel.kind === 'robot') {
    const s = next.robots[sel.index].start;
    s[0] = snap(s[0] + dx);
    s[1] = snap(s[1] + dy);
  } else {
    const w = next.walls[sel.index];
    w.from = [snap(w.from[0] + dx), snap(w.from[1] + dy)];
    w.to = [snap(w.to[0] + dx), snap(w.to[1] + dy)];
  }
  commit(next);
  reportProblems();
}

function turnSelected(dTheta) {
  const sel = app.selection;
  if (!sel || sel.kind !== 'robot') return;
  if (!editable()) return notEditable();
  const next = clone(app.scenario);
  const s = next.robots[sel.index].start;
  s[2] = snapAngle(s[2] + dTheta);
  commit(next);
  reportProblems();
}

// ---------------------------------------------------------------------------
// Pointer input on the canvas

function pointerPx(e) {
  const r = canvas.getBoundingClientRect();
  return [e.clientX - r.left, e.clientY - r.top];
}

function roundPt(p) {
  return p.map((v) => Number(v.toFixed(4)));
}

canvas.addEventListener('mousedown', (e) => {
  if (e.button === 1) e.preventDefault(); // no auto-scroll on middle click
});
canvas.addEventListener('contextmenu', (e) => {
  if (app.drag) e.preventDefault();
});

canvas.addEventListener(
  'pointerdown',
  guard((e) => {
    if (!app.lab) return;
    canvas.focus({ preventScroll: true });
    const px = pointerPx(e);
    app.pointer = px;
    const v = app.view;
    if (e.button === 1 || (e.button === 0 && app.spaceDown)) {
      app.spaceUsed = app.spaceDown;
      app.drag = { kind: 'pan', last: px };
      canvas.setPointerCapture(e.pointerId);
      canvas.classList.add('panning');
      return;
    }
    if (e.button !== 0) return;
    const p = v.toWorld(px);
    const tol = 7 / v.scale;
    const poses = robotPoses();
    const before = JSON.stringify(app.scenario);

    if (!editable()) {
      // While a run exists: click a robot to highlight its card, drag to pan.
      const r = hitRobot(poses, p, tol);
      if (r != null) {
        app.selection = { kind: 'robot', index: r };
        refreshPanels();
      }
      app.drag = { kind: 'pan', last: px };
      canvas.setPointerCapture(e.pointerId);
      app.dirty = true;
      return;
    }

    const sel = app.selection;
    if (sel && sel.kind === 'robot') {
      const pose = app.scenario.robots[sel.index].start;
      const [hx, hy] = v.toPx(handlePoint(pose, handleReach()));
      if (Math.hypot(px[0] - hx, px[1] - hy) <= 9) {
        app.drag = { kind: 'turn', index: sel.index, before };
        canvas.setPointerCapture(e.pointerId);
        return;
      }
    }
    const r = hitRobot(poses, p, tol);
    if (r != null) {
      app.selection = { kind: 'robot', index: r };
      const pose = app.scenario.robots[r].start;
      app.drag = e.shiftKey
        ? { kind: 'turn', index: r, before }
        : { kind: 'robot', index: r, before, offset: [p[0] - pose[0], p[1] - pose[1]] };
      canvas.setPointerCapture(e.pointerId);
      refreshPanels();
      app.dirty = true;
      return;
    }
    if (app.tool === 'wall') {
      const from = snapPoint(p);
      app.drag = { kind: 'wall-new', from, to: from };
      app.preview = [...from, ...from];
      canvas.setPointerCapture(e.pointerId);
      app.dirty = true;
      return;
    }
    if (sel && sel.kind === 'wall') {
      const w = app.scenario.walls[sel.index];
      for (const end of ['from', 'to']) {
        const [ex, ey] = v.toPx(w[end]);
        if (Math.hypot(px[0] - ex, px[1] - ey) <= 9) {
          app.drag = { kind: 'wall-end', index: sel.index, end, before };
          canvas.setPointerCapture(e.pointerId);
          return;
        }
      }
    }
    const wi = hitWall(app.scenario.walls, p, tol);
    if (wi != null) {
      app.selection = { kind: 'wall', index: wi };
      const w = app.scenario.walls[wi];
      app.drag = { kind: 'wall-move', index: wi, before, start: p, from: w.from, to: w.to };
      canvas.setPointerCapture(e.pointerId);
    } else {
      // Empty floor: deselect; a drag pans.
      app.selection = null;
      app.drag = { kind: 'pan', last: px };
      canvas.setPointerCapture(e.pointerId);
    }
    refreshPanels();
    refreshControls();
    app.dirty = true;
  }),
);

canvas.addEventListener(
  'pointermove',
  guard((e) => {
    if (!app.lab) return;
    const px = pointerPx(e);
    app.pointer = px;
    const d = app.drag;
    const v = app.view;
    if (!d) return hover(px);
    const p = v.toWorld(px);
    const free = e.altKey || e.shiftKey;
    switch (d.kind) {
      case 'pan':
        if (d.last[0] !== px[0] || d.last[1] !== px[1]) {
          v.panBy(px[0] - d.last[0], px[1] - d.last[1]);
          app.autoFit = false;
          d.last = px;
          d.moved = true;
          canvas.classList.add('panning');
          app.dirty = true;
        }
        break;
      case 'wall-new': {
        d.to = wallEnd(d.from, p, free);
        app.preview = [...d.from, ...d.to];
        app.dirty = true;
        break;
      }
      case 'wall-end': {
        const next = clone(app.scenario);
        const w = next.walls[d.index];
        const other = d.end === 'from' ? w.to : w.from;
        const end = wallEnd(other, p, free);
        if (Math.hypot(end[0] - other[0], end[1] - other[1]) < 1e-6) return;
        w[d.end] = end;
        d.moved = true;
        pushLive(next);
        break;
      }
      case 'wall-move': {
        const delta = [p[0] - d.start[0], p[1] - d.start[1]];
        const dd = e.altKey ? roundPt(delta) : snapPoint(delta);
        const next = clone(app.scenario);
        next.walls[d.index].from = roundPt([d.from[0] + dd[0], d.from[1] + dd[1]]);
        next.walls[d.index].to = roundPt([d.to[0] + dd[0], d.to[1] + dd[1]]);
        d.moved = dd[0] !== 0 || dd[1] !== 0;
        pushLive(next);
        break;
      }
      case 'robot': {
        const next = clone(app.scenario);
        const s = next.robots[d.index].start;
        const at = [p[0] - d.offset[0], p[1] - d.offset[1]];
        const q = e.altKey ? roundPt(at) : snapPoint(at);
        next.robots[d.index].start = [q[0], q[1], s[2]];
        d.moved = true;
        pushLive(next);
        break;
      }
      case 'turn': {
        const next = clone(app.scenario);
        const s = next.robots[d.index].start;
        const a = Math.atan2(p[1] - s[1], p[0] - s[0]);
        s[2] = e.altKey ? Number(wrapAngle(a).toFixed(4)) : Number(snapAngle(a).toFixed(6));
        d.moved = true;
        pushLive(next);
        break;
      }
      default:
        break;
    }
  }),
);

function hover(px) {
  const ed = editable();
  let cls = '';
  if (ed) {
    const v = app.view;
    const p = v.toWorld(px);
    const tol = 7 / v.scale;
    const sel = app.selection;
    if (sel && sel.kind === 'robot') {
      const [hx, hy] = v.toPx(handlePoint(app.scenario.robots[sel.index].start, handleReach()));
      if (Math.hypot(px[0] - hx, px[1] - hy) <= 9) cls = 'over-handle';
    }
    if (!cls && hitRobot(robotPoses(), p, tol) != null) cls = 'over-item';
    if (!cls && app.tool === 'select' && hitWall(app.scenario.walls, p, tol) != null) cls = 'over-item';
  }
  canvas.classList.toggle('over-item', cls === 'over-item');
  canvas.classList.toggle('over-handle', cls === 'over-handle');
}

function finishDrag(e) {
  const d = app.drag;
  if (!d) return;
  app.drag = null;
  canvas.classList.remove('panning');
  if (e && canvas.hasPointerCapture?.(e.pointerId)) canvas.releasePointerCapture(e.pointerId);
  switch (d.kind) {
    case 'wall-new': {
      app.preview = null;
      const len = Math.hypot(d.to[0] - d.from[0], d.to[1] - d.from[1]);
      if (len < 1e-6) {
        setStatus('A click makes no wall: press and drag to draw one.', 'info');
        break;
      }
      const next = clone(app.scenario);
      next.walls.push({ from: d.from, to: d.to });
      app.selection = { kind: 'wall', index: next.walls.length - 1 };
      commit(next);
      setStatus(
        `Wall ${next.walls.length} added: (${fmt(d.from[0], 1)}, ${fmt(d.from[1], 1)}) → (${fmt(d.to[0], 1)}, ${fmt(d.to[1], 1)}), ${fmt(len)} m.`,
        'info',
      );
      reportProblems();
      break;
    }
    case 'wall-end':
    case 'wall-move':
    case 'robot':
    case 'turn':
      if (d.moved && d.live) {
        commit(d.live, { undoFrom: d.before });
        if (d.kind === 'turn') {
          const s = d.live.robots[d.index];
          setStatus(`${s.name} now faces ${fmt(deg(s.start[2]), 0)}°.`, 'info');
        }
        reportProblems();
      } else {
        refreshPanels();
      }
      break;
    default:
      break;
  }
  refreshControls();
  app.dirty = true;
}

/** Esc during a drag: put everything back as it was. */
function cancelDrag() {
  const d = app.drag;
  if (!d) return false;
  app.drag = null;
  app.preview = null;
  canvas.classList.remove('panning');
  if (d.before) {
    app.lab.setScenario(d.before);
    app.problems = JSON.parse(app.lab.problemsJson());
  }
  app.dirty = true;
  setStatus('Cancelled.', 'info');
  return true;
}

function endDrag() {
  if (app.drag) cancelDrag();
}

canvas.addEventListener('pointerup', guard(finishDrag));
canvas.addEventListener('pointercancel', guard(() => cancelDrag()));
canvas.addEventListener('lostpointercapture', guard((e) => app.drag && finishDrag(e)));

canvas.addEventListener(
  'wheel',
  guard((e) => {
    e.preventDefault();
    const [px, py] = pointerPx(e);
    const unit = e.deltaMode === 1 ? 40 : e.deltaMode === 2 ? 400 : 1;
    app.view.zoomAt(px, py, Math.exp(-e.deltaY * unit * 0.0015));
    app.autoFit = false;
    app.dirty = true;
  }),
  { passive: false },
);

// ---------------------------------------------------------------------------
// Keyboard

function typingTarget(t) {
  if (!t || !t.tagName) return false;
  if (t.tagName === 'TEXTAREA' || t.tagName === 'SELECT') return true;
  if (t.tagName === 'INPUT') return !['checkbox', 'radio', 'button', 'file'].includes(t.type);
  return t.isContentEditable;
}

document.addEventListener(
  'keydown',
  guard((e) => {
    if (!app.lab) return;
    const t = e.target;
    if (!$('summary').hidden) {
      // The summary covers the page: only Escape (close) and Tab (kept inside) work.
      if (e.key === 'Escape') closeSummary();
      else if (e.key === 'Tab') trapFocus(e, $('summary'));
      return;
    }
    if (typingTarget(t)) {
      if (e.key === 'Escape') t.blur();
      return;
    }
    // Let focused buttons and links keep their own Space/Enter.
    if ((e.key === ' ' || e.key === 'Enter') && t.closest?.('button, a, label.button, input')) return;
    if ((e.ctrlKey || e.metaKey) && (e.key === 'z' || e.key === 'Z')) {
      e.preventDefault();
      undo();
      return;
    }
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    const big = e.shiftKey ? 1 : 0.1;
    switch (e.key) {
      case ' ':
        e.preventDefault();
        if (!e.repeat) {
          app.spaceDown = true;
          app.spaceUsed = false;
        }
        break;
      case 's':
      case 'S':
        step();
        break;
      case 'ArrowRight':
        e.preventDefault();
        if (app.selection && editable()) nudge(big, 0);
        else step();
        break;
      case 'ArrowLeft':
      case 'ArrowUp':
      case 'ArrowDown':
        if (app.selection && editable()) {
          e.preventDefault();
          const d = { ArrowLeft: [-big, 0], ArrowUp: [0, big], ArrowDown: [0, -big] }[e.key];
          nudge(...d);
        }
        break;
      case '[':
        turnSelected(Math.PI / 12);
        break;
      case ']':
        turnSelected(-Math.PI / 12);
        break;
      case 'r':
      case 'R':
        reset();
        break;
      case 'f':
      case 'F':
        fitView();
        break;
      case 'w':
      case 'W':
        setTool('wall');
        break;
      case 'v':
      case 'V':
        setTool('select');
        break;
      case 'Delete':
      case 'Backspace':
        e.preventDefault();
        deleteSelection();
        break;
      case 'Escape':
        if (cancelDrag()) break;
        if (!$('help-overlay').hidden) toggleHelp(false);
        else if (!$('pair-overlay').hidden) mergePanel.closePair();
        else if (guide.isOpen) guide.close();
        else if (app.tool === 'wall') setTool('select');
        else if (app.selection) {
          app.selection = null;
          refreshPanels();
          refreshControls();
        }
        app.dirty = true;
        break;
      case '?':
        toggleHelp();
        break;
      case 'g':
      case 'G':
        guide.toggle();
        break;
      default:
        break;
    }
  }),
);

document.addEventListener(
  'keyup',
  guard((e) => {
    if (e.key !== ' ' || !app.spaceDown) return;
    app.spaceDown = false;
    if (typingTarget(e.target)) return;
    if (!app.spaceUsed) {
      if (app.running) pause();
      else run();
    }
  }),
);

function toggleHelp(show) {
  const o = $('help-overlay');
  const open = show ?? o.hidden;
  o.hidden = !open;
  $('help').setAttribute('aria-expanded', String(open));
  if (open) $('help-close').focus();
}

// ---------------------------------------------------------------------------
// Toolbar wiring

function download(name, text, type) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

function safeName(s) {
  return String(s).replace(/[^\w.-]+/g, '_') || 'scenario';
}

function downloadLog(i) {
  const csv = app.lab.logCsv(i);
  const name = `${safeName(app.scenario.name)}-${safeName(app.scenario.robots[i].name)}-log.csv`;
  download(name, csv, 'text/csv');
  setStatus(`Saved ${name} (${csv.split('\n').length - 2} steps).`, 'info');
}

function wire() {
  // Mouse clicks should not leave focus on a button, so that Space keeps
  // meaning run/pause; keyboard users still tab to and press buttons.
  for (const b of document.querySelectorAll('.toolbar button')) b.addEventListener('mousedown', (e) => e.preventDefault());

  $('run').addEventListener('click', run);
  $('pause').addEventListener('click', pause);
  $('step').addEventListener('click', step);
  $('reset').addEventListener('click', reset);
  $('fit').addEventListener('click', () => fitView());
  $('help').addEventListener('click', () => toggleHelp());
  $('help-close').addEventListener('click', () => toggleHelp(false));
  $('tool-select').addEventListener('click', () => setTool('select'));
  $('tool-wall').addEventListener('click', () => setTool('wall'));
  $('add-robot').addEventListener('click', addRobot);
  $('delete').addEventListener('click', deleteSelection);
  $('new').addEventListener('click', newScenario);

  $('preset').addEventListener('change', async (e) => {
    const name = e.target.value;
    if (!name) return;
    try {
      await loadPreset(name);
      setStatus(`Loaded the ${name} preset (Ctrl+Z goes back to what you had).`, 'ok');
    } catch (err) {
      $('preset').value = app.preset;
      setStatus(`Could not load the ${name} preset: ${message(err)}`, 'error');
    }
  });

  $('export').addEventListener(
    'click',
    guard(() => {
      const name = `${safeName(app.scenario.name)}.json`;
      download(name, app.lab.scenarioJson(), 'application/json');
      setStatus(`Exported the scenario as ${name}.`, 'info');
    }),
  );

  const importLabel = $('import-label');
  importLabel.addEventListener('keydown', (e) => {
    if (e.key === 'Enter' || e.key === ' ') {
      e.preventDefault();
      $('import-file').click();
    }
  });
  $('import-file').addEventListener('change', async (e) => {
    const file = e.target.files?.[0];
    e.target.value = '';
    if (!file) return;
    try {
      const text = await file.text();
      const before = JSON.stringify(app.scenario);
      loadScenarioText(text, { preset: '' });
      app.undo.push(before);
      setStatus(`Imported ${file.name}: “${app.scenario.name}”, ${app.scenario.walls.length} walls, ${app.scenario.robots.length} robots.`, 'ok');
      reportProblems();
    } catch (err) {
      setStatus(`Could not import ${file.name}: ${message(err)}. The current scenario is unchanged.`, 'error');
    }
  });

  const speed = $('speed');
  speed.addEventListener('input', () => setSpeed(Number(speed.value)));
  setSpeed(Number(speed.value));

  $('reset-preset').addEventListener('click', resetToPreset);
  $('copy-link').addEventListener('click', copyLink);
  $('summary-open').addEventListener('click', () =>
    openSummary().catch((e) => setStatus(`Could not build the summary: ${message(e)}`, 'error')));
  $('guided-open').addEventListener('click', () => guide.toggle());

  $('seed').addEventListener(
    'change',
    guard((e) => {
      const n = Number(e.target.value);
      try {
        app.lab.setSeed(n);
      } catch (err) {
        e.target.value = String(app.scenario.seed);
        throw err;
      }
      app.running = false;
      app.scenario.seed = n;
      afterScenarioChange();
      setStatus(`Seed ${n}: the run starts over from t = 0 with new noise.`, 'info');
    }),
  );

  $('duration').addEventListener(
    'change',
    guard((e) => {
      const s = Number(e.target.value);
      try {
        app.lab.setDuration(s);
      } catch (err) {
        e.target.value = String(app.scenario.duration_s);
        throw err;
      }
      app.scenario.duration_s = s;
      autosave();
      scheduleShareHash();
      updateReadouts(true);
      setStatus(`Duration ${s} s.`, 'info');
    }),
  );

  for (const k of Object.keys(app.layers)) {
    const box = $(`layer-${k}`);
    box.addEventListener('change', () => {
      app.layers[k] = box.checked;
      try {
        localStorage.setItem(LAYERS_KEY, JSON.stringify(app.layers));
      } catch {
        // layers are a nicety
      }
      app.dirty = true;
    });
  }
}

function setSpeed(v) {
  app.speed = v;
  $('speed').value = String(v);
  $('speed-value').textContent = `${v}×`;
}

function restoreLayers() {
  try {
    const saved = JSON.parse(localStorage.getItem(LAYERS_KEY) ?? 'null');
    if (saved && typeof saved === 'object') {
      for (const k of Object.keys(app.layers)) if (typeof saved[k] === 'boolean') app.layers[k] = saved[k];
    }
  } catch {
    // ignore a bad layers entry
  }
  for (const k of Object.keys(app.layers)) $(`layer-${k}`).checked = app.layers[k];
}

// ---------------------------------------------------------------------------
// Main loop

function frame(now) {
  requestAnimationFrame(frame);
  if (!app.lab) return;
  try {
    if (app.running) advance(now);
    const changed = app.dirty;
    if (app.dirty) draw();
    cameraPanel.update(now, changed || app.running);
    mapsPanel.update(now, changed || app.running);
    mergePanel.update(now);
    guide.update(now);
    if (app.running) updateReadouts(false);
  } catch (e) {
    app.running = false;
    setStatus(message(e), 'error');
    refreshControls();
  }
}

async function main() {
  try {
    await init();
    setRobotColours(JSON.parse(robotColours()));
  } catch (e) {
    setStatus(`Could not load the wasm module (web/pkg): run ./build.sh build, then reload. ${message(e)}`, 'error');
    return;
  }
  $('version').textContent = `slamlab ${version()}${simdEnabled() ? ' · SIMD128' : ''}`;
  wire();
  restoreLayers();
  try {
    await restore();
  } catch (e) {
    setStatus(`Could not load a scenario: ${message(e)}`, 'error');
    return;
  }
  new ResizeObserver(() => resize()).observe(canvas.parentElement);
  resize();
  updateReadouts(true);

  // A small handle for the end-to-end test and for poking at the lab from
  // the browser console.
  window.slamlab = {
    ready: true,
    lab: app.lab,
    scenario: () => clone(app.scenario),
    state: () => JSON.parse(app.lab.stateJson()),
    problems: () => clone(app.problems),
    /** Client (page) coordinates of a world point, for scripted mouse input. */
    worldToClient: (x, y) => {
      const r = canvas.getBoundingClientRect();
      const [px, py] = app.view.toPx([x, y]);
      return [r.left + px, r.top + py];
    },
    view: () => ({ center: [...app.view.center], scale: app.view.scale }),
    /** The link that restores the current scenario and seed (web/share.js). */
    shareLink,
    guide,
    mergePanel,
    markers: () => clone(app.guideMarkers),
  };
  document.body.dataset.ready = 'true';
  requestAnimationFrame(frame);
}

main();
