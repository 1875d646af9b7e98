// End-to-end test of ROS bags in "Your log" (web/page/real/: log-panel.js,
// bag-picks.js, bag-read.js, truth-plot.js; issue 53, item 4; and a
// benchmark's relations: log-relations.js, relations-view.js; issue 54) in headless
// Chromium, on the real bags of the shared data (../shared/data/README.md,
// section bags/). Part of the real-data suite: without the data folder
// (`../shared/data` beside the checkout, or `$SLAMLAB_DATA`) it fails.
//
// Driven as a user drives the page: bags dropped on the view (a drop event
// whose DataTransfer carries File objects made in the page from the bags'
// bytes), or picked with the file input; picks changed with the keyboard
// and the mouse; Play, Step and the downloads clicked. It checks
//   - a ROS 1 bag and an MCAP of the same log dropped together: two robots,
//     each card shows /scan and /odom picked and why; both replay to the end
//     with the same result, and the map downloads as a PGM of its size;
//   - the Stage bag (no odometry, ground truth): odometry none, truth
//     /base_pose_ground_truth; the error plot and a finite ATE, the same as
//     `run-log` reports; the ground truth picked away and back;
//   - the raw MIT CSAIL bag dropped with its `.relations` file: the
//     relation errors grow as it replays and end as `run-log --relations`
//     reports them (1172 of 1172 matched, the same mean, sd and max, the
//     same worst relations); each relation's error is plotted, and the
//     worst drawn on the map (none before a scan); a relations file
//     malformed on its third line is named with it, one named after no
//     open log is refused, and the one in use stays; cut into two
//     stretches, each scores what it replays, as `run-log --from --to`;
//   - a pick switched (odometry → none): the robot's replay starts again;
//   - a bag cut short opens with what was lost; random bytes named x.bag
//     are refused by name; a rosbag2 folder's files dropped together are one
//     bag; the robots already open stay as they were;
//   - (in node, without the browser) the files of rosbag2 folders dropped as
//     folders — what dropped.js hands the worker, here from stand-in
//     directory entries of the File and Directory Entries API, which a
//     synthetic drop cannot carry — are one bag a folder, read in pieces by
//     bag-read.js as the worker reads them; a `-wal` goes before its `.db3`;
//   - a 200 MB MCAP made here (tests/support/bag-mcap.mjs) opens with a
//     progress bar that moves, the tab staying under 600 MB: the peak
//     resident memory (VmHWM in /proc) of the renderer process that runs
//     the page and its worker, found as the renderer new to the test's
//     browser context with a DedicatedWorker thread. Resident memory counts everything the tab touches — both
//     wasm instances (the lab's and the worker's), the JS heaps, the
//     decoded bag, the pieces read — which no in-page API does (the JS
//     heap size of Performance.getMetrics leaves out wasm memory).
//
// Needs the wasm build in web/pkg (`./build.sh build`). Run alone with
//   node --test tests/page-bags.test.mjs
import { after, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, readdirSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { ARTIFACTS, ROOT, newPage, useBrowser, waitReady } from './support/browser.mjs';
import { writeRepeatedMcap } from './support/bag-mcap.mjs';
import { loadWasm } from '../web/cli/wasm.mjs';
import { readBag, sortFiles } from '../web/page/real/bag-read.js';
import { droppedFiles } from '../web/page/real/dropped.js';

const DATA = process.env.SLAMLAB_DATA ? path.resolve(process.env.SLAMLAB_DATA) : path.join(ROOT, '..', 'shared', 'data');
if (!existsSync(path.join(DATA, 'bags'))) {
  throw new Error(`real data not found: ${DATA} has no bags/ (set SLAMLAB_DATA to the shared data folder)`);
}
const BAGS = path.join(DATA, 'bags');
const env = useBrowser();
const tmp = mkdtempSync(path.join(tmpdir(), 'slamlab-page-bags-'));
after(() => rmSync(tmp, { recursive: true, force: true }));

/** The files the page may fetch from the test (`/__bags/<key>`): key → path. */
const SERVED = new Map();

/** Serves `file` to the page as `/__bags/<key>`; returns the key. */
function serve(file) {
  const key = `${SERVED.size}/${path.basename(file)}`;
  SERVED.set(key, file);
  return key;
}

async function openLogView(page) {
  await page.route('**/__bags/**', (route) => {
    const key = decodeURIComponent(new URL(route.request().url()).pathname.replace(/^\/__bags\//, ''));
    const file = SERVED.get(key);
    return file ? route.fulfill({ body: readFileSync(file) }) : route.fulfill({ status: 404, body: 'not served' });
  });
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.getByRole('button', { name: 'Your log…' }).click();
  await page.waitForSelector('#logview:not([hidden])');
}

/**
 * Drops `files` on the view's drop zone as a user's drag from a file
 * manager arrives: dragenter, dragover and drop, the DataTransfer holding
 * File objects made in the page from the files' bytes.
 */
async function drop(page, files) {
  const keys = files.map(serve);
  await page.evaluate(async (keys) => {
    const dt = new DataTransfer();
    for (const key of keys) {
      const blob = await (await fetch(`/__bags/${key}`)).blob();
      dt.items.add(new File([blob], key.split('/').pop()));
    }
    const zone = document.querySelector('#logview .real-drop');
    for (const type of ['dragenter', 'dragover', 'drop']) {
      zone.dispatchEvent(new DragEvent(type, { dataTransfer: dt, bubbles: true, cancelable: true }));
    }
  }, keys);
}

const logSnapshot = (page) => page.evaluate(() => window.slamlab.logView.snapshot());

/** The card of the bag called `name`. */
const card = (page, name) => page.locator('#log-bags .bag-card', { has: page.locator('h2', { hasText: new RegExp(`^${name.replace(/[.]/g, '\\.')}$`) }) });

/** The picks a card shows: each select's shown option and the reason beside it. */
async function picksShown(page, name) {
  return card(page, name).evaluate((c) => {
    const out = {};
    for (const s of c.querySelectorAll('select')) {
      out[s.dataset.pick] = { value: s.value, text: s.selectedOptions[0]?.textContent, why: s.nextElementSibling.textContent };
    }
    return out;
  });
}

/** Plays at the top speed until every robot has replayed all its scans. */
async function playToEnd(page) {
  await page.locator('#log-speed').fill('100');
  await page.getByRole('button', { name: 'Play' }).click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().finished, null, { timeout: 600000, polling: 250 });
}

/** Clicks Step, each time once the step before has ended, until `done` scans are replayed in all. */
async function stepTo(page, done) {
  while ((await logSnapshot(page)).done < done) {
    const before = (await logSnapshot(page)).done;
    await page.getByRole('button', { name: 'Step', exact: true }).click();
    await page.waitForFunction((n) => window.slamlab.logView.snapshot().done > n && !window.slamlab.logView.snapshot().busy, before, { timeout: 60000 });
  }
  assert.equal((await logSnapshot(page)).done, done);
}

/** Clicks a download button and returns the file's name and bytes. */
async function downloaded(page, selector) {
  const [d] = await Promise.all([page.waitForEvent('download'), page.click(selector)]);
  return { name: d.suggestedFilename(), bytes: readFileSync(await d.path()) };
}

/** A binary PGM's width, height and pixels. */
function pgm(bytes) {
  const m = /^P5\n(?:#[^\n]*\n)*(\d+) (\d+)\n255\n/.exec(bytes.subarray(0, 200).toString('latin1'));
  assert.ok(m, 'a binary PGM header');
  return { width: Number(m[1]), height: Number(m[2]), pixels: bytes.subarray(m[0].length) };
}

/** A File of `file`'s bytes called `name`. */
const fileOf = (file, name = path.basename(file)) => new File([readFileSync(file)], name);

/** A stand-in for a dropped folder's directory entry (`webkitGetAsEntry`): `files` as `{name: File}`, read in batches of two. */
function folderEntry(fullPath, files) {
  const entries = Object.entries(files).map(([name, file]) => ({ isFile: true, isDirectory: false, fullPath: `${fullPath}/${name}`, file: (ok) => ok(file) }));
  return {
    isFile: false,
    isDirectory: true,
    fullPath,
    createReader: () => ({ readEntries: (ok) => ok(entries.splice(0, 2)) }),
  };
}

test('rosbag2 folders dropped as folders are one bag each, read in pieces; a write-ahead log goes before its database', async () => {
  const wasm = await loadWasm();
  const mit = path.join(BAGS, 'ros2/mit-csail-db3');
  const mumble = path.join(BAGS, 'other/mumble-hallway_room_loop');
  const loose = fileOf(path.join(BAGS, 'other/scan_tools-demo.bag'));
  const dt = {
    items: [
      { kind: 'file', getAsFile: () => null, webkitGetAsEntry: () => folderEntry('/mit-csail-db3', { 'metadata.yaml': fileOf(path.join(mit, 'metadata.yaml')), 'mit-csail-db3.db3': fileOf(path.join(mit, 'mit-csail-db3.db3')) }) },
      { kind: 'file', getAsFile: () => null, webkitGetAsEntry: () => folderEntry('/mumble', { 'my_data_bag_0.db3': fileOf(path.join(mumble, 'my_data_bag_0.db3')), 'metadata.yaml': fileOf(path.join(mumble, 'metadata.yaml')), 'notes.txt': new File(['x'], 'notes.txt') }) },
      { kind: 'file', webkitGetAsEntry: () => ({ isFile: true, isDirectory: false }), getAsFile: () => loose },
    ],
    files: [loose],
  };
  const entries = await droppedFiles(dt);
  assert.deepEqual(entries.map((e) => e.path), [
    'mit-csail-db3/metadata.yaml', 'mit-csail-db3/mit-csail-db3.db3',
    'mumble/my_data_bag_0.db3', 'mumble/metadata.yaml', 'mumble/notes.txt',
    'scan_tools-demo.bag',
  ]);
  const { items, errors } = await sortFiles(wasm, entries);
  assert.deepEqual(items.map((i) => (i.log ? ['a CARMEN log?', i.log.name] : [i.name, i.files.map((f) => f.name)])), [
    ['mit-csail-db3', ['mit-csail-db3.db3']],
    ['mumble', ['my_data_bag_0.db3']],
    ['a CARMEN log?', 'notes.txt'], // not a bag: the worker reads it as a log, and names its problem
    ['scan_tools-demo.bag', ['scan_tools-demo.bag']],
  ]);
  assert.deepEqual(errors, []);
  // Read as the worker reads them: piece by piece, the progress growing to the whole.
  const seen = [];
  const info = await readBag(items[0].bag, items[0].files, (read, total) => seen.push([read, total]));
  assert.equal(info.messages, 5966);
  assert.deepEqual(seen.at(-1), [5582848, 5582848]);
  assert.deepEqual(seen.map(([r]) => r), [0, 5582848], 'one piece of at most 8 MiB');
  const mumbleInfo = await readBag(items[1].bag, items[1].files);
  assert.deepEqual(mumbleInfo.topics.map((t) => [t.name, t.count]).sort(), [['/imu_data', 3698], ['/scan', 896]]);
  for (const i of items) i.bag?.free();

  // A write-ahead log goes before its database; one without its database is named.
  const db = fileOf(path.join(mit, 'mit-csail-db3.db3'), 'a.db3');
  const wal = new File(['not read here'], 'a.db3-wal');
  const lone = new File(['x'], 'b.db3-wal');
  const sorted = await sortFiles(wasm, [{ file: db, path: 'a.db3' }, { file: wal, path: 'a.db3-wal' }, { file: lone, path: 'b.db3-wal' }]);
  assert.deepEqual(sorted.items.map((i) => i.files.map((f) => f.name)), [['a.db3-wal', 'a.db3']]);
  assert.deepEqual(sorted.errors, ['b.db3-wal: a write-ahead log without its database b.db3; pick or drop them together']);
  for (const i of sorted.items) i.bag.free();
});

test('your log: a ROS 1 bag and an MCAP dropped together are two robots with /scan and /odom picked; both replay to the same map, which downloads', { timeout: 600000 }, async () => {
  const { context, page, problems } = await newPage(env.browser, { width: 1280, height: 1000 });
  await openLogView(page);
  await drop(page, [path.join(BAGS, 'freiburg/mit-csail.bag'), path.join(BAGS, 'ros2/mit-csail-zstd.mcap')]);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 2, null, { timeout: 120000 });
  const snap = await logSnapshot(page);
  assert.deepEqual(snap.robots.map((r) => [r.name, r.total]), [['mit-csail', 1988], ['mit-csail-zstd', 1988]]);
  assert.match(await page.locator('#log-name').innerText(), /^mit-csail\.bag, mit-csail-zstd\.mcap: 3976 laser records$/);
  assert.equal(await page.locator('#log-reading').isHidden(), true, 'no progress bar once read');

  // Each card: what the bag is, its topics, what was picked and why.
  for (const [name, what] of [['mit-csail.bag', /^ROS 1 bag 2\.0, bz2, 0\.78 MB: 5,966 messages over 424\.0 s; 1,988 scans to replay$/], ['mit-csail-zstd.mcap', /^MCAP, zstd, 1\.18 MB: 5,966 messages over 424\.0 s; 1,988 scans to replay$/]]) {
    assert.match(await card(page, name).locator('p.real-stage').innerText(), what);
    const picks = await picksShown(page, name);
    assert.deepEqual([picks.scan.text, picks.odom.text, picks.truth.text], ['/scan', '/odom', 'none']);
    assert.equal(picks.scan.why, "the bag's only LaserScan topic");
    assert.equal(picks.odom.why, "the bag's only Odometry topic not named as ground truth");
    assert.equal(picks.truth.why, 'no topic named as ground truth');
    const rows = await card(page, name).locator('.bag-topics tbody tr').allInnerTexts();
    assert.deepEqual(rows.map((r) => r.split('\t').map((s) => s.trim())).sort(), [
      ['/odom', 'nav_msgs/Odometry', '1,988', 'odometry'],
      ['/scan', 'sensor_msgs/LaserScan', '1,988', 'scans'],
      ['/tf', 'tf2_msgs/TFMessage', '1,988', ''],
      ['/tf_static', 'tf2_msgs/TFMessage', '2', ''],
    ]);
    assert.match(await card(page, name).locator('.bag-offset').innerText(), /^laser on base_link: x 0\.000 m, y 0\.000 m, θ 0\.0°$/);
    assert.equal(await card(page, name).locator('.bag-lost').count(), 0, 'nothing lost');
  }
  await stepTo(page, 10);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-bags-picked.png') });

  // Replayed to the end: the same scans give the same result, whatever the container.
  await playToEnd(page);
  const done = await logSnapshot(page);
  assert.deepEqual(done.robots.map((r) => r.done), [1988, 1988]);
  const [a, b] = done.robots.map((r) => r.summary);
  assert.ok(a.closures > 5, `${a.closures} loop closures`);
  assert.deepEqual(b, a, 'the ROS 1 bag and the MCAP replay alike');
  assert.equal(await page.locator('#log-odom-key').isVisible(), true, 'the legend names the odometry');
  assert.equal(await page.locator('#log-truth').isHidden(), true, 'no ground truth, no error plot');
  await page.locator('#log-canvas').scrollIntoViewIfNeeded();
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-bags-done.png') });

  // The maps: binary PGMs of the size the replay reports, byte for byte alike.
  const first = await downloaded(page, '#log-map-downloads [data-file="pgm"]');
  assert.equal(first.name, 'mit-csail.pgm');
  const m = pgm(first.bytes);
  assert.deepEqual([m.width, m.height], [a.map.width, a.map.height]);
  assert.equal(m.pixels.length, m.width * m.height);
  assert.ok(m.pixels.filter((v) => v === 0).length > 2000, 'walls in the map');
  await page.selectOption('#log-map-of', 'mit-csail-zstd');
  const second = await downloaded(page, '#log-map-downloads [data-file="pgm"]');
  assert.equal(second.name, 'mit-csail-zstd.pgm');
  assert.ok(second.bytes.equals(first.bytes), 'the two maps are the same bytes');
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your log: the Stage bag has no odometry and a ground truth; the error over time and the ATE are shown, as run-log reports them', { timeout: 600000 }, async () => {
  const bag = path.join(BAGS, 'other/cupoch-Mapping1.bag');
  const { context, page, problems } = await newPage(env.browser, { width: 1280, height: 1000 });
  await openLogView(page);
  await page.setInputFiles('#log-file', bag);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 1, null, { timeout: 120000 });
  const picks = await picksShown(page, 'cupoch-Mapping1.bag');
  assert.equal(picks.scan.text, '/base_scan');
  assert.equal(picks.odom.text, 'none: scan matching alone');
  assert.match(picks.odom.why, /^no Odometry topic and no moving transform to the laser's base: scan matching alone/);
  assert.equal(picks.truth.text, '/base_pose_ground_truth');
  assert.equal(picks.truth.why, 'a pose topic named as ground truth');
  const options = await card(page, 'cupoch-Mapping1.bag').locator('select[data-pick="odom"] option').allInnerTexts();
  assert.deepEqual(options, ['none: scan matching alone'], 'no odometry to pick');

  await playToEnd(page);
  const snap = await logSnapshot(page);
  const truth = snap.robots[0].truth;
  assert.equal(truth.errors.length, 2 * 1727, 'an error for every scan');
  assert.ok(Number.isFinite(truth.ate_m) && truth.ate_m > 0 && truth.ate_m < 2, `ATE ${truth.ate_m} m`);
  // The same ATE as the command line's run-log on the same bag.
  const cli = JSON.parse(execFileSync('node', [path.join(ROOT, 'web/cli.mjs'), 'run-log', bag, '--json'], { maxBuffer: 1 << 28 }).toString());
  assert.ok(Math.abs(truth.ate_m - cli.ate_m) < 1e-3, `page ATE ${truth.ate_m} m, run-log ${cli.ate_m} m`);
  assert.equal(await page.locator('#log-truth').isVisible(), true, 'the error plot is shown');
  assert.equal(await page.locator('#log-truth-key').isVisible(), true, 'the legend names the ground truth');
  assert.equal(await page.locator('#log-odom-key').isHidden(), true, 'no odometry to name in the legend');
  assert.match(await page.locator('#log-ate').innerText(), new RegExp(`^cupoch-Mapping1: ATE ${truth.ate_m.toFixed(3)} m \\(dashed\\) over 1727 scans; now \\d+\\.\\d{3} m$`));
  // The plot has drawn the error line in the robot's colour.
  const coloured = await page.locator('#log-error').evaluate((c, colour) => {
    const [r, g, b] = [1, 3, 5].map((i) => parseInt(colour.slice(i, i + 2), 16));
    const px = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < px.length; i += 4) if (Math.abs(px[i] - r) < 30 && Math.abs(px[i + 1] - g) < 30 && Math.abs(px[i + 2] - b) < 30) n++;
    return n;
  }, snap.robots[0].colour);
  assert.ok(coloured > 500, `${coloured} pixels of the error line`);
  // The map with the truth beside SLAM's path, and the error plot under it, in one picture.
  await page.locator('#log-truth').evaluate((e) => e.scrollIntoView({ block: 'end' }));
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-bags-truth.png') });

  // Ground truth picked away: no plot, no legend entry; picked back: both again.
  await card(page, 'cupoch-Mapping1.bag').locator('select[data-pick="truth"]').selectOption('none');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().bags[0]?.truthHidden === true, null, { timeout: 60000 });
  await page.waitForFunction(() => document.querySelector('#log-truth').hidden);
  assert.equal(await page.locator('#log-truth-key').isHidden(), true);
  assert.equal((await picksShown(page, 'cupoch-Mapping1.bag')).truth.why, 'picked by you: the ground truth is not drawn');
  await card(page, 'cupoch-Mapping1.bag').locator('select[data-pick="truth"]').selectOption('topic:/base_pose_ground_truth');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().bags[0]?.truthHidden === false, null, { timeout: 60000 });
  await page.getByRole('button', { name: 'Step', exact: true }).click();
  await page.waitForFunction(() => {
    const r = window.slamlab.logView.snapshot().robots[0];
    return r.done > 0 && r.truth?.errors.length === 2 * r.done;
  }, null, { timeout: 60000 });
  assert.equal(await page.locator('#log-truth').isVisible(), true);
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

/**
 * How many pixels of a PNG (`png`, a Buffer: a screenshot) are within
 * `tol` of the colour `hex` (#rrggbb) in each channel; decoded in the page.
 */
function colourPixels(page, png, hex, tol = 40) {
  return page.evaluate(async ({ b64, hex, tol }) => {
    const bitmap = await createImageBitmap(await (await fetch(`data:image/png;base64,${b64}`)).blob());
    const c = new OffscreenCanvas(bitmap.width, bitmap.height);
    const ctx = c.getContext('2d');
    ctx.drawImage(bitmap, 0, 0);
    const px = ctx.getImageData(0, 0, c.width, c.height).data;
    const [r, g, b] = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16));
    let n = 0;
    for (let i = 0; i < px.length; i += 4) if (Math.abs(px[i] - r) <= tol && Math.abs(px[i + 1] - g) <= tol && Math.abs(px[i + 2] - b) <= tol) n++;
    return n;
  }, { b64: png.toString('base64'), hex, tol });
}

/**
 * The relation figures the page shows, one a robot: its text and data
 * attributes, and apart (`check`: text and data attributes, or null) the
 * relations checked against their scans, shown once a replay is finished.
 */
const relationFigures = (page) =>
  page.locator('#log-rel-figures li').evaluateAll((lis) => lis.map((li) => {
    const c = li.querySelector('.rel-check');
    const text = [...li.childNodes].filter((n) => n !== c && n.nodeName !== 'BR').map((n) => n.textContent).join('');
    return { text, ...li.dataset, check: c ? { text: c.textContent, ...c.dataset } : null };
  }));

test('your log: a bag dropped with its .relations file shows the relation errors run-log reports, plots them and draws the worst on the map; a malformed file is named with its line', { timeout: 600000 }, async () => {
  const bag = path.join(BAGS, 'freiburg/mit-csail.bag');
  const relations = path.join(BAGS, 'freiburg/mit-csail.relations');
  const report = JSON.parse(execFileSync('node', [path.join(ROOT, 'web/cli.mjs'), 'run-log', bag, '--relations', relations, '--check-relations', '--json'], { maxBuffer: 1 << 28 }).toString());
  const cli = report.relations;
  const t0 = report.scans[0].time; // the bag's first scan: the plot's time starts there
  assert.deepEqual([cli.matched, cli.count], [1172, 1172]);

  const { context, page, problems } = await newPage(env.browser, { width: 1280, height: 1500 });
  await openLogView(page);
  await drop(page, [bag, relations]);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots[0]?.relations, null, { timeout: 120000 });
  assert.equal(await page.locator('#log-message').isHidden(), true, 'no message');
  assert.equal(await page.locator('#log-relations').isVisible(), true);
  assert.match(await page.locator('#log-relations p').innerText(), /^A relation \(Kümmerle et al\. 2009\) is the pose of one scan seen from another, matched by the benchmark's authors and checked by hand\./);
  let [fig] = await relationFigures(page);
  assert.equal(fig.text, 'mit-csail: matched 0 of 1,172 relations of mit-csail.relations (so far, on the 0 of 1,988 scans replayed); translation 0.0000 ± 0.0000 m (max 0.0000 m), rotation 0.00 ± 0.00° (max 0.00°)');
  const magentaOnMap = async () => colourPixels(page, await page.locator('#log-canvas').screenshot(), '#e6007e');
  assert.equal(await magentaOnMap(), 0, 'no worst relation drawn before a scan is replayed');
  assert.equal(await page.locator('#log-rel-key').isHidden(), true);

  // Played to the end: the figures grow as the scans are replayed (read every 50 ms).
  await page.evaluate(() => {
    window.matchedSeen = [];
    const tick = () => {
      const li = document.querySelector('#log-rel-figures li');
      if (li) window.matchedSeen.push(Number(li.dataset.matched));
      if (!window.slamlab.logView.snapshot().finished) setTimeout(tick, 50);
    };
    tick();
  });
  await playToEnd(page);
  const seen = await page.evaluate(() => window.matchedSeen);
  const between = [...new Set(seen)].filter((n) => n > 0 && n < 1172);
  assert.ok(between.length >= 3, `the figures were shown at ${between.length} counts between none and all: ${between}`);
  assert.deepEqual(seen, [...seen].sort((a, b) => a - b), 'matched only grows');

  // The end: the same figures as run-log, shown to 4 decimals (translation) and 2 (rotation).
  [fig] = await relationFigures(page);
  const [t, r] = [cli.trans_m, cli.rot_deg];
  assert.equal(
    fig.text,
    `mit-csail: matched 1,172 of 1,172 relations of mit-csail.relations; translation ${t.mean.toFixed(4)} ± ${t.sd.toFixed(4)} m (max ${t.max.toFixed(4)} m), ` +
      `rotation ${r.mean.toFixed(2)} ± ${r.sd.toFixed(2)}° (max ${r.max.toFixed(2)}°)`,
  );
  assert.equal(Number(fig.transMean).toFixed(4), t.mean.toFixed(4));
  assert.deepEqual([fig.matched, fig.count], ['1172', '1172']);
  // Finished: the relations checked against their own scans and the wheels, as run-log --check-relations.
  const c = report.relation_check;
  assert.ok(fig.check, 'the check is shown once the replay is finished');
  assert.deepEqual([fig.check.settled, fig.check.byScans, fig.check.byOdometry], [c.settled, c.by_scans, c.by_odometry].map(String));
  assert.equal(
    fig.check.text,
    `Checked against their own scans: the scans settle ${c.settled.toLocaleString('en')} of 1,172 relations and contradict ${c.by_scans}. ` +
      `Where the scans settle a pose, the relations lie ${c.relations_vs_scans.trans_m.toFixed(4)} m and ${c.relations_vs_scans.rot_deg.toFixed(2)}° from it, ` +
      `this robot ${c.ours_vs_scans.trans_m.toFixed(4)} m and ${c.ours_vs_scans.rot_deg.toFixed(2)}°. ` +
      `Against the ${c.uncontradicted.toLocaleString('en')} relations neither contradicts: translation ${c.trans_m.mean.toFixed(4)} ± ${c.trans_m.sd.toFixed(4)} m, ` +
      `rotation ${c.rot_deg.mean.toFixed(2)} ± ${c.rot_deg.sd.toFixed(2)}°.`,
  );
  assert.ok(Number(fig.check.oursRot) < Number(fig.check.relationsRot), 'nearer the scans than the relations are');
  await page.locator('#log-relations').screenshot({ path: path.join(ARTIFACTS, 'page-bags-relation-check.png') });
  const page5 = await page.evaluate(() => {
    const q = window.slamlab.logView.snapshot().robots[0].relations;
    return { trans: q.trans_m, rot: q.rot_deg, worst: q.worst, errors: [...q.errors] };
  });
  console.log(`mit-csail relations: page ${page5.trans.mean} m, ${page5.rot.mean}°; run-log ${t.mean} m, ${r.mean}°`);
  assert.ok(Math.abs(page5.trans.mean - t.mean) < 1e-9 && Math.abs(page5.rot.mean - r.mean) < 1e-7, 'the page scores as run-log does');

  // The plot: a point a relation (x: the later scan's time since the first scan), in the robot's
  // colour; the five worst ringed in magenta.
  assert.equal(await page.locator('#log-rel-plot').getAttribute('data-points'), '1172');
  assert.equal(page5.errors.length, 2 * 1172);
  const times = page5.errors.filter((_, i) => i % 2 === 0);
  assert.ok(Math.min(...times) >= 0 && Math.max(...times) <= 424.1, `times ${Math.min(...times)}..${Math.max(...times)} s within the bag's 424 s`);
  const last = cli.errors[1171];
  assert.ok(Math.abs(page5.errors[2 * 1172 - 2] - (Math.max(last.t1, last.t2) - t0)) < 1e-6, 'the last point is at the last relation\'s later scan');
  assert.ok(Math.abs(page5.errors[2 * 1172 - 1] - last.trans_m) < 1e-9, 'the last point is the last relation\'s error');
  const plot = await page.locator('#log-rel-plot').screenshot();
  const colour = (await logSnapshot(page)).robots[0].colour;
  const dots = await colourPixels(page, plot, colour);
  assert.ok(dots > 1500, `${dots} pixels of the relations' points`);
  assert.ok((await colourPixels(page, plot, '#e6007e')) > 100, 'the worst ringed on the plot');

  // The worst relations: the table lists run-log's five worst; the map draws them.
  const rows = await page.locator('#log-rel-worst tbody tr').evaluateAll((trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
  assert.deepEqual(rows, cli.worst.slice(0, 5).map((w, k) => [String(k + 1), 'mit-csail', String(w.t1), String(w.t2), (Math.max(w.t1, w.t2) - t0).toFixed(1), w.trans_m.toFixed(4), w.rot_deg.toFixed(2)]));
  assert.equal(await page.locator('#log-rel-key').isVisible(), true, 'the legend names the worst relations');
  const drawn = await magentaOnMap();
  assert.ok(drawn > 300, `${drawn} pixels of the worst relations on the map`);
  // Pointing at the first row with the mouse marks it, and leaving it unmarks it.
  const first = page.locator('#log-rel-worst tbody tr').first();
  await first.hover();
  await page.waitForFunction(() => document.querySelector('#log-rel-worst tbody tr.on'));
  await page.mouse.move(5, 5);
  await page.waitForFunction(() => !document.querySelector('#log-rel-worst tbody tr.on'));
  // Pointed at (here focused: a screenshot of the map, which fills the
  // screen, scrolls the page from under a mouse), that one is drawn
  // stronger and the others fainter.
  await first.focus();
  await page.waitForFunction(() => document.querySelector('#log-rel-worst tbody tr.on'));
  await page.waitForTimeout(300);
  const pointed = await magentaOnMap();
  assert.ok(Math.abs(pointed - drawn) > 50, `pointed at: ${pointed} magenta pixels, not ${drawn}`);
  await page.locator('#log-canvas').scrollIntoViewIfNeeded();
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-bags-relations.png'), fullPage: true });
  await first.evaluate((tr) => tr.blur());
  await page.waitForFunction(() => !document.querySelector('#log-rel-worst tbody tr.on'));
  // Focused by the keyboard: the same.
  await page.locator('#log-rel-worst tbody tr').nth(1).focus();
  await page.waitForFunction(() => document.querySelector('#log-rel-worst tbody tr.on')?.dataset.k === '1');

  // A relations file malformed on its third line: named with it; the one in use stays.
  const broken = path.join(tmp, 'broken.relations');
  writeFileSync(broken, `${cli.worst[0].t1} ${cli.worst[0].t2} 1 0 0 0 0 0\n# a comment\n1 2 3\n`);
  await drop(page, [broken]);
  await page.waitForFunction(() => !document.querySelector('#log-message').hidden, null, { timeout: 60000 });
  assert.equal(await page.locator('#log-message').innerText(), 'Relations not used: broken.relations: line 3: expected 8 numbers (t1 t2 x y z roll pitch yaw), found 3');
  // One named after no open log, with two logs open: refused by name.
  await drop(page, [path.join(BAGS, 'ros2/mit-csail-zstd.mcap')]);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 2, null, { timeout: 120000 });
  const stray = path.join(tmp, 'elsewhere.relations');
  writeFileSync(stray, readFileSync(relations));
  await drop(page, [stray]);
  await page.waitForFunction(() => /elsewhere/.test(document.querySelector('#log-message').textContent), null, { timeout: 60000 });
  assert.equal(
    await page.locator('#log-message').innerText(),
    'Relations not used: elsewhere.relations: no open log or bag is called elsewhere (open: mit-csail.bag, mit-csail-zstd.mcap); name it after its log (aces.relations goes with aces.bag), or pick or drop it together with that one log',
  );
  const figs = await relationFigures(page);
  assert.deepEqual(figs.map((f) => [f.robot, f.matched, f.count]), [['mit-csail', '1172', '1172']], 'the relations in use stay; the new robot has none');

  // Cut into two stretches: each scores the relations both of whose scans it replays, as
  // run-log --from/--to does; the others are named as outside the stretch.
  await page.locator('#log-cut').fill('2');
  await page.locator('#log-cut').dispatchEvent('change');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 4, null, { timeout: 60000 });
  await playToEnd(page);
  const cut = await relationFigures(page);
  assert.deepEqual(cut.map((f) => f.robot), ['mit-csail-1', 'mit-csail-2']);
  for (const [k, [from, to]] of [[0, 993], [994, 1987]].entries()) {
    const c = JSON.parse(execFileSync('node', [path.join(ROOT, 'web/cli.mjs'), 'run-log', bag, '--relations', relations, '--from', String(from), '--to', String(to), '--json'], { maxBuffer: 1 << 28 }).toString()).relations;
    assert.ok(c.matched > 100 && c.matched < 1172, `${c.matched} relations within records ${from}–${to}`);
    const m = c.matched.toLocaleString('en');
    const other = (1172 - c.matched).toLocaleString('en');
    assert.equal(
      cut[k].text,
      `mit-csail-${k + 1}: matched ${m} of 1,172 relations of mit-csail.relations (the other ${other} have a scan outside this stretch (records ${from}–${to}) and are not scored); ` +
        `translation ${c.trans_m.mean.toFixed(4)} ± ${c.trans_m.sd.toFixed(4)} m (max ${c.trans_m.max.toFixed(4)} m), rotation ${c.rot_deg.mean.toFixed(2)} ± ${c.rot_deg.sd.toFixed(2)}° (max ${c.rot_deg.max.toFixed(2)}°)`,
    );
  }
  assert.equal(await page.locator('#log-rel-worst tbody tr').count(), 10, 'five worst a stretch');
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your log: a pick switched (odometry to none) starts that robot again, the file not read again', { timeout: 300000 }, async () => {
  const { context, page, problems } = await newPage(env.browser, { width: 1280, height: 1000 });
  await openLogView(page);
  await drop(page, [path.join(BAGS, 'freiburg/mit-csail.bag')]);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 1, null, { timeout: 120000 });
  await page.locator('#log-speed').fill('20');
  await stepTo(page, 60);
  await page.evaluate(() => {
    // Any progress bar shown from here on would mean the bag was read again.
    window.readAgain = false;
    new MutationObserver(() => (window.readAgain ||= !document.querySelector('#log-reading').hidden)).observe(document.querySelector('#log-reading'), { attributes: true });
  });

  // The keyboard: focus the odometry select and move to its last option, "none".
  const odom = card(page, 'mit-csail.bag').locator('select[data-pick="odom"]');
  await odom.focus();
  await page.keyboard.press('End');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().bags[0]?.picks.odom_none === true, null, { timeout: 60000 });
  await page.waitForFunction(() => !window.slamlab.logView.snapshot().busy && !document.querySelector('#log-bags .busy'));
  const snap = await logSnapshot(page);
  assert.equal(snap.robots[0].done, 0, 'the replay starts again');
  assert.equal(snap.bags[0].picked.odometry, null);
  assert.match(await page.locator('#log-progress').innerText(), /^scan 0 of 1988 · 0 loop closures$/);
  const picks = await picksShown(page, 'mit-csail.bag');
  assert.equal(picks.odom.text, 'none: scan matching alone');
  assert.equal(picks.odom.why, 'picked by you: scan matching alone, from a constant-velocity prediction');
  assert.match(await card(page, 'mit-csail.bag').locator('.bag-topics').innerText(), /\/odom\tnav_msgs\/Odometry\t1,988\t\n/, '/odom is no longer used');

  // The new replay runs without odometry: its odometry path stays empty.
  await stepTo(page, 40);
  assert.equal(await page.evaluate(() => window.readAgain), false, 'the bag was not read again');

  // And back with the mouse: /odom again.
  await odom.selectOption('topic:/odom');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().bags[0]?.picked.odometry === '/odom', null, { timeout: 60000 });
  assert.equal((await picksShown(page, 'mit-csail.bag')).odom.why, "the bag's only Odometry topic not named as ground truth");
  assert.equal((await logSnapshot(page)).robots[0].done, 0);

  // Cut into two stretches, the bag is two robots; a pick remakes both, still two.
  await page.locator('#log-cut').fill('2');
  await page.locator('#log-cut').dispatchEvent('change');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 2, null, { timeout: 60000 });
  await stepTo(page, 40);
  await odom.selectOption('none');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().bags[0]?.picks.odom_none === true, null, { timeout: 60000 });
  const cut = await logSnapshot(page);
  assert.deepEqual(cut.robots.map((r) => [r.name, r.from, r.to, r.done]), [['mit-csail-1', 0, 993, 0], ['mit-csail-2', 994, 1987, 0]]);
  assert.equal(await page.evaluate(() => window.readAgain), false, 'the bag was not read again');
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

test('your log: a bag cut short opens with what was lost, random bytes named x.bag are refused by name, a rosbag2 folder is one bag; nothing open is lost', { timeout: 300000 }, async () => {
  const cut = path.join(tmp, 'cut.bag');
  writeFileSync(cut, readFileSync(path.join(BAGS, 'freiburg/mit-csail.bag')).subarray(0, 300000));
  const junk = path.join(tmp, 'x.bag');
  const bytes = Buffer.alloc(4096);
  for (let i = 0, s = 7; i < bytes.length; i++) bytes[i] = (s = (s * 1103515245 + 12345) >>> 0) >>> 24;
  writeFileSync(junk, bytes);
  const { context, page, problems } = await newPage(env.browser, { width: 1280, height: 1000 });
  await openLogView(page);
  // A good robot first, stepped once.
  await drop(page, [path.join(BAGS, 'ros2/mit-csail-zstd.mcap')]);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 1, null, { timeout: 120000 });
  await page.getByRole('button', { name: 'Step', exact: true }).click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().done === 5, null, { timeout: 60000 });

  await drop(page, [cut, junk]);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 2, null, { timeout: 120000 });
  const message = await page.locator('#log-message').innerText();
  assert.match(message, /^Not opened: x\.bag: not a ROS bag: neither a ROS 1 bag \(#ROSBAG V2\.0\), an MCAP file nor a rosbag2 SQLite file; it starts with "/);
  assert.equal(await page.locator('#log-message').getAttribute('class'), 'real-message error');
  const lost = await card(page, 'cut.bag').locator('.bag-lost').innerText();
  assert.match(lost, /^Read only in part: what was complete is replayed\. Lost: cut\.bag: the file ends inside chunk 3 at byte 244,595 \(it has 55,405 of its 115,664 bytes\): the messages of that chunk are lost$/);
  let snap = await logSnapshot(page);
  assert.deepEqual(snap.robots.map((r) => [r.name, r.done, r.total]), [['mit-csail-zstd', 5, 1988], ['cut', 0, 639]]);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-bags-lost.png') });

  // A rosbag2 folder's files dropped together: one bag, one robot; a
  // metadata.yaml alone names the files it lacks.
  const folder = path.join(BAGS, 'ros2/mit-csail-db3');
  await drop(page, [path.join(folder, 'metadata.yaml'), path.join(folder, 'mit-csail-db3.db3')]);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 3, null, { timeout: 120000 });
  snap = await logSnapshot(page);
  assert.deepEqual(snap.robots.map((r) => [r.name, r.done, r.total]), [['mit-csail-zstd', 5, 1988], ['cut', 0, 639], ['mit-csail-db3', 0, 1988]]);
  assert.match(await card(page, 'mit-csail-db3').locator('p.real-stage').innerText(), /^rosbag2 SQLite, uncompressed, 5\.58 MB: 5,966 messages over 424\.0 s; 1,988 scans to replay$/);
  assert.equal(await page.locator('#log-message').isHidden(), true, 'the old message is gone');
  const lonely = path.join(tmp, 'metadata.yaml');
  writeFileSync(lonely, readFileSync(path.join(folder, 'metadata.yaml')));
  await drop(page, [lonely]);
  await page.waitForFunction(() => /Not opened/.test(document.querySelector('#log-message').textContent), null, { timeout: 60000 });
  assert.match(await page.locator('#log-message').innerText(), /^Not opened: metadata\.yaml: it lists mit-csail-db3\.db3; pick or drop the folder's data files together with it$/);
  assert.equal((await logSnapshot(page)).robots.length, 3, 'the robots stay');

  // Play on: the good robots go on from where they were.
  await page.getByRole('button', { name: 'Step', exact: true }).click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().done === 20, null, { timeout: 60000 });
  assert.deepEqual((await logSnapshot(page)).robots.map((r) => r.done), [10, 5, 5]);
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});

/** Chromium's renderer processes (CDP `SystemInfo.getProcessInfo`): their pids. */
async function rendererPids(browser) {
  const cdp = await browser.newBrowserCDPSession();
  try {
    const { processInfo } = await cdp.send('SystemInfo.getProcessInfo');
    return processInfo.filter((p) => p.type === 'renderer').map((p) => p.id);
  } finally {
    await cdp.detach();
  }
}

/** A process's `{rss, peak}` in MB from /proc: VmRSS and VmHWM (its highest resident set so far); null once it has ended. */
function residentMb(pid) {
  try {
    const status = readFileSync(`/proc/${pid}/status`, 'utf8');
    const kb = (field) => Number(new RegExp(`${field}:\\s+(\\d+) kB`).exec(status)?.[1] ?? NaN);
    return { rss: kb('VmRSS') / 1024, peak: kb('VmHWM') / 1024 };
  } catch {
    return null;
  }
}

/**
 * Does process `pid` run a dedicated worker (a thread named
 * "DedicatedWorker…")? The log worker runs in its page's renderer process.
 */
function runsWorker(pid) {
  try {
    return readdirSync(`/proc/${pid}/task`).some((t) => {
      try {
        return readFileSync(`/proc/${pid}/task/${t}/comm`, 'utf8').startsWith('DedicatedWorker');
      } catch {
        return false;
      }
    });
  } catch {
    return false;
  }
}

test('your log: a 200 MB bag opens with a progress bar that moves, the tab staying under 600 MB', { timeout: 600000 }, async () => {
  // The hand-held Hokuyo bag (uncompressed ROS 1, 360 scans of 681 beams)
  // repeated into one MCAP of 200 MB: 198 copies, 71,280 scans.
  const source = readFileSync(path.join(BAGS, 'other/scan_tools-demo.bag'));
  const big = path.join(tmp, 'hokuyo-200mb.mcap');
  const made = writeRepeatedMcap(big, source, 198);
  assert.ok(made.bytes >= 200e6 && statSync(big).size === made.bytes, `${made.bytes} bytes`);
  assert.equal(made.messages, 71280);

  // Renderer processes are never shared between browser contexts: the tab's is one not there yet.
  const earlier = new Set(await rendererPids(env.browser));
  const { context, page, problems } = await newPage(env.browser, { width: 1280, height: 1000 });
  await openLogView(page);
  await page.evaluate(() => {
    // What a user sees of the progress bar: its value at every frame drawn.
    window.readingSeen = [];
    const box = document.querySelector('#log-reading');
    const bar = document.querySelector('#log-reading-bar');
    const tick = () => {
      if (!box.hidden) window.readingSeen.push({ value: bar.value, max: bar.max, text: box.innerText });
      requestAnimationFrame(tick);
    };
    tick();
  });
  // The tab's memory: the resident set of the renderer process that runs
  // the page and its log worker (both live in it), sampled every 50 ms
  // from /proc while the bag is read, and its kernel-kept peak (VmHWM).
  const highest = new Map(); // pid → the highest VmRSS sampled (MB)
  let sampling = true;
  const sampler = (async () => {
    while (sampling) {
      for (const pid of await rendererPids(env.browser)) {
        const m = residentMb(pid);
        if (m) highest.set(pid, Math.max(highest.get(pid) ?? 0, m.rss));
      }
      await new Promise((r) => setTimeout(r, 50));
    }
  })();
  const t0 = Date.now();
  await page.setInputFiles('#log-file', big);
  // A picture of the bar while it moves (what it showed is checked below, frame by frame).
  await page.waitForSelector('#log-reading:not([hidden])', { timeout: 60000 });
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-bags-reading.png') });
  await page.waitForFunction(() => document.querySelector('#log-bags .bag-card select'), null, { timeout: 300000, polling: 100 });
  const opened = (Date.now() - t0) / 1000;
  await page.getByRole('button', { name: 'Step', exact: true }).click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().done === 5, null, { timeout: 120000 });
  await page.waitForTimeout(500);
  sampling = false;
  await sampler;
  const tabs = (await rendererPids(env.browser)).filter((pid) => !earlier.has(pid) && runsWorker(pid));
  assert.equal(tabs.length, 1, `one new renderer process runs the log worker: ${tabs}`);
  const tab = residentMb(tabs[0]);
  const others = [...highest].filter(([pid]) => pid !== tabs[0]).map(([pid, mb]) => `${pid}: ${mb.toFixed(0)}`);
  const seen = await page.evaluate(() => window.readingSeen);
  console.log(
    `200 MB bag (${made.bytes} bytes, ${made.messages} scans): opened in ${opened.toFixed(1)} s; the tab's renderer (pid ${tabs[0]}) ` +
      `resident at most ${highest.get(tabs[0]).toFixed(0)} MB sampled, ${tab.rss.toFixed(0)} MB after, peak (VmHWM) ${tab.peak.toFixed(0)} MB; ` +
      `other renderers' highest (MB) ${others.join(', ') || 'none'}; ${seen.length} frames showed the progress bar`,
  );
  assert.ok(highest.get(tabs[0]) > 250, 'the sampling saw the bag read (the decoded scans alone are 194 MB)');
  assert.ok(tab.peak <= 600, `the tab's renderer process peaked at ${tab.peak.toFixed(0)} MB`);

  // The progress bar: the bag's name, and values between none and all, in order.
  assert.ok(seen.every((s) => /^Reading hokuyo-200mb\.mcap\s+\d+\.\d of 200\.4 MB$/.test(s.text)), seen[0]?.text);
  assert.ok(seen.every((s) => s.max === made.bytes));
  const middle = [...new Set(seen.map((s) => s.value))].filter((v) => v > 0 && v < made.bytes);
  assert.ok(middle.length >= 3, `the bar showed ${middle.length} values between 0 and the whole`);
  assert.deepEqual(seen.map((s) => s.value), seen.map((s) => s.value).sort((a, b) => a - b), 'the bar only moves on');

  // Opened: the topics and the picks shown.
  const picks = await picksShown(page, 'hokuyo-200mb.mcap');
  assert.deepEqual([picks.scan.text, picks.odom.text, picks.truth.text], ['/scan', 'none: scan matching alone', 'none']);
  assert.match(await card(page, 'hokuyo-200mb.mcap').locator('p.real-stage').innerText(), /^MCAP, uncompressed, 200\.4 MB: 71,280 messages over 7111\.2 s; 71,280 scans to replay$/);
  assert.match(await card(page, 'hokuyo-200mb.mcap').locator('.bag-topics tbody').innerText(), /^\/scan\tsensor_msgs\/LaserScan\t71,280\tscans$/);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-bags-large.png') });
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});
