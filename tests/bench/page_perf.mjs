// How the page holds up on a big scenario (issue 22): frame rate, long
// tasks and simulated-time rate while running in headless Chromium.
//
// Usage: node tests/bench/page_perf.mjs SCENARIO.json [--speed 50] [--seconds 10]
//        [--width 1366 --height 768] [--shot FILE.png] [--parts] [--scroll SELECTOR]
// Imports the scenario through the page's Import button, sets the speed
// slider, presses Run, and for `--seconds` of wall time counts animation
// frames, records every long task (PerformanceObserver 'longtask') and reads
// the simulated clock. Prints one JSON line:
// {walls, robots, fps, frames, longtasks, longest_ms, sim_rate}, sim_rate =
// simulated seconds per wall second (until the run finished, if it did:
// finished_after_s), over100 = long tasks over 100 ms. `--shot`
// saves a screenshot of the page at the end of the run. `--parts` adds where
// the page's frames spent their time (web/page/frame-times.js: totals in ms
// by part, and the slowest frames with their parts). Needs ./build.sh build
// and Chromium. `--scroll` scrolls an element into view before the run (e.g.
// `--scroll '#maps'`: the Maps panel on screen instead of the robot cards).
// `--slow-steps` lists every Lab step over 50 ms with its simulated time and
// the JS heap before and after it (a heap that shrinks inside a step is a
// garbage collection that ran there).
import path from 'node:path';
import { chromium } from 'playwright-core';
import { CHROMIUM_FLAGS, serveRoot, waitReady } from '../support/browser.mjs';
import { importAtSpeed, scenarioArgs } from './page_bench.mjs';

const { args, file, body, scenario, opt } = await scenarioArgs(
  'node tests/bench/page_perf.mjs SCENARIO.json [--speed 50] [--seconds 10]',
);
const speed = opt('speed', 50);
const seconds = opt('seconds', 10);
const viewport = { width: opt('width', 1366), height: opt('height', 768) };

const { server, url } = await serveRoot();
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: CHROMIUM_FLAGS });
try {
  const page = await (await browser.newContext({ viewport })).newPage();
  page.on('pageerror', (e) => console.error(`page error: ${e.message}`));
  await page.goto(url);
  await waitReady(page);
  await importAtSpeed(page, { name: path.basename(file), body, scenario }, speed);
  await page.evaluate(() => {
    window.__perf = { frames: 0, long: [] };
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) window.__perf.long.push([e.duration, e.startTime]);
    }).observe({ type: 'longtask' });
    const tick = () => {
      window.__perf.frames++;
      if (window.__perf.finishedMs === undefined && window.slamlab.state().finished) window.__perf.finishedMs = performance.now();
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  });
  if (args.includes('--slow-steps')) {
    await page.evaluate(() => {
      const lab = window.slamlab.lab;
      const step = lab.step.bind(lab);
      window.__perf.slow = [];
      const heap = () => Math.round(performance.memory.usedJSHeapSize / 2 ** 20);
      lab.step = (n) => {
        const [h0, t0] = [heap(), performance.now()];
        const k = step(n);
        const ms = performance.now() - t0;
        if (ms > 50) window.__perf.slow.push({ ms: Math.round(ms), t: lab.timeS(), heap_mb: [h0, heap()] });
        return k;
      };
    });
  }
  const t0 = await page.evaluate(() => window.slamlab.state().time_s ?? window.slamlab.lab.timeS());
  const scroll = args.indexOf('--scroll');
  if (scroll >= 0) await page.evaluate((sel) => document.querySelector(sel).scrollIntoView({ block: 'start' }), args[scroll + 1]);
  await page.click('#run');
  const w0 = Date.now();
  await page.evaluate(() => {
    window.__perf.frames = 0;
    window.__perf.startMs = performance.now();
    window.slamlab.frameTimes?.(true);
  });
  await page.waitForTimeout(seconds * 1000);
  const out = await page.evaluate(() => ({
    frames: window.__perf.frames,
    long: window.__perf.long.map(([d]) => d),
    // Long tasks over 100 ms that began after the run finished (the panels catching up).
    over100_after_finish: window.__perf.long.filter(([d, t]) => d > 100 && window.__perf.finishedMs !== undefined && t >= window.__perf.finishedMs - 1).length,
    t: window.slamlab.lab.timeS(),
    parts: window.slamlab.frameTimes?.(),
    slow: window.__perf.slow,
    finished_s: window.__perf.finishedMs === undefined ? null : (window.__perf.finishedMs - window.__perf.startMs) / 1000,
  }));
  const wall = (Date.now() - w0) / 1000;
  const shot = args.indexOf('--shot');
  if (shot >= 0) await page.screenshot({ path: args[shot + 1] });
  console.log(
    JSON.stringify({
      walls: scenario.walls.length,
      robots: scenario.robots.length,
      speed,
      fps: +(out.frames / wall).toFixed(1),
      frames: out.frames,
      longtasks: out.long.length,
      longest_ms: Math.round(Math.max(0, ...out.long)),
      over100: out.long.filter((d) => d > 100).length,
      sim_rate: +((out.t - t0) / (out.finished_s ?? wall)).toFixed(1),
      finished_after_s: out.finished_s === null ? null : +out.finished_s.toFixed(1),
      over100_after_finish: out.over100_after_finish,
      ...(args.includes('--parts') ? { parts: out.parts } : {}),
      ...(out.slow ? { slow_steps: out.slow } : {}),
    }),
  );
} finally {
  await browser.close();
  server.close();
}
