// The page benchmarks' shared parts: the command line (a scenario file
// first, then `--name value` numeric options) and loading the scenario.
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

/**
 * Imports the scenario into the page (through the Import button's file
 * input, as a user would), waits until its walls are in, and sets the
 * speed slider to `speed`.
 */
export async function importAtSpeed(page, { name, body, scenario }, speed) {
  await page.setInputFiles('#import-file', { name, mimeType: 'application/json', buffer: body });
  await page.waitForFunction((n) => window.slamlab.scenario().walls.length === n, scenario.walls.length, {
    timeout: 60000,
  });
  await page.evaluate((v) => {
    const s = document.getElementById('speed');
    s.value = String(v);
    s.dispatchEvent(new Event('input', { bubbles: true }));
  }, speed);
}
