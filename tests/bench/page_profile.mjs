// Where the page's time goes while running a big scenario (issue 22): a CPU
// profile over the DevTools protocol (`Profiler`, 1 ms sampling) of
// `--seconds` of wall time, taken after `--warmup` seconds of running, in
// headless Chromium at 1366 × 768.
//
// Usage: node tests/bench/page_profile.mjs SCENARIO.json [--speed 20]
//        [--seconds 8] [--warmup 2] [--top 30]
// Prints the total sampled time, the simulated clock, and the functions with
// the most self time (JavaScript and wasm, `name file:line`), then the same
// for inclusive time of the page's own functions. Needs ./build.sh build.
import { chromium } from 'playwright-core';
import { CHROMIUM_FLAGS, serveRoot, waitReady } from '../support/browser.mjs';
import { importAtSpeed, scenarioArgs } from './page_bench.mjs';

const { file, body, scenario, opt } = await scenarioArgs(
  'node tests/bench/page_profile.mjs SCENARIO.json [--speed 20] [--seconds 8]',
);
const { server, url } = await serveRoot();
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: CHROMIUM_FLAGS });

/** `name file:line` of a profile node. */
const label = (n) => `${n.callFrame.functionName || '(anon)'} ${n.callFrame.url.split('/').pop()}:${n.callFrame.lineNumber}`;

/** Self and inclusive milliseconds by label. */
function tally(profile) {
  const byId = new Map(profile.nodes.map((n) => [n.id, n]));
  const parent = new Map();
  for (const n of profile.nodes) for (const c of n.children ?? []) parent.set(c, n.id);
  const own = new Map();
  const incl = new Map();
  profile.samples.forEach((id, i) => {
    const dt = (profile.timeDeltas[i + 1] ?? 0) / 1000;
    const k = label(byId.get(id));
    own.set(k, (own.get(k) ?? 0) + dt);
    const seen = new Set();
    for (let at = id; at !== undefined; at = parent.get(at)) {
      const l = label(byId.get(at));
      if (seen.has(l)) continue;
      seen.add(l);
      incl.set(l, (incl.get(l) ?? 0) + dt);
    }
  });
  return { own, incl };
}

try {
  const ctx = await browser.newContext({ viewport: { width: 1366, height: 768 } });
  const page = await ctx.newPage();
  await page.goto(url);
  await waitReady(page);
  await importAtSpeed(page, { name: 'scenario.json', body, scenario }, opt('speed', 20));
  const cdp = await ctx.newCDPSession(page);
  await cdp.send('Profiler.enable');
  await cdp.send('Profiler.setSamplingInterval', { interval: 1000 });
  await page.click('#run');
  await page.waitForTimeout(opt('warmup', 2) * 1000);
  const t0 = await page.evaluate(() => window.slamlab.lab.timeS());
  await cdp.send('Profiler.start');
  await page.waitForTimeout(opt('seconds', 8) * 1000);
  const { profile } = await cdp.send('Profiler.stop');
  const t1 = await page.evaluate(() => window.slamlab.lab.timeS());
  const { own, incl } = tally(profile);
  const total = [...own.values()].reduce((a, b) => a + b, 0);
  console.log(`sampled ${total.toFixed(0)} ms, simulated ${(t1 - t0).toFixed(1)} s`);
  const top = opt('top', 30);
  const show = (m) => {
    for (const [k, t] of [...m].sort((a, b) => b[1] - a[1]).slice(0, top)) console.log(t.toFixed(0).padStart(7), k);
  };
  console.log('-- self time');
  show(own);
  console.log('-- inclusive time');
  show(incl);
} finally {
  await browser.close();
  server.close();
}
