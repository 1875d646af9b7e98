// Reading a ROS bag from disk in pieces into the bag facade (web/bag-file.js):
// what `bag-info`, `run-log BAG` and `merge-maps BAG` share. A bag is a file
// (`.bag`, `.mcap`, `.db3`) or a rosbag2 folder (its `metadata.yaml` and the
// data files it lists, or, without one, every `.db3` / `.mcap` in it by
// name). Each file is read 8 MiB at a time and pushed as it comes, so a bag
// is never held whole in node's memory; a `.db3-wal` file goes before its
// `.db3`. Whether a file is a bag at all is told from its name or its
// first bytes.
import { open, readFile, readdir, stat } from 'node:fs/promises';
import path from 'node:path';
import { BagFile, bagKind } from '../bag-file.js';
import { UsageError, wasmCall } from './args.mjs';

const PIECE = 8 << 20;

/** The first 16 bytes of `file` (fewer if it is shorter). */
async function head(file) {
  const fh = await open(file, 'r');
  try {
    const buf = Buffer.alloc(16);
    const { bytesRead } = await fh.read(buf, 0, 16, 0);
    return new Uint8Array(buf.buffer, buf.byteOffset, bytesRead);
  } finally {
    await fh.close();
  }
}

/**
 * True when `file` is a bag: a folder, a file named as one (`.bag`,
 * `.mcap`, `.db3`: read as a bag even when its bytes are not one, so the
 * message says what is wrong with it as a bag), or a file whose first
 * bytes say ROS 1, MCAP or SQLite.
 */
export async function isBag(wasm, file, what = 'file') {
  let s;
  try {
    s = await stat(file);
  } catch (e) {
    throw new UsageError(`cannot read ${what} '${file}': ${e.code ?? e.message}`);
  }
  if (s.isDirectory() || /\.(bag|mcap|db3)$/i.test(file)) return true;
  return bagKind(wasm, await head(file)) !== '';
}

/** Pushes `file` into `bag` piece by piece; `progress(bytes)` after each piece. */
async function pushFile(bag, file, name, progress) {
  let fh;
  try {
    fh = await open(file, 'r');
  } catch (e) {
    throw new UsageError(`cannot read '${file}': ${e.code ?? e.message}`);
  }
  try {
    wasmCall(() => bag.beginFile(name));
    const buf = Buffer.alloc(PIECE);
    for (;;) {
      const { bytesRead } = await fh.read(buf, 0, PIECE, null);
      if (bytesRead === 0) break;
      wasmCall(() => bag.push(new Uint8Array(buf.buffer, buf.byteOffset, bytesRead)));
      progress(bytesRead);
    }
    wasmCall(() => bag.endFile());
  } finally {
    await fh.close();
  }
}

/** The data files of a rosbag2 folder, in reading order (WAL files before their database). */
async function folderFiles(bag, dir) {
  let listed = [];
  try {
    const yaml = await readFile(path.join(dir, 'metadata.yaml'), 'utf8');
    wasmCall(() => bag.setMetadata(yaml));
    listed = bag.metadataFiles();
  } catch (e) {
    if (e instanceof UsageError) throw e;
    if (e.code !== 'ENOENT') throw new UsageError(`${dir}/metadata.yaml: ${e.code ?? e.message}`);
  }
  const names = await readdir(dir);
  if (listed.length === 0) listed = names.filter((n) => /\.(db3|mcap)(\.zstd)?$/i.test(n)).sort();
  if (listed.length === 0) throw new UsageError(`${dir}: no .db3 or .mcap file in the folder`);
  const out = [];
  for (const f of listed) {
    if (names.includes(`${f}-wal`)) out.push(`${f}-wal`);
    out.push(f);
  }
  return out;
}

/**
 * Reads the bag at `file` (a file or a rosbag2 folder) into a new
 * BagFile; returns `{bag, info}`. `onProgress(readBytes, totalBytes)` is
 * called after each piece.
 */
export async function readBag(wasm, file, onProgress = () => {}) {
  let s;
  try {
    s = await stat(file);
  } catch (e) {
    throw new UsageError(`cannot read '${file}': ${e.code ?? e.message}`);
  }
  const bag = BagFile.open(wasm, file);
  const files = s.isDirectory() ? await folderFiles(bag, file) : [null];
  const paths = files.map((f) => (f === null ? file : path.join(file, f)));
  let total = 0;
  for (const p of paths) total += (await stat(p)).size;
  let done = 0;
  for (const [k, p] of paths.entries()) {
    await pushFile(bag, p, files[k] === null ? file : path.join(file, files[k]), (n) => {
      done += n;
      onProgress(done, total);
    });
  }
  const info = wasmCall(() => bag.finish());
  return { bag, info };
}
