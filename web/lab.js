// The lab as JavaScript sees it: one facade over the raw wasm-bindgen `Lab`
// (crate/src/bindings), used by the page (web/app.js and web/page/) and by
// the command line (web/cli/) alike.
//
// The binding hands structured results across the wasm boundary as JSON
// text (ARCHITECTURE.md, "Two layers"); this module parses each of them
// once, here, so its callers get objects: `lab.state()` rather than
// `JSON.parse(lab.stateJson())`. Everything else (stepping, drawing into a
// canvas, bytes for downloads) is handed straight through. Method names
// follow the binding's, without the `Json` suffix where the result is
// parsed. The binding's errors (bad input) are thrown unchanged, as `Error`s
// whose message names the problem; a `WebAssembly.RuntimeError` is a bug.
//
// This module imports nothing: the page hands it the wasm-bindgen module it
// loaded with `init()`, the command line the one web/cli/wasm.mjs loaded
// (worker threads use their own raw `Lab`, web/cli/frame-worker.mjs).

/** Accepts a scenario as an object or as JSON text. */
const scenarioText = (s) => (typeof s === 'string' ? s : JSON.stringify(s));

export class Lab {
  /**
   * A lab of `scenario` (object or JSON text of the scenario format) on the
   * loaded wasm-bindgen module `wasm`; throws with the binding's message if
   * the scenario is not valid.
   */
  static open(wasm, scenario) {
    return new Lab(new wasm.Lab(scenarioText(scenario)));
  }

  /** Wraps a raw wasm-bindgen `Lab` (kept as `this.raw` for tests and the console). */
  constructor(raw) {
    this.raw = raw;
  }

  // --- The scenario ---------------------------------------------------------

  /** Replaces the scenario (object or text); throws, keeping the old one, if it is bad. Resets the run. */
  setScenario(scenario) {
    this.raw.setScenario(scenarioText(scenario));
  }

  /** The scenario in the lab's canonical form (an object). */
  scenario() {
    return JSON.parse(this.raw.scenarioJson());
  }

  /** The same as JSON text (for a file, a link or a worker). */
  scenarioText() {
    return this.raw.scenarioJson();
  }

  /** Problems that keep the scenario from running: `[{field, text}]` (empty when it can run). */
  problems() {
    return JSON.parse(this.raw.problemsJson());
  }

  setSeed(seed) {
    this.raw.setSeed(seed);
  }

  setDuration(seconds) {
    this.raw.setDuration(seconds);
  }

  /** Bytes of camera frames all robots may keep together (default 16 MiB); stops the run. */
  setFrameBudget(bytes) {
    this.raw.setFrameBudget(bytes);
  }

  // --- The run --------------------------------------------------------------

  /** Back to t = 0 (the scenario is kept). */
  reset() {
    this.raw.reset();
  }

  /** Runs up to `n` 0.1 s control steps; returns how many ran (fewer at the end). */
  step(n) {
    return this.raw.step(n);
  }

  runToEnd() {
    this.raw.runToEnd();
  }

  /** Simulated time (s). */
  timeS() {
    return this.raw.timeS();
  }

  /** The run's live state: `{time_s, steps, total_steps, finished, robots: [...]}`. */
  state() {
    return JSON.parse(this.raw.stateJson());
  }

  /** The run's report (the `run --json` document) as an object; `timings` in ms. */
  report(timings = {}) {
    return JSON.parse(this.reportText(timings));
  }

  /** The same as the binding's JSON text, byte for byte (what `run --json` prints). */
  reportText(timings = {}) {
    return this.raw.reportJson(JSON.stringify(timings));
  }

  /**
   * The same text, byte for byte, handed to `write` in chunks (Uint8Array of
   * UTF-8) as it is made: for reports too large to hold whole (sixteen
   * robots over an hour write 75 MB).
   */
  writeReport(timings, write) {
    this.raw.writeReport(JSON.stringify(timings ?? {}), write);
  }

  /** A robot's log as CSV in the thesis's layout. */
  logCsv(robot) {
    return this.raw.logCsv(robot);
  }

  /** The index of the robot called `name`; throws naming the robots there are. */
  robotIndex(name) {
    return this.raw.robotIndex(name);
  }

  // --- The world view (canvas) ------------------------------------------------

  /** Sets what `draw` shows: size, centre, scale, layers, selection (see crate/src/render/mod.rs). */
  setView(view) {
    this.raw.setView(JSON.stringify(view));
  }

  /** The centre and scale that fit the scenario into `width × height` device pixels. */
  fitView(width, height) {
    return JSON.parse(this.raw.fitView(width, height));
  }

  /** `{grid_m, scale_bar_m}` of the current view. */
  viewMetrics() {
    return JSON.parse(this.raw.viewMetrics());
  }

  /** Renders the world into a 2-D canvas context. */
  draw(ctx) {
    this.raw.draw(ctx);
  }

  // --- Cameras and frames ---------------------------------------------------------

  /** The camera's intrinsics and frame size. */
  camera() {
    return JSON.parse(this.raw.cameraInfo());
  }

  drawCamera(robot, ctx) {
    this.raw.drawCamera(robot, ctx);
  }

  /** Every captured frame's metadata for a robot (time, poses, index). */
  frames(robot) {
    return JSON.parse(this.raw.framesJson(robot));
  }

  frameCount(robot) {
    return this.raw.frameCount(robot);
  }

  /** One frame's metadata. */
  frame(robot, index) {
    return JSON.parse(this.raw.frameJson(robot, index));
  }

  drawFrame(robot, index, ctx) {
    this.raw.drawFrame(robot, index, ctx);
  }

  /** Frame `index` as a thumbnail `width` pixels wide (the height in proportion). */
  drawFrameThumb(robot, index, width, ctx) {
    this.raw.drawFrameThumb(robot, index, width, ctx);
  }

  framePng(robot, index) {
    return this.raw.framePng(robot, index);
  }

  /** Registers a PNG/JPEG as the texture `image:NAME`; throws on a bad file. */
  addImageTexture(name, bytes) {
    this.raw.addImageTexture(name, bytes);
  }

  // --- Maps (SLAM and odometry-only) ---------------------------------------------

  mapPgm(robot, mapper) {
    return this.raw.mapPgm(robot, mapper);
  }

  mapPng(robot, mapper) {
    return this.raw.mapPng(robot, mapper);
  }

  mapYaml(robot, mapper, image) {
    return this.raw.mapYaml(robot, mapper, image);
  }

  /** A robot's map's size, resolution and origin (`width`, `height`, `resolution_m`, …). */
  mapInfo(robot, mapper) {
    return JSON.parse(this.raw.mapInfoJson(robot, mapper));
  }

  /** A robot's SLAM and odometry-only scores against the truth. */
  slamFigures(robot) {
    return JSON.parse(this.raw.slamFiguresJson(robot));
  }

  /** Position error over time, at most `maxRows` rows. */
  slamErrors(robot, maxRows) {
    return JSON.parse(this.raw.slamErrorsJson(robot, maxRows));
  }

  drawMap(ctx, robot, mapper, width, height) {
    this.raw.drawMap(ctx, robot, mapper, width, height);
  }

  benchMatchScan(robot) {
    return this.raw.benchMatchScan(robot);
  }

  // --- Merging the maps -------------------------------------------------------

  /** Starts a merge with `method`; returns its progress `{stage, done, total, finished}`. */
  mergeStart(method) {
    return JSON.parse(this.raw.mergeStart(method));
  }

  /** Does up to `units` units of merge work; returns the progress. */
  mergeAdvance(units) {
    return JSON.parse(this.raw.mergeAdvance(units));
  }

  /** Runs the merge to its end; returns the progress. */
  mergeFinish() {
    return JSON.parse(this.raw.mergeFinish());
  }

  hasMerge() {
    return this.raw.hasMerge();
  }

  /** The merge's tables and report (`{tables, report, ...}`). */
  mergeView() {
    return JSON.parse(this.raw.mergeViewJson());
  }

  /** The frames the thesis method selected, with their poses. */
  mergeSelection() {
    return JSON.parse(this.raw.mergeSelectionJson());
  }

  /** One checked frame pair's matches and quad. */
  mergePair(pair, row, col) {
    return JSON.parse(this.raw.mergePairJson(pair, row, col));
  }

  drawMerged(ctx, width, height) {
    this.raw.drawMerged(ctx, width, height);
  }

  mergedPgm() {
    return this.raw.mergedPgm();
  }

  mergedPng() {
    return this.raw.mergedPng();
  }

  mergedYaml(image) {
    return this.raw.mergedYaml(image);
  }

  /** Every group of robots the merge joined, each in its first robot's frame,
   *  with its errors against the truth: `[{group, robots, transforms, reason?, errors}]`. */
  mergeGroups() {
    return JSON.parse(this.raw.mergeGroupsJson());
  }

  drawGroupMerged(ctx, group, width, height) {
    this.raw.drawGroupMerged(ctx, group, width, height);
  }

  groupMergedPgm(group) {
    return this.raw.groupMergedPgm(group);
  }

  groupMergedYaml(group, image) {
    return this.raw.groupMergedYaml(group, image);
  }

  /** Group `group`'s fused map as a PNG (the ROS map's picture, as `mergedPng`). */
  groupMergedPng(group) {
    return this.raw.groupMergedPng(group);
  }

  // --- Describing frames in other threads (web/cli/describe-pool.mjs) ----------------

  /** Frames a merge with `method` would describe that are not yet: `[{robot, index}]`. */
  framesToDescribe(method) {
    const flat = this.raw.framesToDescribe(method);
    const out = [];
    for (let k = 0; k < flat.length; k += 2) out.push({ robot: flat[k], index: flat[k + 1] });
    return out;
  }

  /** Whether the run still holds a frame (the store thins its frames when full). */
  hasFrame(robot, index) {
    return this.raw.hasFrame(robot, index);
  }

  /** What a worker needs to render a frame (JSON text, handed on unparsed). */
  frameSpec(robot, index) {
    return this.raw.frameSpecJson(robot, index);
  }

  describeFrameSpec(spec, method) {
    return this.raw.describeFrameSpec(spec, method);
  }

  /** False (nothing kept) when the frame has been thinned since it was handed out. */
  describeRendered(robot, index, method, gray) {
    return this.raw.describeRendered(robot, index, method, gray);
  }

  /** False (nothing kept) when the frame has been thinned since it was handed out. */
  storeDescribed(robot, index, method, packed) {
    return this.raw.storeDescribed(robot, index, method, packed);
  }

  // --- Mapping in other threads (web/cli/slam-pool.mjs) ---------------------------------

  /** A robot's mapping as bytes for a worker's `SlamAway`; its steps then wait here. */
  sendMappingAway(robot) {
    return this.raw.sendMappingAway(robot);
  }

  /** The steps an away robot made since they were last taken (bytes; empty when none). */
  takeMappingSteps(robot) {
    return this.raw.takeMappingSteps(robot);
  }

  /** The SLAM poses an away robot's worker reported for its newest steps (flat x, y, theta). */
  noteAwayEstimates(robot, flat) {
    this.raw.noteAwayEstimates(robot, flat);
  }

  /** Takes a robot's mapping back (`SlamAway.finish()`'s bytes). */
  bringMappingHome(robot, bytes) {
    this.raw.bringMappingHome(robot, bytes);
  }
}

/** What the loaded build is: `{version, simd, colours}` (colours: `[[r, g, b], ...]` by robot index). */
export function buildInfo(wasm) {
  return { version: wasm.version(), simd: wasm.simdEnabled(), colours: JSON.parse(wasm.robotColours()) };
}
