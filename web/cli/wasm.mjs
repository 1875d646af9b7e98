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

/** Where the wasm build is: web/pkg, or $SLAMLAB_PKG. */
export function pkgDir() {
  return process.env.SLAMLAB_PKG
    ? path.resolve(process.env.SLAMLAB_PKG)
    : path.join(here, '..', 'pkg');
}

// The compiled module, kept so worker threads can instantiate it without
// compiling it again (a WebAssembly.Module can be posted to a worker).
let compiled = null;

/** The WebAssembly.Module loadWasm() compiled (null before). */
export function compiledModule() {
  return compiled;
}

export async function loadWasm() {
  const dir = pkgDir();
  const js = path.join(dir, 'slamlab.js');
  try {
    await access(js);
  } catch {
    throw new Error(`wasm build not found at ${dir}: run ./build.sh build first`);
  }
  const mod = await import(pathToFileURL(js).href);
  const bytes = await readFile(path.join(dir, 'slamlab_bg.wasm'));
  compiled = new WebAssembly.Module(bytes);
  mod.initSync({ module: compiled });
  return mod;
}
