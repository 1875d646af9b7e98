// The lab page's composition root: it loads the wasm build, makes the
// page's modules and connects them. Nothing else lives here.
//
// The modules (web/page/, one concern each; ARCHITECTURE.md, "The page and
// the command line"):
//   state.js        the store: the scenario being edited, with commit and undo
//   run.js          the run controller: Run, Pause, Step, Reset and the pace
//   world-view.js   the map canvas: what the Lab draws, and the overlay on it
//   editor.js       tools and edits; wall-panel.js the selected wall's panel
//   pointer.js      dragging, drawing, panning and zooming on the map
//   keys.js         the keyboard shortcuts
//   persistence.js  presets, the autosave and links (share.js encodes them)
//   toolbar.js      the controls around the map and what they show
//   summary.js      the printable summary, read from each panel's method
//   palette.js      the robots' colours; status.js the status line and guard
//   *-panel.js, guided.js  the side and bottom panels, the guided mode;
//                   pair-view.js (+ pair-map.js) the merge's frame pair,
//                   match-table.js, merge-words.js, hidpi.js (pixel ratio)
//   frame.js        an animation frame's work and pacing (+ frame-times.js)
//   real/           saved maps and logs, merged and replayed in workers;
//                   lab-drop.js hands files dropped on the lab to them
// and web/lab.js, the facade over the wasm `Lab` the command line uses too.
//
// Data flows one way: input handlers call the store or a controller; the
// store tells `onChange` what changed; the views read the store and the
// run controller. The world view redraws on the next animation frame once
// something invalidated it. Every handler that calls into wasm runs inside
// `guard`, which shows what went wrong in the status line.

import init, * as wasm from './pkg/slamlab.js';
import { buildInfo } from './lab.js';
import { clone, MAX_ROBOTS, Store } from './page/state.js';
import { RunController } from './page/run.js';
import { WorldView } from './page/world-view.js';
import { Editor } from './page/editor.js';
import { WallPanel } from './page/wall-panel.js';
import { PointerInput } from './page/pointer.js';
import { Keys } from './page/keys.js';
import { Persistence } from './page/persistence.js';
import { Toolbar, download } from './page/toolbar.js';
import { Summary } from './page/summary.js';
import { setRobotColours } from './page/palette.js';
import { fitStats } from './page/hidpi.js';
import { FramePacer } from './page/frame.js';
import { makeGuard, message, reportUncaught, setStatus } from './page/status.js';
import { RobotsPanel } from './page/robots-panel.js';
import { CameraPanel } from './page/camera-panel.js';
import { MapsPanel } from './page/maps-panel.js';
import { MergePanel } from './page/merge-panel.js';
import { GuidedTour } from './page/guided.js';
import { Covers } from './page/real/cover.js';
import { SavedMapsView } from './page/real/panel.js';
import { LogView } from './page/real/log-panel.js';
import { takeDrops } from './page/lab-drop.js';

const $ = (id) => document.getElementById(id);
const canvas = $('world');
const onError = (e) => setStatus(message(e), 'error');
const lab = () => store.lab;

reportUncaught();

/** After an error: stop running, drop any drag, and show the controls as they are. */
const guard = makeGuard(() => {
  runner.halt();
  pointer.drop();
  view.invalidate();
  toolbar.refresh();
});

const store = new Store(wasm, 'thesis');
const refreshControls = () => toolbar.refresh();
const invalidate = () => view.invalidate();
const editable = () => runner.editable();
const cancelDrag = () => pointer.cancel();

const runner = new RunController(store, {
  guard, cancelDrag, refreshPanels, refreshControls, invalidate, readouts: (force) => toolbar.readouts(force),
  // The guide, when open, says what comes next in its own steps.
  finished: (st) => (guide.isOpen ? guide.announce() : st.robots.length >= 2 && mergePanel.reveal()),
});
const view = new WorldView(canvas, store, {
  running: () => runner.running, editable, state: () => runner.state, readState: () => runner.readState(),
  tool: () => editor.tool, preview: () => pointer.preview, guided: () => guide.isOpen,
});
const editor = new Editor(store, {
  guard, editable, cancelDrag, refreshControls, invalidate, validate: (text) => wasm.validateScenario(text),
  center: () => view.view.center,
  robotsChanged: () => {
    robotsPanel.key = '';
    refreshPanels();
  },
});
const wallPanel = new WallPanel(store, editor, { guard, editable });
const pointer = new PointerInput(canvas, store, view, editor, { guard, editable, refreshPanels, refreshControls });
const persistence = new Persistence(store, { validate: (text) => wasm.validateScenario(text) });

const robotsPanel = new RobotsPanel($('robots'), {
  select: (i) => {
    store.select({ kind: 'robot', index: i });
    refreshPanels();
    view.invalidate();
  },
  rename: (i, name) => editor.editRobot(i, (r) => (r.name = name.trim()), 'renamed'),
  setFollow: (i, side) => editor.editRobot(i, (r) => (r.follow = side), 'now follows the wall on its ' + side),
  setDistance: (i, d) => editor.editRobot(i, (r) => (r.distance = d), `keeps ${d} m to its wall`),
  remove: (i) => editor.removeRobot(i),
  downloadLog: guard((i) => toolbar.downloadLog(i)),
});
const cameraPanel = new CameraPanel($('cameras'), {
  lab,
  onMarker: (picks) => {
    view.marker = picks[picks.length - 1] ?? null; // the camera's view cone
    view.pickMarkers = picks; // with two or more, each is labelled on the map
    view.invalidate();
  },
  onError,
});
const mapsPanel = new MapsPanel($('maps'), { lab, onError, download });
const mergePanel = new MergePanel($('merge'), $('pair-overlay'), {
  lab,
  canMerge: () => Boolean(store.lab && runner.state && runner.state.steps > 0 && !runner.running && store.scenario.robots.length >= 2),
  robotCount: () => store.scenario?.robots.length ?? 0,
  onError,
  setStatus,
  quiet: () => guide.isOpen,
  download,
  report: () => store.lab.reportText(),
});
const guide = new GuidedTour($('guide'), $('guided-open'), {
  lab,
  run: () => runner.info(),
  loadThesisAndRun: async () => {
    await persistence.loadPreset('thesis');
    toolbar.setSpeed(50);
    runner.run();
  },
  merge: mergePanel,
  setMarkers: (m) => {
    view.guideMarkers = m;
    view.invalidate();
  },
  reveal: (id, block = 'start') => {
    const e = $(id);
    (block === 'start' ? e?.closest('.panel') : e)?.scrollIntoView({ block, behavior: 'smooth' });
  },
  zoomTo: (points) => view.zoomTo(points),
  onError,
  setStatus,
  onToggle: (open) => {
    document.body.classList.toggle('guided', open);
    if (!open) mergePanel.flushStatus();
    view.invalidate();
  },
});
const summary = new Summary($('summary'), $('summary-open'), {
  lab,
  scenario: () => store.scenario,
  state: () => runner.readState(),
  link: () => persistence.currentLink,
  shareLink: () => persistence.shareLink(),
  pause: () => runner.pause(),
  world: (w, h) => view.snapshot(w, h),
  maps: mapsPanel,
  merge: mergePanel,
});
const covers = new Covers();
const savedMaps = new SavedMapsView($('real'), $('real-open'), { download, covers });
const logView = new LogView($('logview'), $('log-open'), { download, covers });
const toolbar = new Toolbar({ guard, store, runner, editor, view, persistence, robotsPanel, canvas });
const keys = new Keys({
  guard, store, runner, editor, view, pointer, toolbar, summary, merge: mergePanel, guide, refreshPanels, refreshControls,
});

/** Every panel in step with the scenario, the selection and the run. */
function refreshPanels() {
  const scenario = store.scenario;
  if (!scenario) return;
  cameraPanel.sync(scenario);
  mapsPanel.sync(scenario);
  const ed = runner.editable();
  robotsPanel.sonarRange = scenario.sensors?.sonar_range_m ?? 2;
  robotsPanel.sync(scenario, {
    editable: ed,
    selected: store.selection?.kind === 'robot' ? store.selection.index : null,
    problems: store.problemRobots(),
  });
  $('robot-count').textContent = `(${scenario.robots.length} of at most ${MAX_ROBOTS})`;
  wallPanel.sync(ed);
  toolbar.readouts(true);
  if (!runner.running) {
    // Finished, paused or stepped: the final state, not the last throttled refresh.
    cameraPanel.refresh(true);
    mapsPanel.refresh();
    guide.update(performance.now(), true);
  }
}

/** After every change of the scenario (web/page/state.js says which kind). */
function onChange(kind) {
  if (kind === 'load' || kind === 'seed') runner.halt();
  if (kind === 'load') pointer.drop();
  toolbar.showScenario();
  persistence.saveAndShare();
  if (kind === 'duration') {
    toolbar.readouts(true);
    return;
  }
  refreshPanels();
  toolbar.refresh();
  view.invalidate();
  if (kind === 'load') view.fit();
}

const pacer = new FramePacer({ runner, view, cameraPanel, mapsPanel, mergePanel, guide, toolbar });

/** One animation frame: redraw what is due, advance the run in the time
 *  left, and let the panels follow (page/frame.js). */
function frame(now) {
  if (covers.holdsFrames(runner.running, () => requestAnimationFrame(frame))) return;
  requestAnimationFrame(frame);
  if (!store.lab) return;
  try {
    pacer.run(now);
  } catch (e) {
    runner.halt();
    onError(e);
    toolbar.refresh();
  }
}

async function main() {
  let info;
  try {
    await init();
    info = buildInfo(wasm);
    setRobotColours(info.colours);
  } catch (e) {
    setStatus(`Could not load the wasm module (web/pkg): run ./build.sh build, then reload. ${message(e)}`, 'error');
    return;
  }
  $('version').textContent = `slamlab ${info.version}${info.simd ? ' · SIMD128' : ''}`;
  store.subscribe(onChange);
  view.restoreLayers();
  toolbar.wire();
  $('guided-open').addEventListener('click', () => guide.toggle());
  savedMaps.wire();
  logView.wire();
  takeDrops(document, { maps: savedMaps, log: logView, say: setStatus });
  pointer.listen();
  keys.listen();
  persistence.listen();
  try {
    await persistence.restore();
  } catch (e) {
    setStatus(`Could not load a scenario: ${message(e)}`, 'error');
    return;
  }
  new ResizeObserver(() => view.resize()).observe(canvas.parentElement);
  view.resize();
  toolbar.readouts(true);

  // A small handle for the end-to-end tests and for poking at the lab from
  // the browser console (`lab` is the raw wasm-bindgen Lab).
  window.slamlab = {
    ready: true,
    lab: store.lab.raw,
    scenario: () => clone(store.scenario),
    state: () => store.lab.state(),
    problems: () => clone(store.problems),
    /** Client (page) coordinates of a world point, for scripted mouse input. */
    worldToClient: (x, y) => view.worldToClient(x, y),
    view: () => ({ center: [...view.view.center], scale: view.view.scale }),
    /** The link that restores the current scenario and seed (web/page/share.js). */
    shareLink: () => persistence.shareLink(),
    guide,
    mergePanel,
    markers: () => clone(view.guideMarkers),
    /** The frames picked in the film strips and marked on the map: `[[robot, index]]`. */
    picks: () => view.pickMarkers.map((m) => [m.robot, m.index]),
    /** Work counters for the page tests (issue 22): live camera renders per
     *  robot, maps scored, canvas backing stores resized. */
    perf: () => ({ liveDraws: [...cameraPanel.liveDraws], scored: mapsPanel.scored, resized: fitStats.resized }),
    savedMaps,
    logView,
    /** Where the frames' time went since the last `reset` (web/page/frame-times.js). */
    frameTimes: (reset = false) => pacer.report(reset),
  };
  document.body.dataset.ready = 'true';
  requestAnimationFrame(frame);
}

main();
