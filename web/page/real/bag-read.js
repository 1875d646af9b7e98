// ROS bags read in the log worker (log-worker.js), in pieces (issue 53).
//
// What the user picks or drops into "Your log" is a heap of files: CARMEN
// logs, ROS bags (a ROS 1 `.bag`, an `.mcap`, a rosbag2 `.db3`), and
// rosbag2 folders, whose files come loose (picked together) or with their
// folder's path (a folder dropped as a folder). `sortFiles` tells them
// apart as `bag-info` does (web/cli/bag-read.mjs):
//   - a `.yaml` is a rosbag2 folder's `metadata.yaml`: the data files it
//     lists (by name, from the same folder) and their `-wal` files are one
//     bag; listed files that were not given are noted, the others read;
//   - a `.db3-wal` goes with its `.db3` (the write-ahead log first);
//   - any other file is a bag when its first 16 bytes say so (`bagKind`:
//     ROS 1, MCAP or SQLite, whatever it is called) or its name ends in
//     `.bag`, `.mcap` or `.db3` (then the bag reader says what it is not),
//     else a CARMEN log.
// `readBag` then pushes a bag's files into its `BagFile` (web/bag-file.js)
// 8 MiB at a time, each piece read from the `File` with
// `file.slice(a, b).arrayBuffer()`: the bag is never held whole, and the
// page never holds it at all. Every problem is a message naming the file.

import { BagFile, bagKind } from '../../bag-file.js';

/** Bytes read and pushed at a time. */
export const PIECE = 8 << 20;
/** A metadata.yaml larger than this is not one. */
const MAX_METADATA = 1 << 20;
/** Names a bag goes by. */
const BAG_NAME = /\.(bag|mcap|db3)$/i;

const message = (e) => (e instanceof Error ? e.message : String(e));
const baseName = (p) => String(p).split(/[\\/]/).pop();
const dirName = (p) => String(p).split(/[\\/]/).slice(0, -1).join('/');

/** The data files a rosbag2 metadata.yaml lists (their names), read by a BagFile called `name`. */
function metadataFiles(wasm, name, text) {
  const bag = BagFile.open(wasm, name);
  try {
    bag.setMetadata(text);
    return bag.metadataFiles().map(baseName);
  } finally {
    bag.free();
  }
}

/**
 * Sorts `entries` ([{file: File, path}], `path` the file's name, or its
 * path within a dropped folder) on the loaded wasm-bindgen module `wasm`.
 * Returns `{items, errors: [text]}`, the items in the order given (the
 * rosbag2 folders first): a CARMEN log `{log: File}` or a bag `{name, bag,
 * files: [{name, file}], missing: [names]}`, whose `bag` is a new BagFile
 * (its metadata set) for `readBag`, to be freed by the caller.
 */
export async function sortFiles(wasm, entries) {
  const errors = [];
  const items = [];
  const taken = new Set();
  const inDir = (dir) => entries.filter((e) => !taken.has(e) && dirName(e.path) === dir);

  // A rosbag2 folder: its metadata.yaml and the files it lists.
  for (const meta of entries.filter((e) => /\.ya?ml$/i.test(e.path))) {
    taken.add(meta);
    const dir = dirName(meta.path);
    try {
      if (meta.file.size > MAX_METADATA) throw new Error(`${meta.path}: ${meta.file.size} bytes is too large for a rosbag2 metadata.yaml`);
      const text = await meta.file.text();
      if (!/rosbag2_bagfile_information/.test(text)) {
        throw new Error(`${meta.path}: not a rosbag2 metadata.yaml (it has no rosbag2_bagfile_information); "Your log" opens CARMEN logs and ROS bags`);
      }
      const here = inDir(dir);
      const folder = baseName(dir);
      const listed = metadataFiles(wasm, folder || 'rosbag2', text);
      const data = listed.length ? listed : here.map((e) => baseName(e.path)).filter((n) => /\.(db3|mcap)(\.zstd)?$/i.test(n)).sort();
      const files = [];
      const missing = [];
      for (const n of data) {
        const found = here.find((e) => baseName(e.path) === n);
        if (!found) {
          missing.push(n);
          continue;
        }
        const wal = here.find((e) => baseName(e.path) === `${n}-wal`);
        for (const e of wal ? [wal, found] : [found]) {
          taken.add(e);
          files.push({ name: baseName(e.path), file: e.file });
        }
      }
      if (!files.length) {
        throw new Error(`${meta.path}: it lists ${data.join(', ') || 'no data file'}; pick or drop the folder's data files together with it`);
      }
      // Picked loose, the folder has no name: the bag is called after its first file.
      const name = folder || data[0].replace(/\.(db3|mcap)(\.zstd)?$/i, '');
      const bag = BagFile.open(wasm, name);
      bag.setMetadata(text);
      items.push({ name, bag, files, missing });
    } catch (e) {
      errors.push(message(e));
    }
  }

  // A write-ahead log goes with its database.
  const rest = entries.filter((e) => !taken.has(e));
  const wals = new Map(rest.filter((e) => /-wal$/i.test(e.path)).map((e) => [e.path.replace(/-wal$/i, ''), e]));
  for (const [db, wal] of wals) {
    if (!rest.some((e) => e.path === db)) errors.push(`${wal.path}: a write-ahead log without its database ${baseName(db)}; pick or drop them together`);
  }

  for (const e of rest) {
    if (/-wal$/i.test(e.path)) continue; // read with its database, or named above
    try {
      const head = new Uint8Array(await e.file.slice(0, 16).arrayBuffer());
      // A file named as a bag that is none is refused by the bag reader, with what it starts with.
      if (!bagKind(wasm, head) && !BAG_NAME.test(e.path)) {
        items.push({ log: e.file });
        continue;
      }
      const wal = wals.get(e.path);
      const files = (wal ? [wal, e] : [e]).map((x) => ({ name: baseName(x.path), file: x.file }));
      items.push({ name: baseName(e.path), bag: BagFile.open(wasm, baseName(e.path)), files, missing: [] });
    } catch (err) {
      errors.push(`${e.path}: ${message(err)}`);
    }
  }
  return { items, errors };
}

/**
 * Reads `files` ([{name, file}], in order) into `bag` (a BagFile), one
 * piece at a time; `progress(readBytes, totalBytes)` after each. Returns
 * the bag's info (`BagFile.finish`). Throws the reader's message, which
 * names the file, the record and the topic.
 */
export async function readBag(bag, files, progress = () => {}) {
  const total = files.reduce((s, f) => s + f.file.size, 0);
  let read = 0;
  progress(read, total);
  for (const { name, file } of files) {
    bag.beginFile(name);
    for (let at = 0; at < file.size; at += PIECE) {
      const piece = new Uint8Array(await file.slice(at, Math.min(file.size, at + PIECE)).arrayBuffer());
      bag.push(piece);
      read += piece.length;
      progress(read, total);
    }
    bag.endFile();
  }
  return bag.finish();
}
