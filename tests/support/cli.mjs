// What the command-line tests share: the repository root, the CLI's path,
// running it as a child process (synchronously, or as a promise so that a
// browser test can drive the page meanwhile), and a fresh temporary folder.
//
// Needs the wasm build in web/pkg (`./build.sh build`).
import { execFile, spawnSync } from 'node:child_process';
import { mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
export const CLI = path.join(ROOT, 'web', 'cli.mjs');

/** Runs `node web/cli.mjs ARGS…` in the repository root: `{code, stdout, stderr}`. */
export function runCli(...args) {
  const r = spawnSync(process.execPath, [CLI, ...args], { cwd: ROOT, encoding: 'utf8', maxBuffer: 1 << 30 });
  return { code: r.status, stdout: r.stdout, stderr: r.stderr };
}

/** The same without blocking: a promise of `{code, stdout, stderr}`. */
export function runCliAsync(...args) {
  return new Promise((resolve) => {
    execFile(process.execPath, [CLI, ...args], { cwd: ROOT, encoding: 'utf8', maxBuffer: 1 << 30 }, (error, stdout, stderr) => {
      resolve({ code: error ? (error.code ?? 1) : 0, stdout, stderr });
    });
  });
}

/** A new empty folder under the system's temporary folder, named `slamlab-NAME-…`. */
export function tempDir(name) {
  return mkdtempSync(path.join(tmpdir(), `slamlab-${name}-`));
}
