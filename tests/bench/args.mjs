// The page benchmarks' command line: a scenario file first, then
// `--name value` options with numeric values.
import { readFile } from 'node:fs/promises';

/**
 * Parses `process.argv`: exits with `usage` (code 2) when no scenario is
 * given. Returns the scenario's path, its text and parsed JSON, and
 * `opt(name, default)` for a numeric option.
 */
export async function scenarioArgs(usage) {
  const args = process.argv.slice(2);
  const opt = (name, dflt) => {
    const i = args.indexOf(`--${name}`);
    return i >= 0 ? Number(args[i + 1]) : dflt;
  };
  const file = args[0];
  if (!file) {
    console.error(`usage: ${usage}`);
    process.exit(2);
  }
  const body = await readFile(file);
  return { args, file, body, scenario: JSON.parse(body), opt };
}
