// "Your log" with robots of two buildings (issue 55, item 1 for the log
// view): the robots' maps merge in pairs but not all into one, so the
// view lists the groups, as "Your maps" does (web/page/real/map-groups.js),
// and shows one group at a time: its transforms, its overlay (the legend
// names its robots) and its downloads.
//
// Two synthetic CARMEN logs (tests/support/synthetic-log.mjs): the hall
// and the six-sided lab, driven round one and a half and two times, each cut
// into two stretches, so four robots: hall-1 and hall-2 of one world,
// lab-1 and lab-2 of the other. Each robot's frame is its
// first scan, so the truth of the second robot's frame in the first's is
// T₀⁻¹ ∘ Tₖ of the true poses, k the second stretch's first record.
//
// Needs the wasm build in web/pkg (`./build.sh build`). Alone:
//   node --test tests/page-log-groups.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { ARTIFACTS, newPage, useBrowser, waitReady } from './support/browser.mjs';
import { ringLog } from './support/synthetic-log.mjs';

const env = useBrowser();
const tmp = mkdtempSync(path.join(tmpdir(), 'slamlab-page-log-groups-'));

/** `a⁻¹ ∘ b` for poses [x, y, theta]. */
function relative([ax, ay, at], [bx, by, bt]) {
  const c = Math.cos(at), s = Math.sin(at);
  return [c * (bx - ax) + s * (by - ay), -s * (bx - ax) + c * (by - ay), bt - at];
}

const wrap = (a) => Math.atan2(Math.sin(a), Math.cos(a));

/** The PGM header's width and height, and the count of wall (black) pixels. */
function pgmSize(bytes) {
  const m = /^P5\n(?:#[^\n]*\n)*(\d+) (\d+)\n255\n/.exec(bytes.subarray(0, 200).toString('latin1'));
  assert.ok(m, 'a binary PGM header');
  const [w, h] = [Number(m[1]), Number(m[2])];
  assert.equal(bytes.length, m[0].length + w * h, 'the PGM holds its header and w x h bytes');
  return { w, h, walls: bytes.subarray(m[0].length).filter((v) => v === 0).length };
}

test('your log: robots of two buildings merge into two groups, each with its own tab, transform, overlay and downloads', { timeout: 600000 }, async () => {
  const hall = ringLog({ laps: 1.5, perLap: 140, world: 'hall' });
  // Two laps of the lab: cut in two, each robot maps the whole room (the
  // lab has little wall, and a half lap each shares too little of it).
  const lab = ringLog({ laps: 2, perLap: 120, world: 'lab' });
  const hallFile = path.join(tmp, 'hall.log');
  const labFile = path.join(tmp, 'lab.log');
  writeFileSync(hallFile, hall.text);
  writeFileSync(labFile, lab.text);
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.getByRole('button', { name: 'Your log…' }).click();
  await page.waitForSelector('#logview:not([hidden])');
  await page.evaluate(() => {
    window.longTasks = [];
    new PerformanceObserver((list) => window.longTasks.push(...list.getEntries().map((e) => e.duration))).observe({ type: 'longtask' });
  });
  await page.setInputFiles('#log-file', [hallFile, labFile]);
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 2, null, { timeout: 60000 });
  await page.locator('#log-cut').fill('2');
  await page.locator('#log-cut').dispatchEvent('change');
  await page.waitForFunction(() => window.slamlab.logView.snapshot().robots.length === 4, null, { timeout: 60000 });
  const robots = (await page.evaluate(() => window.slamlab.logView.snapshot())).robots;
  assert.deepEqual(robots.map((r) => [r.name, r.from]), [['hall-1', 0], ['hall-2', 105], ['lab-1', 0], ['lab-2', 120]]);

  // Merge maps replays the rest of every robot, then merges the four maps.
  await page.locator('#log-merge').click();
  await page.waitForFunction(() => window.slamlab.logView.snapshot().merge, null, { timeout: 500000, polling: 250 });
  await page.waitForTimeout(500);
  const tasks = await page.evaluate(() => window.longTasks);
  assert.ok(Math.max(0, ...tasks) <= 100, `long tasks while replaying and merging: ${tasks.map(Math.round).join(', ')} ms`);
  const merge = (await page.evaluate(() => window.slamlab.logView.snapshot())).merge.merge;
  const joined = merge.groups.filter((g) => g.maps.length > 1).map((g) => g.maps);
  assert.deepEqual(joined, [['hall-1.yaml', 'hall-2.yaml'], ['lab-1.yaml', 'lab-2.yaml']], JSON.stringify(merge.groups));

  // The verdict names both groups in robots' names, never "No merge".
  const verdict = await page.locator('#log-verdict').innerText();
  assert.match(verdict, /^Merged into 2 groups that share no wall with each other: hall-1 \+ hall-2; lab-1 \+ lab-2\.$/);
  assert.doesNotMatch(verdict, /No merge|\.yaml/);
  assert.match(await page.locator('#log-groups').innerText(), /Group 1: hall-1 \+ hall-2 \(confidence \d\.\d\d\)\s+Group 2: lab-1 \+ lab-2/);
  const tabs = page.locator('#log-groups [role="tab"]');
  assert.deepEqual(await tabs.allInnerTexts(), ['Group 1: 2 maps', 'Group 2: 2 maps']);

  /** The shown group's transform row of its second robot, checked against `truth`; its legend and title. */
  const checkGroup = async (first, second, truth) => {
    const caption = await page.locator('#log-transforms caption').innerText();
    assert.match(caption, new RegExp(`in the frame of ${first} \\(the reference\\)`));
    const rows = await page.locator('#log-transforms tr').allInnerTexts();
    const row = await page.locator('#log-transforms tr').nth(1).locator('td').allInnerTexts();
    assert.equal(row[0], second, rows.join(' | '));
    const [x, y, deg] = row.slice(1, 4).map(Number);
    const dist = Math.hypot(x - truth[0], y - truth[1]);
    const turn = Math.abs(wrap(((deg - (truth[2] * 180) / Math.PI) * Math.PI) / 180)) * (180 / Math.PI);
    console.log(`${second} in ${first}'s frame: [${x}, ${y}, ${deg}°], truth [${truth.map((v, i) => (i < 2 ? v : (wrap(v) * 180) / Math.PI).toFixed(3))}]: ${dist.toFixed(3)} m, ${turn.toFixed(2)}° off`);
    assert.ok(dist < 0.2, `${second} is ${dist} m off the truth`);
    assert.ok(turn < 1.5, `${second} is ${turn}° off the truth`);
    const other = first.startsWith('hall') ? ['lab-1', 'lab-2'] : ['hall-1', 'hall-2'];
    for (const o of other) assert.match(rows.join('\n'), new RegExp(`${o}\\s+–\\s+–\\s+–\\s+in another group`));
    // The overlay's legend names this group's robots, and only them.
    await page.waitForFunction((names) => document.querySelector('#log-legend').dataset.names === names, `${first}\n${second}`);
    const legend = await page.locator('#log-legend label').allInnerTexts();
    assert.deepEqual(legend.map((s) => s.trim()), [first, second]);
    assert.match(await page.locator('#log-overlay-title').innerText(), new RegExp(`of group \\d: ${first} \\+ ${second}$`));
  };
  const download = async (selector) => {
    const [d] = await Promise.all([page.waitForEvent('download'), page.locator(selector).click()]);
    return { name: d.suggestedFilename(), bytes: readFileSync(await d.path()) };
  };

  await page.evaluate(() => document.querySelector('#log-verdict').scrollIntoView({ block: 'start' }));
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-log-groups.png') });

  // Group 1 (the hall) is shown first.
  assert.equal(await tabs.nth(0).getAttribute('aria-selected'), 'true');
  await checkGroup('hall-1', 'hall-2', relative(hall.truth[0], hall.truth[105]));
  const hallPgm = await download('#log-downloads [data-file="pgm"]');
  assert.equal(hallPgm.name, 'merged-group-1.pgm');
  const hallSize = pgmSize(hallPgm.bytes);
  // The hall is about 17 x 12 m, turned into hall-1's frame and drawn at
  // 0.05 m a cell with a margin: each side between 12 m and twice 17 m.
  console.log(`group 1 merged map ${hallSize.w} x ${hallSize.h}, ${hallSize.walls} wall pixels`);
  const plausible = ({ w, h }, small, large) => [w, h].every((n) => n >= small / 0.05 && n <= (2 * large) / 0.05);
  assert.ok(plausible(hallSize, 12, 17), `hall merged ${hallSize.w} x ${hallSize.h}`);
  assert.ok(hallSize.walls > 500, 'walls in the hall merged map');
  const hallJson = JSON.parse((await download('#log-downloads [data-file="json"]')).bytes.toString('utf8'));
  assert.deepEqual(hallJson.transforms.map((t) => t.map), ['hall-1.yaml', 'hall-2.yaml']);
  assert.equal(hallJson.group, 1);
  await page.locator('#log-overlay').scrollIntoViewIfNeeded();
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-log-groups-1.png') });

  // Group 2 (the lab), picked with the mouse.
  await tabs.nth(1).click();
  assert.equal(await tabs.nth(1).getAttribute('aria-selected'), 'true');
  await checkGroup('lab-1', 'lab-2', relative(lab.truth[0], lab.truth[120]));
  const labPgm = await download('#log-downloads [data-file="pgm"]');
  assert.equal(labPgm.name, 'merged-group-2.pgm');
  const labSize = pgmSize(labPgm.bytes);
  // The lab is 13 x 8.5 m, and has less wall than the hall.
  console.log(`group 2 merged map ${labSize.w} x ${labSize.h}, ${labSize.walls} wall pixels`);
  assert.ok(plausible(labSize, 8.5, 13), `lab merged ${labSize.w} x ${labSize.h}`);
  assert.ok(labSize.walls < hallSize.walls, `lab ${labSize.walls} wall pixels, hall ${hallSize.walls}`);
  assert.ok(labSize.walls > 500, 'walls in the lab merged map');
  assert.notDeepEqual([labSize.w, labSize.h], [hallSize.w, hallSize.h], 'each group has its own merged map');
  assert.equal((await download('#log-downloads [data-file="yaml"]')).bytes.toString('utf8').match(/image: "?([^"\n]+)/)[1], 'merged-group-2.pgm');
  assert.equal((await download('#log-downloads [data-file="png"]')).name, 'merged-group-2.png');
  const labJson = JSON.parse((await download('#log-downloads [data-file="json"]')).bytes.toString('utf8'));
  assert.deepEqual(labJson.transforms.map((t) => t.map), ['lab-1.yaml', 'lab-2.yaml']);
  await page.locator('#log-overlay').scrollIntoViewIfNeeded();
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-log-groups-2.png') });

  // The arrow key goes back to group 1.
  await tabs.nth(1).focus();
  await page.keyboard.press('ArrowLeft');
  assert.equal(await tabs.nth(0).getAttribute('aria-selected'), 'true');
  await checkGroup('hall-1', 'hall-2', relative(hall.truth[0], hall.truth[105]));
  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});
