// The saved-maps merge as JavaScript sees it: one facade over the raw
// wasm-bindgen `MapMerge` (crate/src/bindings/maps.rs), used by the page's
// "Your maps" worker (web/page/real/merge-worker.js), by "Your log"'s merge
// of its robots' maps (web/page/real/log-merge.js) and by the `merge-maps`
// command (web/cli/merge-maps.mjs).
//
// Saved maps are ROS map_server maps: a YAML (resolution, origin, the image
// it names) and a PGM or PNG image. The caller reads the files (node from
// disk, the page from a file picker) and hands text and bytes over; the
// merge finds each map's frame in the first map's frame, or refuses with a
// reason (crate/src/merge/saved/mod.rs; the report's format is
// docs/interfaces.md, "merge-maps").
//
// As web/lab.js does for `Lab`, this module parses every JSON text the
// binding returns once, here, and hands back objects: `maps.report()`
// rather than `JSON.parse(merger.reportJson())`. Bytes (map pixels, the
// merged map's PGM and PNG) and the YAML text pass straight through. The
// binding's errors (a bad file, a pair that is not one) are thrown
// unchanged, as `Error`s whose message names the file and the field; a
// `WebAssembly.RuntimeError` is a bug.
//
// This module imports nothing: the caller hands it the loaded wasm-bindgen
// module.

/** The most maps one merge takes (the binding refuses a seventeenth). */
export const MAX_SAVED_MAPS = 16;

export class SavedMaps {
  /** An empty set of saved maps on the loaded wasm-bindgen module `wasm`. */
  static open(wasm) {
    return new SavedMaps(new wasm.MapMerge());
  }

  /** Wraps a raw wasm-bindgen `MapMerge` (kept as `this.raw` for tests and the console). */
  constructor(raw) {
    this.raw = raw;
  }

  /** Frees the maps held in wasm memory; the object is unusable afterwards. */
  free() {
    this.raw.free();
  }

  // --- The maps -------------------------------------------------------------------

  /**
   * Reads one map: `name` the YAML's path as given, `yamlText` its text,
   * `imageName` the image's path (for messages), `image` its bytes
   * (Uint8Array). Returns the map's index; throws naming the file and the
   * field on a bad map, and at the seventeenth. A new map drops the last
   * merge.
   */
  addMap(name, yamlText, imageName, image) {
    return this.raw.addMap(name, yamlText, imageName, image);
  }

  /**
   * Reads a map in place of map `index` (a file opened again under the
   * same name, an image read at another resolution): same arguments as
   * `addMap`; the other maps keep their indices; drops the last merge.
   */
  replaceMap(index, name, yamlText, imageName, image) {
    this.raw.replaceMap(index, name, yamlText, imageName, image);
  }

  /**
   * Adds the last map of a bag's `nav_msgs/OccupancyGrid` topic (`bag` a
   * finished web/bag-file.js `BagFile`; `topic` left out: `/map`, else the
   * bag's only map topic), named as the bag. Returns its index.
   */
  addBagMap(bag, topic = '') {
    return this.raw.addBagMap(bag.raw, topic);
  }

  /** Map `index`'s `{name, width, height, resolution, origin: [x, y, yaw]}` (cells, metres, radians). */
  mapInfo(index) {
    return JSON.parse(this.raw.mapInfoJson(index));
  }

  /** Map `index`'s cells as grey values (PGM shades), top row first: a Uint8Array of width × height. */
  mapPixels(index) {
    return this.raw.mapPixels(index);
  }

  // --- The merge ------------------------------------------------------------------

  /** Merges the maps (two or more); returns the report's `{maps, merge}` as an object. */
  merge() {
    return JSON.parse(this.raw.merge());
  }

  /** The same, calling `progress(line)` with a line of text after each pair. */
  mergeWithProgress(progress) {
    return JSON.parse(this.raw.mergeWithProgress(progress));
  }

  /**
   * Aligns maps `a` and `b` again from a person's rough overlay: map b's
   * frame at `pose` = [x, y, theta] (metres, radians) in map a's. The
   * result replaces that pair's verdict and the maps are joined again, so
   * `report()` and the merged map follow it. Returns the pair's result in
   * the report's `merge.pairs[]` format (with `guess`); a pair is refined in
   * the order the merge judged it, so for a > b it comes back as b, a.
   */
  refine(a, b, pose) {
    if (!Array.isArray(pose) || pose.length !== 3) {
      throw new Error(`refine: the guess must be a pose [x, y, theta], got ${JSON.stringify(pose)}`);
    }
    return JSON.parse(this.raw.refine(a, b, pose[0], pose[1], pose[2]));
  }

  /**
   * Keeps a person's placement of maps `a` and `b` (map b's frame at
   * `pose` = [x, y, theta] in map a's) as it is, not verified, after the
   * tests refused it; `report()` then says `verified: false`. Returns the
   * pair's result (as `refine` does).
   */
  keepPlacement(a, b, pose) {
    if (!Array.isArray(pose) || pose.length !== 3) {
      throw new Error(`keep placement: the pose must be [x, y, theta], got ${JSON.stringify(pose)}`);
    }
    return JSON.parse(this.raw.keepPlacement(a, b, pose[0], pose[1], pose[2]));
  }

  /** The report `merge` returned, after any `refine`. */
  report() {
    return JSON.parse(this.raw.reportJson());
  }

  // --- The merged map (the joined maps in the first map's frame) ------------------

  /** The merged map as a binary PGM (Uint8Array); throws before a merge. */
  mergedPgm() {
    return this.raw.mergedPgm();
  }

  /** The same pixels as a PNG (Uint8Array). */
  mergedPng() {
    return this.raw.mergedPng();
  }

  /** The map_server YAML text naming `image` (the PGM's file name). */
  mergedYaml(image) {
    return this.raw.mergedYaml(image);
  }

  // --- Each group's merged map (report.merge.groups[k], in its first map's frame) --

  /** Group `k`'s merged map as a binary PGM (Uint8Array); group 0 is the merged map. */
  groupPgm(k) {
    return this.raw.groupPgm(k);
  }

  /** Group `k`'s merged map as a PNG (Uint8Array). */
  groupPng(k) {
    return this.raw.groupPng(k);
  }

  /** Group `k`'s map_server YAML text naming `image`. */
  groupYaml(k, image) {
    return this.raw.groupYaml(k, image);
  }

  /**
   * Each group of `merge` (the report's `merge`) as files to download:
   * `{pgm, png, yaml, stem}` for a group of two or more maps, null for a
   * map alone. With one such group its files are `merged.*`, with several
   * `merged-group-N.*` (N counting the groups of two or more); a group
   * joined where a person placed a map adds `-not-verified` to its name and
   * says so in its YAML.
   */
  groupFiles(merge) {
    const groups = merge.groups ?? [];
    const several = groups.filter((g) => g.maps.length > 1).length > 1;
    let n = 0;
    return groups.map((g, k) => {
      if (g.maps.length < 2) return null;
      n += 1;
      const named = several ? `merged-group-${n}` : 'merged';
      const stem = g.verified === false ? `${named}-not-verified` : named;
      const f = { pgm: this.groupPgm(k), png: this.groupPng(k), yaml: this.groupYaml(k, `${stem}.pgm`), stem };
      if (g.verified === false) f.yaml = `# Joined where a person placed a map by hand: not verified by the merge's tests.\n${f.yaml}`;
      return f;
    });
  }
}

/** The `image` a map's YAML names (its path relative to the YAML's folder), so the caller knows what to read; throws on a bad YAML. */
export function mapImagePath(wasm, name, yamlText) {
  return wasm.mapImagePath(name, yamlText);
}

/** The most cells one map may hold. */
export function mapMaxCells(wasm) {
  return wasm.mapMaxCells();
}
