#!/usr/bin/env node
// The lab's command line: the same wasm build as the page, run headless in node.
//
//   node web/cli.mjs run SCENARIO.json [--seed N] [--duration S] [--method auto|thesis|map-only] [--json]
//                                     [--workers N]
//   node web/cli.mjs help        (every command)
//
// Each command lives in a module of web/cli/ that exports `commands`
// ({name: async (argv, wasm) => exit status}, `argv` the words after the
// command's name, `wasm` the loaded wasm-bindgen module) and `usage` (its
// lines of the help text). Commands that run a scenario open it with
// web/cli/args.mjs (a web/lab.js Lab) and run it with web/cli/run-loop.mjs.
// Progress goes to stderr; with --json the result is the only thing on stdout.
// Exit status: 0 when the command completed, 2 on bad input (message on
// stderr), 1 on an internal error (a bug: please report it).
import { loadWasm } from './cli/wasm.mjs';
import { UsageError, parseArgs } from './cli/args.mjs';
import * as run from './cli/run.mjs';
import * as camera from './cli/camera.mjs';
import * as surf from './cli/surf.mjs';
import * as slam from './cli/slam.mjs';
import * as merge from './cli/merge.mjs';
import * as savedMaps from './cli/merge-maps.mjs';
import * as runLog from './cli/run-log.mjs';
import * as bagInfo from './cli/bag-info.mjs';

export { UsageError, parseArgs };

/**
 * The command modules, in the order of the help text. A new command: a
 * module in web/cli/ exporting `commands` and `usage`, imported above and
 * listed here. (Imported statically, so a broken import fails loudly.)
 */
const MODULES = [
  run,
  camera,
  surf,
  slam,
  merge,
  savedMaps,
  runLog,
  bagInfo,
];

const commands = {};
for (const m of MODULES) {
  for (const name of Object.keys(m.commands)) {
    if (name in commands) throw new Error(`two command modules define '${name}'`);
  }
  Object.assign(commands, m.commands);
}
const usages = MODULES.map((m) => m.usage).filter(Boolean);

async function main() {
  const [cmd, ...rest] = process.argv.slice(2);
  if (!cmd || cmd === '--help' || cmd === '-h' || cmd === 'help') {
    console.error(usages.join('\n'));
    return cmd ? 0 : 2;
  }
  const f = commands[cmd];
  if (!f) {
    console.error(`unknown command '${cmd}'\n${usages.join('\n')}`);
    return 2;
  }
  const wasm = await loadWasm();
  return await f(rest, wasm);
}

main().then(
  (code) => { process.exitCode = code ?? 0; },
  (e) => {
    if (e instanceof UsageError) {
      console.error(`error: ${e.message}`);
      process.exitCode = 2;
    } else {
      console.error(`internal error: ${e.stack ?? e}`);
      process.exitCode = 1;
    }
  },
);
