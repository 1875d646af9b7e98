// The log replay as JavaScript sees it: one facade over the raw
// wasm-bindgen `LogReplay` (crate/src/bindings/logs.rs), used by the page's
// "Your log" worker (web/page/real/log-worker.js, web/page/real/log-merge.js)
// and by the `run-log` command (web/cli/run-log.mjs).
//
// A log replay reads a laser log (CARMEN: FLASER / ROBOTLASER1 / RAWLASER1
// and ODOM records, plain or gzip), optionally keeps a stretch of its laser
// records, replays it through the log SLAM a few scans at a time (scan
// matching, pose graph, loop closures), settles the pose graph at the end
// and reports every scan's pose and the map (docs/interfaces.md, "Real
// laser logs: run-log").
//
// As web/lab.js does for `Lab`, this module parses every JSON text the
// binding returns once, here, and hands back objects: `replay.view()`
// rather than `JSON.parse(replay.viewJson())`. Method names follow the
// binding's, without the `Json` suffix where the result is parsed; bytes
// (map pixels, PGM, PNG) and the YAML text pass straight through. The
// binding's errors (a malformed record, a bad range) are thrown unchanged,
// as `Error`s whose message names the problem (with the line number for a
// record); a `WebAssembly.RuntimeError` is a bug.
//
// A new binding method gets its facade method in the section it belongs to
// (opening, stepping, results, the live map), parsed here if it returns
// JSON. This module imports nothing: the caller hands it the loaded
// wasm-bindgen module.

/** The largest `to` the binding takes (an i32); larger means the end. */
const LAST_RECORD = 2 ** 31 - 1;

/** Accepts timings as an object or as JSON text. */
const timingsText = (t) => (typeof t === 'string' ? t : JSON.stringify(t ?? {}));

export class LogReplay {
  /**
   * A replay of the CARMEN log in `bytes` (Uint8Array; plain or gzip) on
   * the loaded wasm-bindgen module `wasm`; throws with the line number of
   * a malformed record.
   */
  static open(wasm, bytes) {
    return new LogReplay(new wasm.LogReplay(bytes));
  }

  /** Wraps a raw wasm-bindgen `LogReplay` (kept as `this.raw` for tests and the console). */
  constructor(raw) {
    this.raw = raw;
  }

  /** Frees the replay held in wasm memory; the object is unusable afterwards. */
  free() {
    this.raw.free();
  }

  // --- The log --------------------------------------------------------------------

  /** How many laser records the log holds. */
  laserRecords() {
    return this.raw.laserRecords();
  }

  /**
   * What was picked from a bag and why — `{scan_topic, scan_reason,
   * odometry, odometry_reason, truth_topic, truth_reason, laser_frame,
   * base_frame, laser_offset, offset_reason, scan_topics, odometry_topics,
   * truth_topics}` — or null for a CARMEN log.
   */
  picked() {
    return JSON.parse(this.raw.pickedJson());
  }

  /**
   * Replays laser records `from..=to` only (0-based; `to` left out, null or
   * negative: to the end); throws when the stretch holds no record.
   */
  setRange(from, to) {
    const last = to === undefined || to === null || to < 0 ? -1 : Math.min(to, LAST_RECORD);
    this.raw.setRange(from, last);
  }

  // --- The replay -----------------------------------------------------------------

  /** Replays up to `n` more scans; returns how many are left. */
  step(n) {
    return this.raw.step(n);
  }

  /** Replays what is left, settles the pose graph and draws the map. */
  finish() {
    this.raw.finish();
  }

  /**
   * The replay so far: `{done, total, odometry, poses, closures}`, with
   * each replayed scan's odometry and current SLAM pose as flat
   * `[x, y, theta, ...]` lists and each loop closure as
   * `{segment: [x1, y1, x2, y2], from_scan, to_scan, score}`.
   */
  view() {
    return JSON.parse(this.raw.viewJson());
  }

  /**
   * The ground truth beside the SLAM path so far, or null when the log
   * has none: `{poses, errors, ate_m}` — the truth at each replayed scan's
   * time laid onto the SLAM's frame by the rigid fit the ATE is scored
   * after (flat `[x, y, theta, ...]`), and `[time, error m, ...]`.
   */
  truth() {
    return JSON.parse(this.raw.truthJson());
  }

  /**
   * Sets the relations of a benchmark file (text of `t1 t2 x y z roll
   * pitch yaw` lines, Kümmerle et al. 2009) to score against; returns how
   * many. The report then carries `relations`.
   */
  setRelations(text) {
    return this.raw.setRelations(text);
  }

  /**
   * Whether the report also checks the relations against their own scans
   * and the wheel odometry (its `relation_check`).
   */
  setCheckRelations(on) {
    this.raw.setCheckRelations(on);
  }

  /**
   * The relations checked against their own scans and the wheel odometry
   * (`run-log --check-relations`'s `relation_check`), or null without
   * relations.
   */
  relationCheck() {
    return JSON.parse(this.raw.relationCheckJson());
  }

  /**
   * The replay so far scored against the relations: `{count, matched,
   * trans_m: {mean, sd, max}, rot_deg: {mean, sd, max}, worst, errors}`,
   * each error `{t1, t2, scan1, scan2, trans_m, rot_deg}`.
   */
  relationScore() {
    return JSON.parse(this.raw.relationScoreJson());
  }

  /** Each scan's time (s, the log's clock) of the stretch replayed, replayed or not (Float64Array). */
  times() {
    return this.raw.times();
  }

  /**
   * The replay as it was once `k` scans were replayed (1 to `done`), in
   * the shape of `view()`: the first `k` scans at the poses the SLAM had
   * for them then, and the loop closures found by then.
   */
  viewAt(k) {
    return JSON.parse(this.raw.viewAtJson(k));
  }

  // --- The results (after finish) ----------------------------------------------------

  /** The run-log report as an object; `timings` (ms, object or JSON text) becomes its `timings_ms`. */
  report(timings = {}) {
    return JSON.parse(this.reportText(timings));
  }

  /** The same as the binding's JSON text, byte for byte (what `run-log --json` prints). */
  reportText(timings = {}) {
    return this.raw.reportJson(timingsText(timings));
  }

  /** The map as a binary PGM (ROS map_server; Uint8Array). */
  mapPgm() {
    return this.raw.mapPgm();
  }

  /** The map as a PNG (Uint8Array). */
  mapPng() {
    return this.raw.mapPng();
  }

  /** The map_server YAML text naming `image` (the PGM's file name). */
  mapYaml(image) {
    return this.raw.mapYaml(image);
  }

  // --- The live map (the scans so far at their current poses) ------------------------

  /** Draws the live map; false before the first scan (nothing drawn). */
  drawLive() {
    return this.raw.drawLive();
  }

  /** Draws, as the live map, the first `k` scans' map at the poses they had once scan `k` was replayed. */
  drawAt(k) {
    this.raw.drawAt(k);
  }

  /** The live map's `{width, height, resolution_m, origin_m, occupied_cells, scans, dropped_updates}`; throws before `drawLive`. */
  liveInfo() {
    return JSON.parse(this.raw.liveInfoJson());
  }

  /** The live map's grey pixels (PGM shades), top row first (Uint8Array). */
  livePixels() {
    return this.raw.livePixels();
  }
}
