// What pausing a big run costs the page (issue 22): the panels redraw every
// robot's final state when a run pauses or ends, which for sixteen robots
// in a 60 x 60 m maze was one long task of half a second.
//
// Usage: node tests/bench/page_pause.mjs SCENARIO.json [SECONDS]
// Imports the scenario, runs it at 50x for SECONDS (default 12) of wall
// time, presses Pause and prints one JSON line: the simulated time, the
// click's round trip and every long task (ms) in the 2 s after the click.
import path from 'node:path';
import { readFile } from 'node:fs/promises';
import { chromium } from 'playwright-core';
import { CHROMIUM_FLAGS, serveRoot, waitReady } from '../support/browser.mjs';
import { importAtSpeed } from './page_bench.mjs';
const file = process.argv[2];
const body = await readFile(file);
const scenario = JSON.parse(body);
const { server, url } = await serveRoot();
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: CHROMIUM_FLAGS });
try {
  const page = await (await browser.newContext({ viewport: { width: 1366, height: 768 } })).newPage();
  await page.goto(url);
  await waitReady(page);
  await importAtSpeed(page, { name: path.basename(file), body, scenario }, 50);
  await page.click('#run');
  await page.waitForTimeout(Number(process.argv[3] ?? 12) * 1000);
  await page.evaluate(() => {
    window.__long = [];
    new PerformanceObserver((l) => { for (const e of l.getEntries()) window.__long.push(Math.round(e.duration)); }).observe({ type: 'longtask' });
  });
  const t0 = Date.now();
  await page.getByRole('button', { name: 'Pause', exact: true }).click();
  const click = Date.now() - t0;
  await page.waitForTimeout(2000);
  console.log(JSON.stringify({ t: await page.evaluate(() => window.slamlab.state().time_s), click_ms: click, long: await page.evaluate(() => window.__long) }));
} finally {
  await browser.close();
  server.close();
}
