// "Your log" as a roboticist meets it (issue 55): a replay you can watch
// and scrub, in headless Chromium (tests/support/browser.mjs) driven by
// real mouse events.
//
// The ring log of tests/support/synthetic-log.mjs (two laps of 140 scans,
// 0.25 s apart: 70 s of log; the second lap closes a loop) is played at a
// speed in × real time, which the replay keeps to; then the timeline under
// the map is dragged with the mouse to an early moment: its label reads
// that moment's time, the map shown is the one the SLAM had then (fewer
// walls than at the end, asked of the session), and no loop closure found
// later is drawn (no orange pixel on the canvas); the map is cut to what
// was seen. Start over runs the log from its first scan without opening it
// again. Then the views: the log's map zooms about the pointer with the
// wheel (the transform checked numerically), pans by a drag, resets, and
// each layer hides (pixel counts); two fingers pinch it (touch events sent
// through the DevTools protocol); the merged maps of the log cut in two
// zoom and reset, and a robot unticked leaves no pixel of its colour.
//
// Screenshots land in test-artifacts/ (issue55-scrubbed-replay.png and
// issue55-zoomed-overlay.png are the pictures docs/ keeps).
//
// Needs the wasm build in web/pkg (`./build.sh build`). Run alone with
//   node --test tests/page-log-ux.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { ARTIFACTS, newPage, useBrowser, waitReady } from './support/browser.mjs';
import { ringLog } from './support/synthetic-log.mjs';
import { centredFrame, floorPlan, mapImage, mapYaml } from './support/synthetic-maps.mjs';

const env = useBrowser();
const tmp = mkdtempSync(path.join(tmpdir(), 'slamlab-page-log-ux-'));

const logState = (page) => page.evaluate(() => window.slamlab.logView.snapshot());

/** Records the duration of every long task of the page's main thread in `window.longTasks`. */
function watchLongTasks(page) {
  return page.evaluate(() => {
    window.longTasks = [];
    window.longTaskObserver = new PerformanceObserver((list) =>
      window.longTasks.push(...list.getEntries().map((e) => e.duration)),
    );
    window.longTaskObserver.observe({ type: 'longtask' });
  });
}

/**
 * How many pixels of the element `selector` as shown on screen are near
 * the colour `rgb` (each channel within `tol`): a screenshot of it decoded
 * and counted in a Web Worker of the page (the log canvas belongs to a
 * worker, so its pixels cannot be read back directly; and the counting
 * must not be a long task of the page's main thread, which the tests watch).
 */
async function pixelsNear(page, selector, rgb, tol = 40) {
  const png = (await page.locator(selector).screenshot()).toString('base64');
  return page.evaluate(({ png, rgb, tol }) => {
    const src = `onmessage = async ({ data: { png, rgb, tol } }) => {
      const bitmap = await createImageBitmap(await (await fetch('data:image/png;base64,' + png)).blob());
      const ctx = new OffscreenCanvas(bitmap.width, bitmap.height).getContext('2d');
      ctx.drawImage(bitmap, 0, 0);
      const d = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - rgb[0]) <= tol && Math.abs(d[i + 1] - rgb[1]) <= tol && Math.abs(d[i + 2] - rgb[2]) <= tol) n++;
      }
      postMessage(n);
    };`;
    const worker = new Worker(URL.createObjectURL(new Blob([src], { type: 'text/javascript' })));
    return new Promise((resolve) => {
      worker.onmessage = (e) => {
        worker.terminate();
        resolve(e.data);
      };
      worker.postMessage({ png, rgb, tol });
    });
  }, { png, rgb, tol });
}

/** Presses the mouse on the timeline's thumb (at its value) and drags it to `fraction` of the track. */
async function dragTimeline(page, fraction) {
  // The replay's controls at the top of the screen: the map and the timeline under it in view.
  await page.locator('.log-controls').evaluate((e) => e.scrollIntoView({ block: 'start' }));
  const box = await page.locator('#log-time').boundingBox();
  const { value, max } = await page.locator('#log-time').evaluate((e) => ({ value: Number(e.value), max: Number(e.max) }));
  // Chromium's thumb is 16 px wide: its centre runs from 8 px to width - 8 px.
  const at = (f) => box.x + 8 + f * (box.width - 16);
  const y = box.y + box.height / 2;
  await page.mouse.move(at(value / max), y);
  await page.mouse.down();
  await page.mouse.move(at((value / max + fraction) / 2), y, { steps: 5 });
  await page.mouse.move(at(fraction), y, { steps: 5 });
  await page.mouse.up();
}

const ORANGE = [0xe0, 0x7b, 0x00];

test('your log: a replay played in × real time, scrubbed back with the mouse to the map and closures of that moment, replayed again', { timeout: 300000 }, async () => {
  const file = path.join(tmp, 'ring.log');
  writeFileSync(file, ringLog({ laps: 2, perLap: 140 }).text);
  const { context, page, problems } = await newPage(env.browser, { width: 1920, height: 1080 });
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.getByRole('button', { name: 'Your log…' }).click();
  await page.waitForSelector('#logview:not([hidden])');
  await watchLongTasks(page);
  await page.setInputFiles('#log-file', file);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().records === 281, null, { timeout: 60000 });
  assert.equal(await page.locator('#log-time-value').innerText(), '0.0 s of 1 min 10 s');

  // Played at 10× real time, the log's clock runs at most ten times the
  // wall clock's (a step accounts for the time since the one before).
  await page.locator('#log-speed').fill('10');
  assert.equal(await page.locator('#log-speed-value').innerText(), '10× real time');
  await page.getByRole('button', { name: 'Play' }).click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().timeline.live > 2, null, { timeout: 60000 });
  const t0 = { wall: Date.now(), log: (await logState(page)).timeline.live };
  await page.waitForTimeout(2000);
  const t1 = { wall: Date.now(), log: (await logState(page)).timeline.live };
  const rate = (t1.log - t0.log) / ((t1.wall - t0.wall) / 1000);
  assert.ok(rate > 3 && rate < 12, `the log ran at ${rate.toFixed(1)}× real time when 10× was asked`);
  assert.match(await page.locator('#log-time-value').innerText(), /^(\d+\.\d s|1 min \d\d s) of 1 min 10 s$/);

  // Faster to the end: the loop is closed, the map is whole.
  // A replay slower than asked says how fast it goes.
  await page.locator('#log-speed').fill('100');
  await page.locator('#log-speed').dispatchEvent('input');
  const labels = [];
  while (!(await logState(page)).finished) {
    labels.push(await page.locator('#log-speed-value').innerText());
    await page.waitForTimeout(200);
  }
  console.log(`speed labels at 100×: ${[...new Set(labels)].join(' | ')}`);
  for (const l of labels) {
    const m = /^100× real time(?: \(replaying at (\d+(?:\.\d)?)×\))?$/.exec(l);
    assert.ok(m && (!m[1] || Number(m[1]) < 80), `speed label ${l}`);
  }
  assert.equal(await page.locator('#log-speed-value').innerText(), '100× real time', 'once done, the speed asked only');
  const end = await logState(page);
  assert.ok(end.closures > 0, 'the second lap closed a loop');
  assert.equal(await page.locator('#log-time-value').innerText(), '1 min 10 s of 1 min 10 s');
  const endWalls = end.summary.map.occupied_cells;
  // The map is cut to what the scans saw (the ring is 16 x 10 m) plus 1 m,
  // not the laser's reach around every pose.
  const { width, height, resolution_m: res } = end.summary.map;
  assert.ok(width * res < 19 && height * res < 13, `the map is ${width * res} x ${height * res} m`);
  assert.match(await page.locator('#log-progress').innerText(), new RegExp(`map ${width} × ${height} cells$`));
  const endOrange = await pixelsNear(page, '#log-canvas', ORANGE);
  assert.ok(endOrange > 30, `${endOrange} orange pixels of loop closures at the end`);

  // Drag the timeline back to a fifth of the log (14 s, scan 57: the first lap).
  await dragTimeline(page, 0.2);
  await page.waitForFunction(() => {
    const s = window.slamlab.logView.snapshot();
    return !s.busy && s.robots[0].at !== null;
  });
  const back = await logState(page);
  const r = back.robots[0];
  const moment = back.timeline.moment;
  assert.ok(Math.abs(moment - 14) < 3, `the moment shown: ${moment} s`);
  assert.equal(moment, Number(await page.locator('#log-time').inputValue()), 'the slider where the mouse left it');
  assert.equal(r.at, Math.floor(moment / 0.25) + 1, 'the scans up to the moment (one each 0.25 s)');
  assert.ok(r.atTime <= moment && r.atTime > moment - 0.25, `the last scan shown at ${r.atTime} s`);
  assert.equal(
    await page.locator('#log-time-value').innerText(),
    `${moment.toFixed(1)} s of 1 min 10 s · looking back (replayed to 1 min 10 s)`,
  );
  assert.equal(r.atClosures, 0, 'no loop was closed by then');
  // (The end's map is drawn at the smoothed poses, its walls thinner.)
  assert.ok(r.atWalls > 50 && r.atWalls * 1.5 < endWalls, `${r.atWalls} wall cells then, ${endWalls} at the end`);
  const LIGHT = [0x9c, 0xc0, 0xe8]; // the track's replayed part after the moment shown
  assert.ok((await pixelsNear(page, '#log-time', LIGHT, 12)) > 200, 'the track shows what was replayed after the moment');
  const backOrange = await pixelsNear(page, '#log-canvas', ORANGE);
  assert.equal(backOrange, 0, 'no loop closure drawn before it was found');
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-log-scrubbed.png') });
  await page.screenshot({ path: path.join(ARTIFACTS, 'issue55-scrubbed-replay.png') });

  // Back to the end: the settled map and its closures again.
  await dragTimeline(page, 1);
  await page.waitForFunction(() => {
    const s = window.slamlab.logView.snapshot();
    return !s.busy && s.robots[0].at === null;
  });
  assert.equal(await page.locator('#log-time-value').innerText(), '1 min 10 s of 1 min 10 s');
  assert.ok((await pixelsNear(page, '#log-canvas', ORANGE)) > 30, 'the closures are drawn again');
  const light = await pixelsNear(page, '#log-time', [0x9c, 0xc0, 0xe8], 12);
  assert.ok(light < 20, `at the live end, nothing replayed lies after it (${light} pixels: the thumb's edge)`);

  // One click on the track (no drag) looks back too, and the label says when.
  const track = await page.locator('#log-time').boundingBox();
  await page.mouse.click(track.x + track.width / 2, track.y + track.height / 2);
  await page.waitForFunction(() => {
    const s = window.slamlab.logView.snapshot();
    return !s.busy && s.robots[0].at !== null;
  });
  const clicked = (await logState(page)).timeline.moment;
  assert.ok(Math.abs(clicked - 35) < 3, `clicked to ${clicked} s`);
  assert.equal(
    await page.locator('#log-time-value').innerText(),
    `${clicked.toFixed(1)} s of 1 min 10 s · looking back (replayed to 1 min 10 s)`,
  );

  // Start over: from the first scan, without opening the file again.
  await page.getByRole('button', { name: 'Start over' }).click();
  await page.waitForFunction(() => {
    const s = window.slamlab.logView.snapshot();
    return s.playing && !s.finished && s.done < 281;
  });
  await page.waitForFunction(() => window.slamlab.logView.snapshot().finished, null, { timeout: 240000, polling: 100 });
  const again = await logState(page);
  assert.equal(again.done, 281);
  assert.equal(again.closures, end.closures, 'the same replay finds the same loop closures');

  const tasks = await page.evaluate(() => window.longTasks);
  assert.ok(Math.max(0, ...tasks) <= 100, `long tasks: ${tasks.map(Math.round).join(', ')} ms`);
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

/** The view transform of the log canvas (zoom.js's `{k, x, y}`, device pixels). */
const logView = async (page) => (await logState(page)).view;

test('your log: the map zooms about the pointer with the wheel, pans by dragging, resets; each layer can be hidden', { timeout: 300000 }, async () => {
  const file = path.join(tmp, 'ring-zoom.log');
  writeFileSync(file, ringLog({ laps: 2, perLap: 140 }).text);
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.getByRole('button', { name: 'Your log…' }).click();
  await page.waitForSelector('#logview:not([hidden])');
  await watchLongTasks(page);
  await page.setInputFiles('#log-file', file);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().records === 281, null, { timeout: 60000 });
  await page.locator('#log-speed').fill('100');
  await page.getByRole('button', { name: 'Play' }).click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().finished, null, { timeout: 240000, polling: 100 });
  await page.locator('#log-canvas').scrollIntoViewIfNeeded();
  const box = await page.locator('#log-canvas').boundingBox();
  assert.ok(box.width >= 1300, `the map fills the width: ${box.width} px`);
  assert.deepEqual(await logView(page), { k: 1, x: 0, y: 0 });
  assert.equal(await page.locator('#log-view-reset').isDisabled(), true);
  const before = await pixelsNear(page, '#log-canvas', [0x22, 0x22, 0x22], 10);

  // The wheel zooms in about the pointer: the point under it stays put.
  // Whole pixels: the browser reports the pointer in whole CSS pixels.
  const c = [Math.round(box.x + 0.3 * box.width), Math.round(box.y + 0.4 * box.height)];
  const local = [c[0] - box.x, c[1] - box.y]; // device pixels (dpr 1)
  await page.mouse.move(...c);
  await page.mouse.wheel(0, -300);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().view.k > 1);
  const z = await logView(page);
  assert.ok(Math.abs(z.k - Math.exp(0.6)) < 1e-9, `zoomed by ${z.k}`);
  for (const i of [0, 1]) {
    const under = (local[i] - [z.x, z.y][i]) / z.k;
    assert.ok(Math.abs(under - local[i]) < 1e-6, `the point under the pointer moved: ${under} ≠ ${local[i]}`);
  }
  await page.waitForTimeout(300);
  const zoomed = await pixelsNear(page, '#log-canvas', [0x22, 0x22, 0x22], 10);
  assert.ok(zoomed > before * 1.3, `walls drawn larger: ${zoomed} dark pixels, ${before} before`);

  // A drag moves the view by as much as the pointer moved.
  await page.mouse.move(...c);
  await page.mouse.down();
  await page.mouse.move(c[0] + 60, c[1] + 20, { steps: 4 });
  await page.mouse.move(c[0] + 120, c[1] + 40, { steps: 4 });
  await page.mouse.up();
  await page.waitForFunction((x) => window.slamlab.logView.snapshot().view.x > x + 100, z.x);
  const moved = await logView(page);
  assert.ok(Math.abs(moved.x - z.x - 120) < 1e-6 && Math.abs(moved.y - z.y - 40) < 1e-6, `panned by ${moved.x - z.x}, ${moved.y - z.y}`);
  assert.equal(moved.k, z.k);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-log-zoomed.png') });

  // Reset view: the fitted drawing again.
  await page.getByRole('button', { name: 'Reset view' }).click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().view.k === 1);
  assert.deepEqual(await logView(page), { k: 1, x: 0, y: 0 });
  await page.waitForTimeout(300);
  assert.equal(await pixelsNear(page, '#log-canvas', [0x22, 0x22, 0x22], 10), before, 'the same drawing as before the zoom');

  // Each layer hides and shows again: loop closures (orange), SLAM's path (the robot's blue).
  for (const [name, rgb] of [['loop closures', ORANGE], ["SLAM's path", [0x1f, 0x77, 0xb4]]]) {
    const shown = await pixelsNear(page, '#log-canvas', rgb, 24);
    assert.ok(shown > 30, `${shown} pixels of ${name}`);
    await page.getByLabel(name, { exact: true }).uncheck();
    await page.waitForTimeout(300);
    assert.equal(await pixelsNear(page, '#log-canvas', rgb, 24), 0, `${name} hidden`);
    await page.getByLabel(name, { exact: true }).check();
    await page.waitForTimeout(300);
    assert.equal(await pixelsNear(page, '#log-canvas', rgb, 24), shown, `${name} shown again`);
  }

  const tasks = await page.evaluate(() => window.longTasks);
  assert.ok(Math.max(0, ...tasks) <= 100, `long tasks: ${tasks.map(Math.round).join(', ')} ms`);
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your log: the merged maps zoom with the wheel and reset; a robot unticked hides its map and path', { timeout: 400000 }, async () => {
  const file = path.join(tmp, 'hall.log');
  writeFileSync(file, ringLog({ laps: 1.5, perLap: 140, world: 'hall' }).text);
  const { context, page, problems } = await newPage(env.browser, { width: 1920, height: 1080 });
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.getByRole('button', { name: 'Your log…' }).click();
  await page.waitForSelector('#logview:not([hidden])');
  await page.setInputFiles('#log-file', file);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().records === 211, null, { timeout: 60000 });
  await page.locator('#log-cut').fill('2');
  await page.locator('#log-cut').dispatchEvent('change');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 2, null, { timeout: 60000 });
  await page.locator('#log-merge').click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().merge, null, { timeout: 300000, polling: 200 });
  assert.equal((await logState(page)).merge.merge.status, 'merged');
  await page.locator('#log-overlay').scrollIntoViewIfNeeded();
  await page.waitForTimeout(300);
  const box = await page.locator('#log-overlay').boundingBox();
  assert.ok(box.width >= 1800 && box.height >= 800, `the merged maps fill the screen: ${box.width} x ${box.height} px`);
  const RED = [0xd6, 0x27, 0x28]; // hall-2's colour
  const dark = async () => pixelsNear(page, '#log-overlay', [0x30, 0x30, 0x30], 48);
  const fitted = await dark();

  // The wheel zooms in about the pointer; Reset view fits the maps again.
  const c = [Math.round(box.x + 0.55 * box.width), Math.round(box.y + 0.5 * box.height)];
  await page.mouse.move(...c);
  await page.mouse.wheel(0, -400);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().mergeView?.k > 1);
  const z = (await logState(page)).mergeView;
  assert.ok(Math.abs(z.k - Math.exp(0.8)) < 1e-9, `zoomed by ${z.k}`);
  for (const i of [0, 1]) {
    const local = c[i] - [box.x, box.y][i];
    const under = (local - [z.x, z.y][i]) / z.k;
    assert.ok(Math.abs(under - local) < 1e-6, `the point under the pointer moved: ${under} ≠ ${local}`);
  }
  await page.waitForTimeout(400);
  const zoomed = await dark();
  await page.screenshot({ path: path.join(ARTIFACTS, 'issue55-zoomed-overlay.png') });
  assert.ok(zoomed > fitted * 1.3, `walls drawn larger: ${zoomed} dark pixels, ${fitted} fitted`);
  await page.locator('#log-merge-reset').click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().mergeView.k === 1);
  await page.waitForTimeout(400);
  assert.equal(await dark(), fitted, 'the fitted drawing again');

  // Untick hall-2: its red map and path go; tick it: they come back.
  const red = await pixelsNear(page, '#log-overlay', RED, 40);
  assert.ok(red > 100, `${red} pixels of hall-2`);
  await page.getByLabel('hall-2', { exact: true }).uncheck();
  await page.waitForTimeout(400);
  assert.equal(await pixelsNear(page, '#log-overlay', RED, 40), 0, 'hall-2 hidden');
  await page.getByLabel('hall-2', { exact: true }).check();
  await page.waitForTimeout(400);
  assert.equal(await pixelsNear(page, '#log-overlay', RED, 40), red, 'hall-2 shown again');
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your log: a pinch of two fingers zooms the map about their midpoint', { timeout: 120000 }, async () => {
  const file = path.join(tmp, 'ring-pinch.log');
  writeFileSync(file, ringLog({ laps: 1, perLap: 140 }).text);
  const context = await env.browser.newContext({ viewport: { width: 1366, height: 768 }, hasTouch: true });
  const page = await context.newPage();
  const problems = [];
  page.on('pageerror', (e) => problems.push(e.message));
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.getByRole('button', { name: 'Your log…' }).click();
  await page.waitForSelector('#logview:not([hidden])');
  await page.setInputFiles('#log-file', file);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().records === 141, null, { timeout: 60000 });
  await page.getByRole('button', { name: 'Step', exact: true }).click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().done === 5);
  await page.locator('.log-controls').evaluate((e) => e.scrollIntoView({ block: 'start' }));
  const box = await page.locator('#log-canvas').boundingBox();
  const mid = [Math.round(box.x + box.width / 2), Math.round(box.y + box.height / 2)];

  // Two fingers 40 px apart spread to 120 px apart, in ten moves, about `mid`.
  const cdp = await context.newCDPSession(page);
  const fingers = (half) => [
    { x: mid[0] - half, y: mid[1], id: 1 },
    { x: mid[0] + half, y: mid[1], id: 2 },
  ];
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: fingers(20) });
  for (let i = 1; i <= 10; i++) await cdp.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: fingers(20 + 4 * i) });
  await cdp.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
  await page.waitForFunction(() => window.slamlab.logView.snapshot().view.k > 2.9);
  const z = (await logState(page)).view;
  assert.ok(Math.abs(z.k - 3) < 1e-9, `pinched to ${z.k}×`);
  for (const i of [0, 1]) {
    const local = mid[i] - [box.x, box.y][i];
    const under = (local - [z.x, z.y][i]) / z.k;
    assert.ok(Math.abs(under - local) < 1e-6, `the point between the fingers moved: ${under} ≠ ${local}`);
  }
  assert.deepEqual(problems, []);
  await context.close();
});

test('your maps: the merged overlay fills the screen, zooms about the pointer, resets; a map unticked is hidden', { timeout: 180000 }, async () => {
  // Two maps of one 30 x 20 m floor: A sees its west part, B its east part turned by 0.9 rad.
  const plan = floorPlan(30, 20, 7);
  const files = [
    ['ux-a.yaml', mapYaml('ux-a.pgm', [-2, 1, 0])],
    ['ux-a.pgm', mapImage(plan, [-0.5, -0.5, 0], 640, 440, ([x]) => x <= 19.5)],
    ['ux-b.yaml', mapYaml('ux-b.pgm')],
    ['ux-b.pgm', mapImage(plan, centredFrame(18, 10, 0.9, 640, 640), 640, 640, ([x]) => x >= 9)],
  ].map(([name, data]) => {
    writeFileSync(path.join(tmp, name), data);
    return path.join(tmp, name);
  });
  const { context, page, problems } = await newPage(env.browser, { width: 1920, height: 1080 });
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.getByRole('button', { name: 'Your maps…' }).click();
  await page.waitForSelector('#real:not([hidden])');
  await page.setInputFiles('#real-files', files);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report, null, { timeout: 120000 });
  assert.match(await page.locator('#real-verdict').innerText(), /^Merged/);
  await page.locator('#real-overlay').scrollIntoViewIfNeeded();
  await page.waitForTimeout(400);
  const box = await page.locator('#real-overlay').boundingBox();
  assert.ok(box.width >= 1800 && box.height >= 800, `the overlay fills the screen: ${box.width} x ${box.height} px`);
  const zoomOf = () => page.evaluate(() => window.slamlab.savedMaps.overlay.zoom.toJSON());
  const RED = [0xd6, 0x27, 0x28]; // the second map's colour
  const red = async () => pixelsNear(page, '#real-overlay', RED, 40);
  const fitted = await red();
  assert.ok(fitted > 1000, `${fitted} pixels of the second map`);

  const c = [Math.round(box.x + 0.5 * box.width), Math.round(box.y + 0.5 * box.height)];
  await page.mouse.move(...c);
  await page.mouse.wheel(0, -500);
  await page.waitForFunction(() => window.slamlab.savedMaps.overlay.zoom.k > 1);
  const z = await zoomOf();
  assert.ok(Math.abs(z.k - Math.exp(1)) < 1e-9, `zoomed by ${z.k}`);
  for (const i of [0, 1]) {
    const local = c[i] - [box.x, box.y][i];
    assert.ok(Math.abs((local - [z.x, z.y][i]) / z.k - local) < 1e-6, 'the point under the pointer stays');
  }
  await page.waitForTimeout(400);
  const zoomed = await red();
  assert.ok(zoomed > fitted * 1.2, `the second map drawn larger: ${zoomed} pixels, ${fitted} fitted`);
  await page.locator('#real-view-reset').click();
  await page.waitForTimeout(400);
  assert.deepEqual(await zoomOf(), { k: 1, x: 0, y: 0 });
  assert.equal(await red(), fitted, 'the fitted overlay again');

  await page.getByLabel('ux-b.yaml', { exact: true }).uncheck();
  await page.waitForTimeout(400);
  assert.equal(await red(), 0, 'the second map hidden');
  await page.getByLabel('ux-b.yaml', { exact: true }).check();
  await page.waitForTimeout(400);
  assert.equal(await red(), fitted, 'the second map shown again');
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});
