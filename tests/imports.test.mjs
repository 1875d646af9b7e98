// The JavaScript's import graph (web/**/*.js, web/**/*.mjs): no circles, no
// import of a file that is not there, and the layers ARCHITECTURE.md draws
// ("The page"): web/app.js composes web/page/; web/cli.mjs composes
// web/cli/; both stand on the facades over the wasm build (web/lab.js,
// web/saved-maps.js, web/log-replay.js, web/images.js), which import
// nothing; the page and the command line never import each other, and
// reach the wasm classes and functions that answer in JSON text only
// through those facades. Also the sizes the page keeps to: the composition
// root at most 300 lines, no module over 600.
//
// Static `import … from` / `export … from` lines are read as text (the
// wasm build in web/pkg/ is generated and left out; dynamic imports of it
// are not edges).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, readFileSync, readdirSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const web = path.join(root, 'web');

/** Every .js / .mjs file under web/, but the generated wasm builds. */
function sources(dir = web) {
  const out = [];
  for (const e of readdirSync(dir, { withFileTypes: true })) {
    const p = path.join(dir, e.name);
    if (e.isDirectory()) {
      if (!/^pkg/.test(e.name)) out.push(...sources(p));
    } else if (/\.m?js$/.test(e.name)) {
      out.push(p);
    }
  }
  return out.sort();
}

/** The relative specifiers a module imports statically. */
export function importsOf(text) {
  const specs = [];
  const re = /^\s*(?:import|export)\b[^;'"]*?(?:\bfrom\s*)?['"]([^'"]+)['"]/gm;
  for (const m of text.matchAll(re)) if (m[1].startsWith('.')) specs.push(m[1]);
  return specs;
}

/** file → the files it imports (absolute paths); pkg/ imports are left out. */
function graph() {
  const g = new Map();
  for (const f of sources()) {
    const deps = importsOf(readFileSync(f, 'utf8'))
      .map((s) => path.resolve(path.dirname(f), s))
      .filter((p) => !p.split(path.sep).some((part) => /^pkg/.test(part)));
    g.set(f, deps);
  }
  return g;
}

/** A circle in `g` as a list of files, or null. */
function findCycle(g) {
  const state = new Map(); // file → 1 (on the path) | 2 (done)
  const stack = [];
  const visit = (f) => {
    state.set(f, 1);
    stack.push(f);
    for (const d of g.get(f) ?? []) {
      if (state.get(d) === 1) return [...stack.slice(stack.indexOf(d)), d];
      if (!state.has(d)) {
        const c = visit(d);
        if (c) return c;
      }
    }
    stack.pop();
    state.set(f, 2);
    return null;
  };
  for (const f of g.keys()) {
    if (!state.has(f)) {
      const c = visit(f);
      if (c) return c;
    }
  }
  return null;
}

const rel = (p) => path.relative(root, p);

test('the import parser reads the forms the sources use', () => {
  const text = [
    "import init, * as wasm from './pkg/slamlab.js';",
    "import {\n  a,\n  b,\n} from './page/a.js';",
    "export { x } from \"../lab.js\";",
    "import './side-effect.js';",
    "import { readFile } from 'node:fs/promises';",
    "// import { no } from './comment-mid-line.js' is not at a line start: see below",
    "const s = 'import x from \"./not-an-import.js\"';",
  ].join('\n');
  assert.deepEqual(importsOf(text), ['./pkg/slamlab.js', './page/a.js', '../lab.js', './side-effect.js']);
});

test('the circle finder finds a circle and accepts a tree', () => {
  const tree = new Map([['a', ['b', 'c']], ['b', ['c']], ['c', []]]);
  assert.equal(findCycle(tree), null);
  const circle = new Map([['a', ['b']], ['b', ['c']], ['c', ['a']]]);
  assert.deepEqual(findCycle(circle), ['a', 'b', 'c', 'a']);
});

test('every import names a file that is there', () => {
  for (const [f, deps] of graph()) {
    for (const d of deps) assert.ok(existsSync(d), `${rel(f)} imports ${rel(d)}, which is missing`);
  }
});

test('the import graph of web/ has no circle', () => {
  const g = graph();
  assert.ok(g.size > 20, `found ${g.size} modules`);
  const c = findCycle(g);
  assert.equal(c, null, c && `import circle: ${c.map(rel).join(' -> ')}`);
});

/** The facades over the wasm build: each parses the JSON its binding returns, and imports nothing. */
const FACADES = ['lab.js', 'saved-maps.js', 'log-replay.js', 'bag-file.js', 'images.js'].map((f) => path.join(web, f));

/**
 * Raw wasm-bindgen names that answer in JSON text and have a facade: the
 * saved-maps merge, the log replay, ROS bags and SURF on image files. (The raw `Lab`
 * stays open to worker threads, which take only bytes from it.)
 */
const WRAPPED = /\bwasm\.(MapMerge|LogReplay|BagFile|bagKind|mapImagePath|mapMaxCells|surf_features(_rgba)?|surf_match)\b/;

test('the layers: the facades import nothing; page and command line stay apart', () => {
  const g = graph();
  for (const f of FACADES) assert.deepEqual(g.get(f), [], `${rel(f)} imports ${(g.get(f) ?? []).map(rel)}`);
  const inDir = (p, d) => p.startsWith(path.join(web, d) + path.sep);
  for (const [f, deps] of g) {
    for (const d of deps) {
      if (inDir(f, 'page')) {
        assert.ok(!inDir(d, 'cli') && !/app\.js$|cli\.mjs$/.test(d), `${rel(f)} imports ${rel(d)}`);
      }
      if (inDir(f, 'cli')) {
        assert.ok(!inDir(d, 'page') && !/app\.js$|cli\.mjs$/.test(d), `${rel(f)} imports ${rel(d)}`);
      }
    }
  }
});

test('the page: a small composition root over modules of at most 600 lines', () => {
  const lines = (p) => readFileSync(p, 'utf8').split('\n').length - 1;
  assert.ok(lines(path.join(web, 'app.js')) <= 300, `web/app.js has ${lines(path.join(web, 'app.js'))} lines`);
  for (const f of sources().filter((p) => p.startsWith(path.join(web, 'page') + path.sep))) {
    assert.ok(lines(f) <= 600, `${rel(f)} has ${lines(f)} lines`);
  }
});

test('the wasm classes that answer in JSON are reached only through their facades', () => {
  assert.ok(WRAPPED.test('const m = new wasm.MapMerge();') && WRAPPED.test('wasm.surf_features(bytes)'));
  assert.ok(!WRAPPED.test('new wasm.Lab(text)') && !WRAPPED.test('maps.mapImagePath'));
  const raw = [];
  for (const f of sources().filter((p) => !FACADES.includes(p))) {
    for (const [k, line] of readFileSync(f, 'utf8').split('\n').entries()) {
      if (WRAPPED.test(line)) raw.push(`${rel(f)}:${k + 1}: ${line.trim()}`);
    }
  }
  assert.deepEqual(raw, []);
});
