// Shared by every command module: argument parsing, the input-error type,
// and opening a scenario file into a Lab (the facade of web/lab.js) with
// the common --seed/--duration.
// (Command modules import from here, not from ../cli.mjs, which imports them.)
import { readFile } from 'node:fs/promises';
import { Lab } from '../lab.js';

/** An input error: exit status 2 with this message. */
export class UsageError extends Error {}

/**
 * Splits argv into positionals and --options. `spec` maps option names to
 * 'flag' (no value) or 'value'. Unknown options are input errors.
 */
export function parseArgs(argv, spec) {
  const positional = [];
  const options = {};
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a.startsWith('--')) {
      const [name, inline] = a.slice(2).split(/=(.*)/s, 2);
      if (!(name in spec)) throw new UsageError(`unknown option --${name}`);
      if (spec[name] === 'flag') {
        options[name] = true;
      } else {
        const v = inline ?? argv[++i];
        if (v === undefined) throw new UsageError(`--${name} needs a value`);
        options[name] = v;
      }
    } else {
      positional.push(a);
    }
  }
  return { positional, options };
}

/** Calls into wasm; an Error thrown there is a problem with the input. */
export function wasmCall(f) {
  try {
    return f();
  } catch (e) {
    if (e instanceof WebAssembly.RuntimeError) throw e; // a trap is a bug
    throw new UsageError(e.message ?? String(e));
  }
}

/**
 * Reads a scenario file into a new Lab (web/lab.js) on the wasm-bindgen
 * module `wasm`, applies `options.seed` and
 * `options.duration` (strings from the command line) and refuses badly
 * placed robots, each with a message naming the problem.
 */
export async function openScenario(file, options, wasm) {
  let text;
  try {
    text = await readFile(file, 'utf8');
  } catch (e) {
    throw new UsageError(`cannot read scenario '${file}': ${e.code ?? e.message}`);
  }
  const lab = wasmCall(() => Lab.open(wasm, text));
  if (options.seed !== undefined) {
    if (!/^\d+$/.test(options.seed) || !Number.isSafeInteger(Number(options.seed))) {
      throw new UsageError(`--seed: '${options.seed}' is not a whole number from 0 to 2^53`);
    }
    wasmCall(() => lab.setSeed(Number(options.seed)));
  }
  if (options.duration !== undefined) {
    const d = Number(options.duration);
    if (options.duration.trim() === '' || !Number.isFinite(d)) {
      throw new UsageError(`--duration: '${options.duration}' is not a number of seconds`);
    }
    wasmCall(() => lab.setDuration(d));
  }
  const problems = lab.problems();
  if (problems.length > 0) throw new UsageError(problems[0].text);
  return lab;
}
