// What the browser's own work in a frame is (issue 22): a `devtools.timeline`
// trace over the DevTools protocol of `--seconds` of wall time, taken after
// `--warmup` seconds of running, in headless Chromium at 1366 × 768. The CPU
// profile (page_profile.mjs) shows that work only as `(program)`; the trace
// names it (Paint, Layout, UpdateLayerTree, Layerize, Commit, GC ...).
//
// Usage: node tests/bench/page_trace.mjs SCENARIO.json [--speed 20]
//        [--seconds 5] [--warmup 2] [--top 25]
// Prints the simulated clock and, for the renderer's main thread, the total
// self time (ms) by event name (an event's time less its children's), the
// count of each, and the longest top-level tasks with their largest parts.
// Needs ./build.sh build.
import { chromium } from 'playwright-core';
import { CHROMIUM_FLAGS, serveRoot, waitReady } from '../support/browser.mjs';
import { importAtSpeed, scenarioArgs } from './page_bench.mjs';

const { file, body, scenario, opt } = await scenarioArgs(
  'node tests/bench/page_trace.mjs SCENARIO.json [--speed 20] [--seconds 5]',
);
const { server, url } = await serveRoot();
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: CHROMIUM_FLAGS });

/** Complete ('X') events of the busiest renderer thread named CrRendererMain. */
function mainThreadEvents(events) {
  const names = new Map();
  for (const e of events) {
    if (e.ph === 'M' && e.name === 'thread_name' && e.args?.name === 'CrRendererMain') names.set(`${e.pid}:${e.tid}`, true);
  }
  const byThread = new Map();
  for (const e of events) {
    const k = `${e.pid}:${e.tid}`;
    if (!names.has(k) || e.ph !== 'X' || !(e.dur > 0)) continue;
    if (!byThread.has(k)) byThread.set(k, []);
    byThread.get(k).push(e);
  }
  return [...byThread.values()].sort((a, b) => b.length - a.length)[0] ?? [];
}

/** Self time by name: each event's duration less its direct children's. */
function selfTimes(evs) {
  evs.sort((a, b) => a.ts - b.ts || b.dur - a.dur);
  const self = new Map();
  const count = new Map();
  const stack = [];
  const tops = [];
  for (const e of evs) {
    while (stack.length && stack[stack.length - 1].ts + stack[stack.length - 1].dur <= e.ts) stack.pop();
    const parent = stack[stack.length - 1];
    if (parent) parent.kids = (parent.kids ?? 0) + e.dur;
    else tops.push(e);
    if (parent) (parent.parts ??= new Map()).set(e.name, (parent.parts.get(e.name) ?? 0) + e.dur);
    stack.push(e);
  }
  for (const e of evs) {
    self.set(e.name, (self.get(e.name) ?? 0) + (e.dur - (e.kids ?? 0)) / 1000);
    count.set(e.name, (count.get(e.name) ?? 0) + 1);
  }
  return { self, count, tops };
}

try {
  const ctx = await browser.newContext({ viewport: { width: 1366, height: 768 } });
  const page = await ctx.newPage();
  await page.goto(url);
  await waitReady(page);
  await importAtSpeed(page, { name: 'scenario.json', body, scenario }, opt('speed', 20));
  const cdp = await ctx.newCDPSession(page);
  await page.click('#run');
  await page.waitForTimeout(opt('warmup', 2) * 1000);
  const events = [];
  cdp.on('Tracing.dataCollected', (d) => events.push(...d.value));
  const done = new Promise((resolve) => cdp.once('Tracing.tracingComplete', resolve));
  const t0 = await page.evaluate(() => window.slamlab.lab.timeS());
  await cdp.send('Tracing.start', {
    categories: 'devtools.timeline,disabled-by-default-devtools.timeline,v8,blink.user_timing,toplevel',
    transferMode: 'ReportEvents',
  });
  await page.waitForTimeout(opt('seconds', 5) * 1000);
  await cdp.send('Tracing.end');
  await done;
  const t1 = await page.evaluate(() => window.slamlab.lab.timeS());
  const evs = mainThreadEvents(events);
  const { self, count, tops } = selfTimes(evs);
  const busy = tops.reduce((a, e) => a + e.dur, 0) / 1000;
  console.log(`main thread busy ${busy.toFixed(0)} ms in ${opt('seconds', 5)} s, simulated ${(t1 - t0).toFixed(1)} s`);
  console.log('-- self time by event (ms, count)');
  const top = opt('top', 25);
  for (const [k, v] of [...self].sort((a, b) => b[1] - a[1]).slice(0, top)) {
    console.log(v.toFixed(0).padStart(7), String(count.get(k)).padStart(6), k);
  }
  console.log('-- longest tasks (ms) and their largest direct parts');
  for (const e of tops.sort((a, b) => b.dur - a.dur).slice(0, 8)) {
    const parts = [...(e.parts ?? [])].sort((a, b) => b[1] - a[1]).slice(0, 4).map(([k, v]) => `${k} ${(v / 1000).toFixed(0)}`);
    console.log((e.dur / 1000).toFixed(0).padStart(7), e.name, '|', parts.join(', '));
  }
} finally {
  await browser.close();
  server.close();
}
