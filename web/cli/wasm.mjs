// Loads the same wasm build the page uses (web/pkg, made by `./build.sh build`)
// into node. wasm-bindgen's `--target web` output works in node when we hand
// it the module bytes ourselves instead of letting it fetch() them.
//
// SLAMLAB_PKG=web/pkg-scalar selects the scalar (no SIMD128) build that
// `./build.sh build-scalar` makes, for A/B benchmarks.
import { readFile, access } from 'node:fs/promises';
import { fileURLToPath, pathToFileURL } from 'node:url';
import path from 'node:path';

const here = path.dirname(fileURLToPath(import.meta.url));

export async function loadWasm() {
  const pkgDir = process.env.SLAMLAB_PKG
    ? path.resolve(process.env.SLAMLAB_PKG)
    : path.join(here, '..', 'pkg');
  const js = path.join(pkgDir, 'slamlab.js');
  try {
    await access(js);
  } catch {
    throw new Error(`wasm build not found at ${pkgDir}: run ./build.sh build first`);
  }
  const mod = await import(pathToFileURL(js).href);
  const bytes = await readFile(path.join(pkgDir, 'slamlab_bg.wasm'));
  mod.initSync({ module: bytes });
  return mod;
}
