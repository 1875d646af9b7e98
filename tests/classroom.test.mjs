// End-to-end tests of the classroom features of the page, in headless
// Chromium: the guided mode (thesis §6.2.1–6.2.5) stepped through to the
// merge with its numbers checked on the way, the method comparison chart,
// the printable summary, shared links (a link restores the exact scenario
// and seed; Reset to preset; a damaged link), and the fit at 1280 × 720 and
// at tablet width (768 × 1024). Screenshots go to test-artifacts/.
//
// The server and browser are tests/support/browser.mjs's, as for
// tests/page.test.mjs. Needs the wasm build in web/pkg (`./build.sh build`).
// Run alone with
//   node --test tests/classroom.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { readFile } from 'node:fs/promises';
import { ARTIFACTS, ROOT, newPage, useBrowser, waitReady } from './support/browser.mjs';
const env = useBrowser();

const guideTitle = (page) => page.locator('#guide-title').innerText();
const liveText = (page) => page.locator('#guide .guide-live').innerText();
const mergeView = (page) => page.evaluate(() => JSON.parse(window.slamlab.lab.mergeViewJson()));
const nextEnabled = (page, timeout) =>
  page.waitForFunction(() => !document.querySelector('#guide-next').disabled, null, { timeout });

test('guided mode: §6.2.1 to §6.2.5 on the thesis preset, numbers on the way, then the chart and the summary', { timeout: 420000 }, async () => {
  const { context, page, problems } = await newPage(env.browser);
  await page.goto(env.baseUrl);
  await waitReady(page);

  // Open with the toolbar button: step 1 of 5, Next disabled before a run.
  const opener = page.getByRole('button', { name: 'Guided: reproduce the thesis' });
  await opener.click();
  assert.equal(await opener.getAttribute('aria-expanded'), 'true');
  assert.equal(await guideTitle(page), 'Data collection');
  assert.match(await page.locator('#guide .guide-counter').innerText(), /Step 1 of 5 · §6\.2\.1/i);
  assert.equal(await page.locator('#guide-next').isDisabled(), true, 'no Next before the robots have run');
  assert.equal(await page.locator('#guide-back').isDisabled(), true);
  assert.equal(await page.locator('.cameras').isVisible(), false, 'the guide takes the cameras\u2019 place');

  // §6.2.1: the button loads the thesis preset and runs the robots to the end.
  await page.getByRole('button', { name: 'Load the thesis map and run' }).click();
  await page.waitForFunction(() => window.slamlab.state().time_s > 1, null, { timeout: 30000 });
  assert.equal((await page.evaluate(() => window.slamlab.scenario())).name, 'thesis');
  await page.waitForFunction(() => window.slamlab.state().finished, null, { timeout: 240000 });
  await nextEnabled(page, 5000);
  const collect = await liveText(page);
  const pictures = /Frames: robot1 (\d+), robot2 (\d+)/.exec(collect);
  assert.ok(pictures, `the step reports the frames taken: ${collect}`);
  assert.equal(Number(pictures[1]), 148, 'one frame per simulated second over 147 s, t = 0 included');
  assert.equal(Number(pictures[2]), 148);
  assert.match(collect, /robot1 \d+\.\d\d m \(odometry alone \d+\.\d\d m\)/);

  // §6.2.2: a thesis merge starts, held before matching; its selection is
  // marked on the map, one marker per kept frame.
  await page.locator('#guide-next').click();
  assert.equal(await guideTitle(page), 'Image selection');
  await nextEnabled(page, 10000);
  const sel = await page.evaluate(() => JSON.parse(window.slamlab.lab.mergeSelectionJson()));
  assert.equal(sel.method, 'thesis');
  assert.equal(sel.robots.length, 2);
  for (const r of sel.robots) {
    assert.ok(r.selected.length > 0, `${r.name} kept ${r.selected.length} frames`);
    assert.ok(r.square >= r.selected.length && r.captured >= r.square, `${r.name}: ${r.captured} → ${r.square} → ${r.selected.length}`);
    for (const f of r.selected) {
      assert.ok(Math.abs(f.sonar4_m - f.sonar5_m) <= sel.sonar_tolerance_m + 1e-9, `frame ${f.frame}: sonars 4 and 5 alike`);
    }
  }
  const markers = await page.evaluate(() => window.slamlab.markers());
  assert.equal(markers.length, sel.robots[0].selected.length + sel.robots[1].selected.length, 'a marker per selected frame');
  const selText = await liveText(page);
  assert.match(selText, new RegExp(`robot1: 148 frames → ${sel.robots[0].square} facing a wall squarely → ${sel.robots[0].selected.length} kept`));
  await page.waitForTimeout(300);
  const held = await mergeView(page);
  assert.equal(held.progress.stage, 'features');
  assert.equal(held.progress.done, 0, 'the merge waits for step 6.2.3');
  await page.screenshot({ path: path.join(ARTIFACTS, 'classroom-selection.png') });

  // §6.2.3: the table fills in; every planned pair is checked; the best
  // pair's matches open in the pair view.
  await page.locator('#guide-next').click();
  assert.equal(await guideTitle(page), 'Image matching');
  await page.waitForFunction(() => JSON.parse(window.slamlab.lab.mergeViewJson()).tables[0].cells.length > 0, null, {
    timeout: 60000,
  });
  const partial = (await mergeView(page)).tables[0];
  await nextEnabled(page, 180000);
  const matched = await mergeView(page);
  const table = matched.tables[0];
  assert.equal(table.rows, sel.robots[0].selected.length);
  assert.equal(table.cols, sel.robots[1].selected.length);
  assert.equal(table.planned, table.rows * table.cols, 'the thesis matches every pair');
  assert.equal(table.cells.length, table.planned, 'every cell filled');
  assert.ok(partial.cells.length < table.cells.length, `the table filled in over time (${partial.cells.length} first)`);
  assert.ok(table.best, 'a best pair');
  const best = table.cells.find((c) => c[0] === table.best[0] && c[1] === table.best[1]);
  assert.match(await liveText(page), new RegExp(`row ${table.best[0] + 1} × column ${table.best[1] + 1} .*: ${best[2]} inliers`));
  assert.match(await page.locator('#merge-table-hint').innerText(), new RegExp(`${table.planned} of ${table.planned} pairs checked`));
  await page.getByRole('button', { name: 'Show the best pair\u2019s matches' }).click();
  await page.waitForSelector('#pair-overlay:not([hidden]) canvas');
  assert.match(await page.locator('#pair-overlay').innerText(), new RegExp(`ratio-test matches, ${best[2]} inliers`));
  await page.keyboard.press('Escape');
  assert.equal(await page.locator('#pair-overlay').isHidden(), true, 'Escape closes the pair view first');
  assert.equal(await page.locator('#guide').isVisible(), true, '... and leaves the guide open');

  // §6.2.4: the two equations with the measured numbers; K and AD.
  await page.locator('#guide-next').click();
  assert.equal(await guideTitle(page), 'Distance between the robots');
  const report = (await mergeView(page)).report;
  assert.equal(report.method, 'thesis');
  const d = report.pairs[0].distance;
  assert.ok(d, `a distance was computed: ${report.pairs[0].reason}`);
  assert.ok(Number.isFinite(d.k_m_per_px) && d.k_m_per_px > 0, `K = ${d.k_m_per_px}`);
  assert.ok(Number.isFinite(d.ad_m) && d.ad_m > 0, `AD = ${d.ad_m}`);
  const dist = await liveText(page);
  assert.ok(dist.includes(`K = 2 · ${d.de_m.toFixed(3)} · ${d.tan_half_fov.toFixed(4)} / (${d.fj_px.toFixed(1)} − ${d.gh_px.toFixed(1)})`), dist);
  assert.ok(dist.includes(`= ${(d.k_m_per_px * 1000).toFixed(2)} mm/px`), dist);
  assert.ok(dist.includes(`= ${d.ad_m.toFixed(3)} m`), dist);
  assert.ok(dist.includes(`B′C′ = ${d.bc_px.toFixed(0)} px, FJ = ${d.fj_px.toFixed(1)} px, GH = ${d.gh_px.toFixed(1)} px`), dist);
  const letters = (await page.evaluate(() => window.slamlab.markers())).filter((m) => m.label).map((m) => m.label).sort();
  assert.deepEqual(letters, ['A′', 'D', 'E'], 'A′, D and E are labelled on the map');
  const zoom = await page.evaluate(() => window.slamlab.view().scale);
  await page.screenshot({ path: path.join(ARTIFACTS, 'classroom-distance.png') });

  // §6.2.5: merged, with the transform's error against the ground truth.
  await page.locator('#guide-next').click();
  assert.equal(await guideTitle(page), 'Merge the maps');
  assert.ok((await page.evaluate(() => window.slamlab.view().scale)) < zoom, 'the map zooms back out');
  assert.equal(report.status, 'merged', report.reason);
  const e = report.errors.find((x) => x.robot === 'robot2');
  assert.ok(e.error_m < 0.3, `robot2's map frame is off by ${e.error_m} m`);
  assert.match(await liveText(page), new RegExp(`Error against the ground truth: ${e.error_m.toFixed(3)} m and ${Math.abs(e.error_deg).toFixed(2)}°`));
  assert.equal(await page.locator('#merge-map').isVisible(), true, 'the merged map is drawn');
  await page.waitForTimeout(600); // the side panel scrolls the merged map into view
  await page.screenshot({ path: path.join(ARTIFACTS, 'classroom-merge.png') });
  assert.equal(await page.locator('#guide-next').innerText(), 'Finish');
  await page.locator('#guide-next').click();
  assert.equal(await page.locator('#guide').isHidden(), true);
  assert.equal(await page.evaluate(() => window.slamlab.markers()), null, 'the markers go with the guide');
  assert.equal(await page.evaluate(() => document.activeElement.id), 'guided-open', 'focus returns to the opener');

  // The method chart: the thesis's row is filled; merging with the other two
  // methods on the same run fills theirs.
  const chart = page.locator('#merge-methods-chart');
  assert.match(await chart.getAttribute('aria-label'), new RegExp(`Thesis §6\\.2: ${e.error_m.toFixed(3)} m`));
  assert.match(await chart.getAttribute('aria-label'), /Automatic: not run yet/);
  for (const method of ['map-only', 'auto']) {
    await page.selectOption('#merge-method', method);
    await page.getByRole('button', { name: 'Merge maps' }).click();
    await page.waitForFunction((m) => window.slamlab.mergePanel.results[m], method, { timeout: 120000 });
  }
  const results = await page.evaluate(() => window.slamlab.mergePanel.results);
  const label = await chart.getAttribute('aria-label');
  for (const [name, key] of [['Automatic', 'auto'], ['Map-only', 'map-only']]) {
    const r = results[key];
    const expect = r.status === 'merged' ? `${name}: ${r.error_m.toFixed(3)} m` : `${name}: no merge`;
    assert.ok(label.includes(expect), `${label} names ${expect}`);
  }
  await chart.scrollIntoViewIfNeeded();
  await page.screenshot({ path: path.join(ARTIFACTS, 'classroom-chart.png') });

  // The printable summary: scenario, seed, link, figures, verdict, methods.
  await page.getByRole('button', { name: 'Summary of the run, printable' }).click();
  const summary = page.locator('#summary');
  await summary.waitFor({ state: 'visible' });
  const sum = await summary.innerText();
  assert.match(sum, /Run summary: “thesis”/);
  assert.match(sum, /Seed 7 · 147\.0 s simulated of 147 s/);
  assert.match(sum, /#preset=thesis&seed=7/);
  assert.match(sum, /robot1\s+left wall, 0\.60 m\s+148\s+\d+\s+\d+\.\d\d m/);
  assert.match(sum, /Transform error of each method/);
  const images = await summary.locator('img').evaluateAll((imgs) => imgs.map((i) => i.naturalWidth));
  assert.ok(images.length >= 4 && images.every((w) => w > 0), `summary images: ${images}`);
  await page.emulateMedia({ media: 'print' });
  assert.equal(await page.locator('.toolbar').isVisible(), false, 'printing shows the summary alone');
  assert.equal(await summary.isVisible(), true);
  await page.emulateMedia({ media: 'screen' });
  await page.screenshot({ path: path.join(ARTIFACTS, 'classroom-summary.png') });
  await page.keyboard.press('Escape');
  assert.equal(await summary.isHidden(), true);

  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('a shared link restores the same scenario and seed; Reset to preset; short and damaged links', { timeout: 90000 }, async () => {
  const a = await newPage(env.browser);
  await a.page.goto(env.baseUrl);
  await waitReady(a.page);

  // Edit: a new seed and a robot's follow distance.
  await a.page.fill('#seed', '11');
  await a.page.locator('#seed').dispatchEvent('change');
  const dist = a.page.locator('.robot-card').nth(1).locator('input.dist');
  await dist.fill('0.8');
  await dist.dispatchEvent('change');
  const first = await a.page.evaluate(() => window.slamlab.scenario());
  assert.equal(first.seed, 11);
  assert.equal(first.robots[1].distance, 0.8);
  let link = await a.page.evaluate(() => window.slamlab.shareLink());
  assert.match(link, /#z=[\w-]+&from=thesis$/, link);

  // Copy link puts the link on the clipboard and in the address bar, which
  // then follows the edits.
  await a.context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: env.baseUrl });
  await a.page.getByRole('button', { name: 'Copy link' }).click();
  await a.page.waitForFunction(() => /Link copied/.test(document.querySelector('#status').textContent), null, { timeout: 5000 });
  assert.equal(await a.page.evaluate(() => navigator.clipboard.readText()), link);
  await a.page.waitForFunction((l) => location.href === l, link, { timeout: 5000 });
  await a.page.fill('#seed', '13');
  await a.page.locator('#seed').dispatchEvent('change');
  const edited = await a.page.evaluate(() => window.slamlab.scenario());
  assert.equal(edited.seed, 13);
  assert.notEqual(await a.page.evaluate(() => window.slamlab.shareLink()), link, 'a new seed, a new link');
  link = await a.page.evaluate(() => window.slamlab.shareLink());
  await a.page.waitForFunction((l) => location.href === l, link, { timeout: 5000 });

  // A new browser (no autosave) opens the link: the same scenario, seed and run.
  const b = await newPage(env.browser);
  await b.page.goto(link);
  await waitReady(b.page);
  const opened = await b.page.evaluate(() => window.slamlab.scenario());
  assert.deepEqual(opened, edited, 'the shared link restores the scenario exactly');
  assert.equal(await b.page.inputValue('#seed'), '13');
  assert.equal(
    await b.page.evaluate(() => window.slamlab.lab.scenarioJson()),
    await a.page.evaluate(() => window.slamlab.lab.scenarioJson()),
    'the Lab holds the same scenario in both pages',
  );
  assert.match(await b.page.locator('#status').innerText(), /Opened a shared link: “thesis” with seed 13/);
  // Same scenario and seed, same run: a few seconds agree to the bit.
  for (const p of [a.page, b.page]) await p.evaluate(() => window.slamlab.lab.step(50));
  const [sa, sb] = await Promise.all([a.page, b.page].map((p) => p.evaluate(() => window.slamlab.state().robots.map((r) => r.truth))));
  assert.deepEqual(sa, sb, 'both pages run the same simulation');

  // Reset to preset: back to the thesis preset as shipped (seed 7, 0.6 m).
  await b.page.getByRole('button', { name: 'Reset to the preset this scenario came from' }).click();
  await b.page.waitForFunction(() => window.slamlab.scenario().seed === 7);
  const reset = await b.page.evaluate(() => window.slamlab.scenario());
  const shipped = JSON.parse(await readFile(path.join(ROOT, 'scenarios/thesis.json'), 'utf8'));
  assert.equal(reset.robots[1].distance, shipped.robots[1].distance ?? 0.6);
  assert.equal(reset.walls.length, shipped.walls.length);
  await b.page.waitForFunction(() => location.hash === '#preset=thesis&seed=7', null, { timeout: 5000 });

  // A reload keeps the scenario (the address bar and the autosave agree).
  await b.page.reload();
  await waitReady(b.page);
  assert.equal((await b.page.evaluate(() => window.slamlab.scenario())).seed, 7);
  assert.match(await b.page.locator('#status').innerText(), /Restored your last scenario “thesis” \(seed 7\)/);

  // The short form for presets, in the query as typed by hand.
  const c = await newPage(env.browser);
  await c.page.goto(`${env.baseUrl}?preset=maze&seed=12&duration=150`);
  await waitReady(c.page);
  const maze = await c.page.evaluate(() => window.slamlab.scenario());
  assert.equal(maze.name, 'maze');
  assert.equal(maze.seed, 12);
  assert.equal(maze.duration_s, 150);
  await c.page.waitForFunction(() => location.search === '' && location.hash === '#preset=maze&seed=12&duration=150', null, {
    timeout: 5000,
  });

  // A damaged link is reported; the page falls back to the thesis preset.
  const bad = await newPage(env.browser);
  await bad.page.goto(`${env.baseUrl}#z=not-a-scenario`);
  await waitReady(bad.page);
  assert.match(await bad.page.locator('#status').innerText(), /The link could not be opened/);
  assert.equal((await bad.page.evaluate(() => window.slamlab.scenario())).name, 'thesis');

  for (const x of [a, b, c, bad]) {
    assert.deepEqual(x.problems, [], 'no console errors or page errors');
    await x.context.close();
  }
});

/** Controls that stick out of the viewport or their toolbar row. */
async function overflowing(page) {
  return page.evaluate(() => {
    const out = [];
    const vw = document.documentElement.clientWidth;
    for (const e of document.querySelectorAll('.toolbar button, .toolbar select, .toolbar input, .toolbar label, #guide button')) {
      const r = e.getBoundingClientRect();
      if (r.width === 0) continue; // hidden
      if (r.left < 0 || r.right > vw + 0.5) out.push(`${e.id || e.textContent.trim()}: ${r.left}..${r.right} of ${vw}`);
    }
    if (document.documentElement.scrollWidth > vw) out.push(`page ${document.documentElement.scrollWidth} px wide`);
    const guide = document.querySelector('#guide');
    if (!guide.hidden && guide.scrollWidth > guide.clientWidth) out.push(`guide content ${guide.scrollWidth} px in ${guide.clientWidth}`);
    return out;
  });
}

test('fit: two toolbar rows at 1280 × 720; nothing overflows at 768 × 1024; the guide by keyboard', { timeout: 60000 }, async () => {
  const { context, page, problems } = await newPage(env.browser);
  await page.goto(env.baseUrl);
  await waitReady(page);
  const rows = await page.$$eval('.toolbar-row', (els) => els.map((e) => Math.round(e.getBoundingClientRect().height)));
  assert.deepEqual(rows.map((h) => h <= 44), [true, true], `each toolbar row is one line at 1280 px (heights ${rows})`);
  assert.deepEqual(await overflowing(page), []);

  await page.setViewportSize({ width: 768, height: 1024 });
  await page.waitForTimeout(200);
  assert.deepEqual(await overflowing(page), [], 'nothing sticks out at 768 px');

  // Keyboard: G opens the guide (focus on its heading), Tab reaches its
  // buttons, Escape closes it and gives the focus back.
  await page.locator('#world').focus();
  await page.keyboard.press('g');
  assert.equal(await page.locator('#guide').isVisible(), true);
  assert.equal(await page.evaluate(() => document.activeElement.id), 'guide-title');
  await page.keyboard.press('Tab');
  assert.match(await page.evaluate(() => document.activeElement.getAttribute('aria-label') ?? ''), /Close the guide/);
  await page.keyboard.press('Tab');
  assert.equal(await page.evaluate(() => document.activeElement.textContent), 'Load the thesis map and run');
  assert.deepEqual(await overflowing(page), [], 'the open guide fits at 768 px');
  await page.screenshot({ path: path.join(ARTIFACTS, 'classroom-768.png') });
  await page.keyboard.press('Escape');
  assert.equal(await page.locator('#guide').isHidden(), true);
  assert.equal(await page.evaluate(() => document.activeElement.id), 'guided-open');

  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});
