// A ROS bag as JavaScript sees it: one facade over the raw wasm-bindgen
// `BagFile` (crate/src/bindings/bags.rs), used by the page's "Your log"
// worker (web/page/real/log-worker.js) and by the command line
// (web/cli/bag-read.mjs: `bag-info`, `run-log BAG`, `merge-maps BAG`).
//
// A bag is one file (ROS 1 `.bag`, `.mcap`, rosbag2 `.db3`) or a rosbag2
// folder (its `metadata.yaml`, then its data files). The caller reads each
// file in pieces — node from disk, the page's worker from a `File` in
// slices — and pushes them in order: the bag is never held whole. Then
// `finish()` says what the bag holds (as `bag-info --json`), and
// `replay(picks)` makes a web/log-replay.js `LogReplay` of the scans picked
// (`{scan_topic, odom_topic, odom_none, truth_topic, truth_none}`, each
// optional; `odom_topic: 'tf'` takes the moving transform of /tf).
//
// As web/lab.js does for `Lab`, this module parses every JSON text the
// binding returns once, here. Errors are thrown as `Error`s whose message
// names the file, the record and the topic. It imports nothing: the caller
// hands it the loaded wasm-bindgen module, and the `LogReplay` class to wrap
// a replay in.

/** Which container a file is from its first bytes: 'ros1', 'mcap', 'sqlite' or '' (not a bag). */
export function bagKind(wasm, firstBytes) {
  return wasm.bagKind(firstBytes);
}

export class BagFile {
  /** A bag called `name` (a file's or a folder's name) on the loaded wasm-bindgen module `wasm`. */
  static open(wasm, name) {
    return new BagFile(new wasm.BagFile(name));
  }

  /** Wraps a raw wasm-bindgen `BagFile` (kept as `this.raw`). */
  constructor(raw) {
    this.raw = raw;
  }

  /** Frees the bag held in wasm memory. */
  free() {
    this.raw.free();
  }

  // --- Reading ----------------------------------------------------------------------

  /** A rosbag2 folder's `metadata.yaml` text, before its data files. */
  setMetadata(yamlText) {
    this.raw.setMetadata(yamlText);
  }

  /** The data files the metadata lists, in order. */
  metadataFiles() {
    return JSON.parse(this.raw.metadataFilesJson());
  }

  /** Starts the next file of the bag (`name` for messages; a `-wal` file before its `.db3`). */
  beginFile(name) {
    this.raw.beginFile(name);
  }

  /** The current file's next bytes (Uint8Array), in order. */
  push(bytes) {
    this.raw.push(bytes);
  }

  /** Ends the current file. */
  endFile() {
    this.raw.endFile();
  }

  /** The bag has been read: its info (as `bag-info --json`). */
  finish() {
    return JSON.parse(this.raw.finish());
  }

  /** The info again. */
  info() {
    return JSON.parse(this.raw.infoJson());
  }

  // --- Using it ---------------------------------------------------------------------

  /**
   * A replay of the bag's scans, wrapped in `LogReplayClass` (the
   * web/log-replay.js class); `picks` as above. Its report's `bag.picked`
   * says what was picked and why.
   */
  replay(LogReplayClass, picks = {}) {
    return new LogReplayClass(this.raw.replay(JSON.stringify(picks)));
  }
}
