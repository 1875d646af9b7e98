// "Your maps" (web/page/real/) as a roboticist meets it, in headless
// Chromium (tests/support/browser.mjs), driven with real mouse and key
// events.
//
// Groups: two maps of building A (which merge) and two of building B (a
// different floor plan; they merge with each other and with neither of
// A's) opened together read "Merged into 2 groups", list each group, and
// each group's tab shows its own transform (against the truth), overlay
// legend and downloads (the merged PGM as large as the truth gives, its
// YAML, the transforms JSON in that group's frame); the reference map has
// no row of its own, and the YAML's origin has no float noise.
//
// A placement you can keep: two maps of different buildings placed by
// hand with real mouse drags; a refused Refine keeps the placement on
// screen with the judged overlay outlined and the reason, Place by hand
// starts again from it, and "Use my placement (not verified)" joins the
// map exactly there, not verified in the verdict, the table, the pair
// list, the downloads (names, a YAML comment) and the JSON.
//
// Resolutions: images picked without YAML at a resolution typed wrong say
// "0.1 m, assumed — change" on their cards; typing 0.05 reads both again
// and merges them at the truth; an image alone read at 0.1 beside a YAML
// map at 0.05 is said to merge at 0.05 (measured), and does when changed.
// A file opened again replaces the one open.
// A photograph (tests/data/chelsea.png, the cat of scikit-image's sample
// images) opened as a map is warned about with its grey levels measured.
// One map open says to open another; a card shows the known part of its
// map, not the unknown around it.
//
// Needs the wasm build in web/pkg (`./build.sh build`). Run alone with
//   node --test tests/page-maps-ux.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { ARTIFACTS, ROOT, newPage, useBrowser, waitReady } from './support/browser.mjs';
import { centredFrame, floorPlan, mapImage, mapYaml } from './support/synthetic-maps.mjs';

const env = useBrowser();
const tmp = mkdtempSync(path.join(tmpdir(), 'slamlab-maps-ux-'));
const RES = 0.05;

function file(name, data) {
  const p = path.join(tmp, name);
  writeFileSync(p, data);
  return p;
}

/**
 * Two maps of a 30 x 20 m plan made from `seed`: `tag`-west (560 x 440
 * cells, seeing x <= 19.5 m, its image's corner at (-0.5, -0.5)) and
 * `tag`-east (600 x 600, seeing x >= 9 m, turned by `theta`). Both YAML
 * origins are 0, so the east map's frame in the west map's is its image
 * frame moved by 0.5 m.
 */
function building(tag, seed, theta) {
  const plan = floorPlan(30, 20, seed);
  const west = [-0.5, -0.5, 0];
  const east = centredFrame(19, 10, theta, 600, 600);
  const files = [
    file(`${tag}-west.yaml`, mapYaml(`${tag}-west.pgm`)),
    file(`${tag}-west.pgm`, mapImage(plan, west, 560, 440, ([x]) => x <= 19.5)),
    file(`${tag}-east.yaml`, mapYaml(`${tag}-east.pgm`)),
    file(`${tag}-east.pgm`, mapImage(plan, east, 600, 600, ([x]) => x >= 9)),
  ];
  return { files, truth: [east[0] + 0.5, east[1] + 0.5, east[2]], sizes: [[560, 440], [600, 600]] };
}

/** Size of the merged grid of a west map and an east map placed at `pose` in its frame (origins 0). */
function mergedSize({ sizes: [[wx, wy], [ex, ey]] }, [x, y, t]) {
  const pts = [[0, 0], [1, 0], [1, 1], [0, 1]].flatMap(([u, v]) => {
    const bu = u * ex * RES, bv = v * ey * RES;
    return [[u * wx * RES, v * wy * RES], [x + Math.cos(t) * bu - Math.sin(t) * bv, y + Math.sin(t) * bu + Math.cos(t) * bv]];
  });
  const span = (k) => Math.max(...pts.map((p) => p[k])) - Math.min(...pts.map((p) => p[k]));
  return [Math.ceil(span(0) / RES), Math.ceil(span(1) / RES)];
}

const snapshot = (page) => page.evaluate(() => window.slamlab.savedMaps.snapshot());

async function openView(page) {
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.getByRole('button', { name: 'Your maps…' }).click();
  await page.waitForSelector('#real:not([hidden])');
}

/** Clicks a download button and returns the file's name and bytes. */
async function downloaded(page, kind) {
  const [d] = await Promise.all([page.waitForEvent('download'), page.click(`#real-downloads button[data-file="${kind}"]`)]);
  return { name: d.suggestedFilename(), bytes: readFileSync(await d.path()) };
}

/** Width and height in a binary PGM's header. */
function pgmSize(bytes) {
  const m = /^P5\n(?:#[^\n]*\n)*(\d+) (\d+)\n255\n/.exec(bytes.subarray(0, 200).toString('latin1'));
  assert.ok(m, 'a binary PGM header');
  assert.equal(bytes.length, m[0].length + Number(m[1]) * Number(m[2]));
  return [Number(m[1]), Number(m[2])];
}

/** The transforms table's row of `map`: its cells. */
async function row(page, map) {
  const rows = await page.locator('#real-transforms tr').evaluateAll((trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
  return rows.find((r) => r[0] === map);
}

/** The table's row of `map` is `truth` [x, y, theta] within 0.1 m and 0.5°. */
function near(cells, [tx, ty, tt], what) {
  assert.ok(cells, `${what} has a row`);
  const [x, y, deg] = cells.slice(1, 4).map(Number);
  assert.ok(Math.hypot(x - tx, y - ty) < 0.1, `${what}: ${cells} against ${tx}, ${ty}`);
  assert.ok(Math.abs(deg - (tt * 180) / Math.PI) < 0.5, `${what}: ${cells} against ${(tt * 180) / Math.PI}°`);
}

test('your maps: maps of two buildings merge into two groups, each with its transforms, overlay and downloads', { timeout: 300000 }, async () => {
  const a = building('a', 7, 0.9);
  const b = building('b', 21, -0.6);
  const { context, page, problems } = await newPage(env.browser, { width: 1920, height: 1080 });
  await openView(page);
  await page.setInputFiles('#real-files', [...a.files, ...b.files]);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report, null, { timeout: 240000 });
  const { report } = await snapshot(page);
  const members = report.merge.groups.map((g) => g.maps);
  assert.deepEqual(members, [['a-west.yaml', 'a-east.yaml'], ['b-west.yaml', 'b-east.yaml']], report.merge.reason);

  // The verdict names both groups and never says "No merge" or "not joined".
  const verdict = await page.locator('#real-verdict').innerText();
  assert.equal(verdict, 'Merged into 2 groups that share no wall with each other: a-west.yaml + a-east.yaml; b-west.yaml + b-east.yaml.');
  assert.equal(await page.locator('#real-verdict').getAttribute('class'), 'real-verdict ok');
  const list = await page.locator('#real-groups li').allInnerTexts();
  assert.equal(list.length, 2);
  assert.match(list[0], /^Group 1: a-west\.yaml \+ a-east\.yaml \(confidence (0\.\d\d|1\.00)\)$/);
  assert.match(list[1], /^Group 2: b-west\.yaml \+ b-east\.yaml \(confidence (0\.\d\d|1\.00)\)$/);
  const pairs = await page.locator('#real-pairs').innerText();
  assert.doesNotMatch(pairs, /no_merge/);
  assert.match(pairs, /a-west\.yaml \+ b-west\.yaml\s+not merged/);
  assert.match(pairs, /a-west\.yaml \+ a-east\.yaml\s+merged/);

  // Group 1 first: its transform, "in another group" for B's maps, its downloads.
  const tabs = page.locator('#real-groups [role="tab"]');
  assert.equal(await tabs.count(), 2);
  assert.equal(await tabs.nth(0).getAttribute('aria-selected'), 'true');
  near(await row(page, 'a-east.yaml'), a.truth, "group 1's a-east.yaml");
  assert.deepEqual((await row(page, 'b-east.yaml')).slice(1), ['–', '–', '–', 'in another group']);
  assert.match(await page.locator('#real-legend').innerText(), /a-west\.yaml\s*a-east\.yaml/);
  assert.doesNotMatch(await page.locator('#real-legend').innerText(), /b-west/);
  for (const b of await page.locator('#real-downloads button').all()) assert.equal(await b.isDisabled(), false);
  const pgmA = await downloaded(page, 'pgm');
  assert.equal(pgmA.name, 'merged-group-1.pgm');
  const [wa, ha] = pgmSize(pgmA.bytes);
  const [ewa, eha] = mergedSize(a, a.truth);
  assert.ok(Math.abs(wa - ewa) <= 2 && Math.abs(ha - eha) <= 2, `group 1 merged ${wa} x ${ha}, the truth gives ${ewa} x ${eha}`);
  const jsonA = JSON.parse((await downloaded(page, 'json')).bytes.toString('utf8'));
  assert.equal(jsonA.status, 'merged');
  assert.equal(jsonA.group, 1);
  assert.equal(jsonA.frame, 'a_west');
  assert.deepEqual(jsonA.transforms.map((t) => t.map), ['a-west.yaml', 'a-east.yaml']);

  // Group 2 by a real click on its tab: B's transform in b-west's frame and B's files.
  await tabs.nth(1).click();
  assert.equal(await tabs.nth(1).getAttribute('aria-selected'), 'true');
  near(await row(page, 'b-east.yaml'), b.truth, "group 2's b-east.yaml");
  // The reference map has no row of its own (tf2 refuses a frame to itself): the caption names it.
  assert.equal(await row(page, 'b-west.yaml'), undefined);
  assert.equal(await page.locator('#real-transforms caption').innerText(), "Each map's frame in the frame of b-west.yaml (the reference)");
  assert.deepEqual((await row(page, 'a-west.yaml')).slice(1), ['–', '–', '–', 'in another group']);
  await page.waitForFunction(() => /b-west\.yaml/.test(document.querySelector('#real-legend').textContent));
  assert.equal(await page.locator('#real-overlay-title').innerText(), 'Merged overlay of group 2: b-west.yaml + b-east.yaml');
  assert.doesNotMatch(await page.locator('#real-legend').innerText(), /a-west/);
  const pgmB = await downloaded(page, 'pgm');
  assert.equal(pgmB.name, 'merged-group-2.pgm');
  const [wb, hb] = pgmSize(pgmB.bytes);
  const [ewb, ehb] = mergedSize(b, b.truth);
  assert.ok(Math.abs(wb - ewb) <= 2 && Math.abs(hb - ehb) <= 2, `group 2 merged ${wb} x ${hb}, the truth gives ${ewb} x ${ehb}`);
  const yamlB = await downloaded(page, 'yaml');
  assert.equal(yamlB.name, 'merged-group-2.yaml');
  assert.match(yamlB.bytes.toString('utf8'), /image: "?merged-group-2\.pgm"?/);
  // The origin without float noise (at most six decimals).
  assert.match(yamlB.bytes.toString('utf8'), /\norigin: \[-?\d+(\.\d{1,6})?, -?\d+(\.\d{1,6})?, 0\.0\]\n/);
  const pngB = await downloaded(page, 'png');
  assert.equal(pngB.name, 'merged-group-2.png');
  const jsonB = JSON.parse((await downloaded(page, 'json')).bytes.toString('utf8'));
  assert.equal(jsonB.group, 2);
  assert.equal(jsonB.frame, 'b_west');
  const [x, y] = jsonB.transforms[1].pose;
  assert.ok(Math.hypot(x - b.truth[0], y - b.truth[1]) < 0.1, `JSON group 2: ${jsonB.transforms[1].pose}`);

  // The arrow keys move between the tabs too.
  await tabs.nth(1).focus();
  await page.keyboard.press('ArrowLeft');
  assert.equal(await tabs.nth(0).getAttribute('aria-selected'), 'true');
  near(await row(page, 'a-east.yaml'), a.truth, "group 1's a-east.yaml again");

  await page.locator('#real-verdict').evaluate((e) => e.scrollIntoView({ block: 'start' }));
  await tabs.nth(1).click();
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(ARTIFACTS, 'issue55-two-building-groups.png') });
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

/** `a ∘ b` for poses [x, y, theta]. */
function compose([ax, ay, at], [bx, by, bt]) {
  const c = Math.cos(at), s = Math.sin(at);
  return [ax + c * bx - s * by, ay + s * bx + c * by, at + bt];
}

/** The page's point (CSS pixels) of `[x, y]` in map a's frame, while a map is placed by hand. */
async function onScreen(page, [x, y]) {
  const { view } = (await snapshot(page)).adjust;
  const box = await page.locator('#real-overlay').boundingBox();
  return [box.x + (view.k * x + view.e) / view.dpr, box.y + (view.f - view.k * y) / view.dpr];
}

/** A real mouse drag of the placed map's middle by `[dx, dy]` metres. */
async function dragBy(page, [dx, dy]) {
  const { pose, pivot } = (await snapshot(page)).adjust.placing;
  const middle = compose(pose, [...pivot, 0]);
  const from = await onScreen(page, middle), to = await onScreen(page, [middle[0] + dx, middle[1] + dy]);
  await page.mouse.move(...from);
  await page.mouse.down();
  await page.mouse.move(...to, { steps: 12 });
  await page.mouse.up();
  await page.waitForFunction(() => !document.querySelector('#real-overlay').dataset.sending);
  return (await snapshot(page)).adjust.placing.pose;
}

/** Presses Refine and waits for its verdict. */
async function refine(page) {
  await page.getByRole('button', { name: 'Refine' }).click();
  await page.waitForFunction(() => {
    const s = window.slamlab.savedMaps.snapshot();
    return s.adjust.pair && !s.busy && !s.adjust.placing;
  }, null, { timeout: 120000 });
  return snapshot(page);
}

const close = (p, q) => p.every((v, i) => Math.abs(v - q[i]) < 1e-9);

test('your maps: a refused Refine keeps your placement, shows what was judged, and "Use my placement" joins it, not verified', { timeout: 300000 }, async () => {
  // Two different buildings: never merged, whatever the placement.
  const a = building('keep-a', 7, 0);
  const b = building('keep-b', 21, 0.4);
  const files = [a.files[0], a.files[1], b.files[2], b.files[3]];
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await openView(page);
  await page.setInputFiles('#real-files', files);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report, null, { timeout: 120000 });
  assert.equal((await snapshot(page)).report.merge.status, 'no_merge');
  assert.equal(await page.locator('#real-keep').isHidden(), true, 'nothing to keep before a Refine');

  await page.getByRole('button', { name: 'Place by hand' }).click();
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().adjust.view);
  const placed = await dragBy(page, [-24, 1]);
  let snap = await refine(page);
  assert.notEqual(snap.adjust.pair.status, 'merged', snap.adjust.pair.reason);
  // The placement stays on screen, with the judged overlay outlined and the reason.
  assert.ok(close(snap.adjust.kept.pose, placed), `kept ${snap.adjust.kept.pose}, placed ${placed}`);
  assert.ok(snap.adjust.kept.judged, 'the refined overlay that was judged');
  assert.equal(await page.locator('#real-overlay-title').innerText(), 'Your placement of keep-b-east.yaml (refused by Refine)');
  assert.match(await page.locator('#real-legend').innerText(), /dashed: the refined overlay that was judged and refused/);
  assert.match(await page.locator('#real-refined').innerText(), /^Refine of keep-b-east\.yaml on keep-a-west\.yaml: refused, because refined from your guess .*\d.*Your placement stays on screen/);
  assert.equal(await page.locator('#real-keep').isVisible(), true);
  assert.equal(await page.locator('#real-keep').innerText(), 'Use my placement (not verified)');

  // Place by hand again starts from the last placement, not from the start.
  await page.getByRole('button', { name: 'Place by hand' }).click();
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().adjust.placing);
  assert.ok(close((await snapshot(page)).adjust.placing.pose, placed), 'starts from the last placement');
  const mine = await dragBy(page, [1.5, -1]);
  snap = await refine(page);
  assert.notEqual(snap.adjust.pair.status, 'merged');
  assert.ok(close(snap.adjust.kept.pose, mine));
  await page.locator('#real-adjust').evaluate((e) => e.scrollIntoView({ block: 'start' }));
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(ARTIFACTS, 'issue55-kept-placement.png') });

  // Use my placement: joined exactly there, not verified everywhere it shows.
  await page.getByRole('button', { name: 'Use my placement (not verified)' }).click();
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report.merge.verified === false && !window.slamlab.savedMaps.snapshot().busy);
  snap = await snapshot(page);
  assert.equal(snap.report.merge.status, 'merged');
  assert.ok(close(snap.report.merge.transforms[1].pose, mine), `joined at ${snap.report.merge.transforms[1].pose}, placed at ${mine}`);
  assert.match(await page.locator('#real-verdict').innerText(), /^Merged where you placed a map, not verified by the merge's tests: placed by hand and kept as placed, not verified \(the tests refused it: refined from your guess/);
  assert.equal(await page.locator('#real-verdict').getAttribute('class'), 'real-verdict unverified');
  assert.equal(await page.locator('#real-keep').isHidden(), true);
  assert.match(await page.locator('#real-transforms caption').innerText(), /with your placement, not verified$/);
  assert.equal((await row(page, 'keep-b-east.yaml (placed by hand, not verified)'))[1], mine[0].toFixed(3));
  assert.match(await page.locator('#real-pair').innerText(), /keep-b-east\.yaml onto keep-a-west\.yaml \(placed by hand, not verified\)/);
  assert.equal(await page.locator('#real-unverified').isVisible(), true);
  assert.equal(await page.locator('#real-downloads [data-file="pgm"]').innerText(), 'Merged map PGM (not verified)');
  const pgm = await downloaded(page, 'pgm');
  assert.equal(pgm.name, 'merged-not-verified.pgm');
  const [w, h] = pgmSize(pgm.bytes);
  const [ew, eh] = mergedSize({ sizes: [a.sizes[0], b.sizes[1]] }, mine);
  assert.ok(Math.abs(w - ew) <= 2 && Math.abs(h - eh) <= 2, `merged ${w} x ${h}, the placement gives ${ew} x ${eh}`);
  const yaml = (await downloaded(page, 'yaml')).bytes.toString('utf8');
  assert.match(yaml, /^# Joined where a person placed a map by hand: not verified/);
  assert.match(yaml, /image: "?merged-not-verified\.pgm"?/);
  const json = JSON.parse((await downloaded(page, 'json')).bytes.toString('utf8'));
  assert.equal(json.verified, false);
  assert.equal(json.status, 'merged');
  assert.equal(json.pairs[0].verified, false);

  assert.equal(await page.locator('#real-overlay-title').innerText(), 'Merged overlay (your placement, not verified)');
  await page.locator('#real-adjust').evaluate((e) => e.scrollIntoView({ block: 'start' }));
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-maps-ux-kept.png') });
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

/** The text of map `name`'s card. */
const cardText = (page, name) => page.locator(`.real-card[data-map="${name}"] figcaption`).innerText();

test('your maps: an image without YAML shows its assumed resolution, and changing it reads the images again and merges them', { timeout: 300000 }, async () => {
  const a = building('res', 7, 0.9);
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await openView(page);
  // Both images picked without their YAMLs, at a resolution typed wrong.
  await page.fill('#real-resolution', '0.1');
  await page.setInputFiles('#real-files', [a.files[1], a.files[3]]);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report, null, { timeout: 120000 });
  assert.match(await cardText(page, 'res-west.pgm'), /560 × 440 cells · 0\.1 m, assumed — change · origin \[0, 0, 0\]/);
  assert.match(await cardText(page, 'res-east.pgm'), /0\.1 m, assumed — change/);
  const before = (await snapshot(page)).report;
  assert.deepEqual(before.maps.map((m) => m.resolution), [0.1, 0.1]);

  // Change: type 0.05 on one card; both images (read at the same assumption) are read again and merged.
  await page.locator('.real-card[data-map="res-west.pgm"] .real-assumed-change').click();
  const box = page.getByRole('spinbutton', { name: 'Resolution of res-west.pgm in metres per cell' });
  assert.equal(await box.inputValue(), '0.1');
  await box.fill('0.05');
  await box.press('Enter');
  await page.waitForFunction(() => {
    const s = window.slamlab.savedMaps.snapshot();
    return s.report && s.report.maps[0].resolution === 0.05 && !s.busy;
  }, null, { timeout: 120000 });
  const { report, maps } = await snapshot(page);
  assert.deepEqual(maps.map((m) => m.resolution), [0.05, 0.05]);
  assert.match(await cardText(page, 'res-west.pgm'), /0\.05 m, assumed — change/);
  assert.match(await cardText(page, 'res-east.pgm'), /0\.05 m, assumed — change/);
  assert.equal(await page.locator('.real-card').count(), 2, 'read again in place, not added');
  assert.equal(report.merge.status, 'merged', report.merge.reason);
  const [x, y] = report.merge.transforms[1].pose;
  assert.ok(Math.hypot(x - a.truth[0], y - a.truth[1]) < 0.1, `merged at ${report.merge.transforms[1].pose}, truth ${a.truth}`);
  assert.match(await page.locator('#real-message').innerText(), /^Read res-west\.pgm, res-east\.pgm again at 0\.05 m per cell\.$/);
  // A map with its YAML says nothing is assumed.
  await page.setInputFiles('#real-files', [a.files[0], a.files[1]]);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().maps.length === 3 && window.slamlab.savedMaps.snapshot().report, null, { timeout: 120000 });
  assert.doesNotMatch(await cardText(page, 'res-west.yaml'), /assumed/);
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your maps: a file opened again under the same name replaces the one open, in its place', { timeout: 300000 }, async () => {
  const a = building('again', 7, 0.9);
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await openView(page);
  await page.setInputFiles('#real-files', a.files);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report, null, { timeout: 120000 });
  const first = (await snapshot(page)).report;
  // The east map again (the same files): still two maps, in the same order, merged again.
  await page.setInputFiles('#real-files', [a.files[2], a.files[3]]);
  await page.waitForFunction(() => /in place of/.test(document.querySelector('#real-message').textContent) && window.slamlab.savedMaps.snapshot().report, null, { timeout: 120000 });
  const { maps, report } = await snapshot(page);
  assert.deepEqual(maps.map((m) => m.name), ['again-west.yaml', 'again-east.yaml']);
  assert.equal(await page.locator('.real-card').count(), 2);
  assert.equal(await page.locator('#real-message').innerText(), 'Opened again-east.yaml. Opened again, in place of the one open: again-east.yaml.');
  assert.equal(report.merge.pairs.length, 1);
  assert.deepEqual(report.merge.transforms, first.merge.transforms);
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your maps: a photograph opened as a map is warned about, with the figures measured', { timeout: 300000 }, async () => {
  const photo = path.join(ROOT, 'tests', 'data', 'chelsea.png');
  const a = building('photo', 7, 0.9);
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await openView(page);
  await page.setInputFiles('#real-files', [a.files[0], a.files[1], photo]);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report, null, { timeout: 120000 });
  const warning = await page.locator('.real-card[data-map="chelsea.png"] .real-card-warning').innerText();
  const m = /^chelsea\.png does not look like an occupancy grid \(a photograph\?\): it uses (\d+) grey levels, and its three commonest hold only (\d+) % of its pixels/.exec(warning);
  assert.ok(m, warning);
  assert.ok(Number(m[1]) > 100 && Number(m[2]) < 20, warning);
  assert.equal(await page.locator('.real-card[data-map="photo-west.yaml"] .real-card-warning').count(), 0, 'a map is not warned about');
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-maps-ux-photo.png') });
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your maps: one map open says to open another; a card shows the map cropped to what it knows', { timeout: 120000 }, async () => {
  // A 10 x 5 m plan in a 40 x 40 m image of unknown: 200 x 100 known cells of 800 x 800.
  const plan = floorPlan(10, 5, 3);
  const files = [file('small.yaml', mapYaml('small.pgm', [-20.3, 1.1, 0])), file('small.pgm', mapImage(plan, [-20, -20, 0], 800, 800, () => true))];
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await openView(page);
  await page.setInputFiles('#real-files', files);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().maps.length === 1 && !window.slamlab.savedMaps.snapshot().busy);
  await page.waitForFunction(() => /One map is open/.test(document.querySelector('#real-message').textContent));
  assert.equal(await page.locator('#real-message').innerText(),
    'Opened small.yaml. One map is open: open one more (or several) to merge it with, the map of another robot or another run of the same building.');
  assert.equal(await page.locator('#real-merge').isDisabled(), true);
  const size = await page.locator('.real-card canvas').evaluate((c) => [c.width, c.height]);
  assert.ok(Math.abs(size[0] / size[1] - 2) < 0.1, `the card's picture is ${size[0]} x ${size[1]}: cropped to the 2:1 building, not the square image`);
  assert.match(await cardText(page, 'small.yaml'), /800 × 800 cells · 0\.05 m · origin \[-20\.3, 1\.1, 0\]/);
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your maps: an image read at a wrong assumed resolution is said to merge at the one measured', { timeout: 300000 }, async () => {
  const a = building('scale', 7, 0.9);
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await openView(page);
  await page.setInputFiles('#real-files', [a.files[0], a.files[1]]);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().maps.length === 1);
  // The east image alone, read at 0.1 m per cell: its walls are twice as long as the west map's.
  await page.fill('#real-resolution', '0.1');
  await page.setInputFiles('#real-files', [a.files[3]]);
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report, null, { timeout: 120000 });
  assert.equal((await snapshot(page)).report.merge.status, 'no_merge');
  await page.waitForFunction(() => /measured/.test(document.querySelector('#real-message').textContent), null, { timeout: 120000 });
  assert.match(await page.locator('#real-message').innerText(),
    /^scale-east\.pgm does not fit scale-west\.yaml at the 0\.1 m per cell assumed, but merges with it read at 0\.05 m per cell \(measured: confidence (0\.\d\d|1\.00)\): change its resolution on its card\?$/);
  // Following the hint merges them at the truth.
  await page.locator('.real-card[data-map="scale-east.pgm"] .real-assumed-change').click();
  await page.getByRole('spinbutton', { name: 'Resolution of scale-east.pgm in metres per cell' }).fill('0.05');
  await page.getByRole('button', { name: 'Read again' }).click();
  await page.waitForFunction(() => window.slamlab.savedMaps.snapshot().report?.merge.status === 'merged', null, { timeout: 120000 });
  const [x, y] = (await snapshot(page)).report.merge.transforms[1].pose;
  assert.ok(Math.hypot(x - a.truth[0], y - a.truth[1]) < 0.1);
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});
