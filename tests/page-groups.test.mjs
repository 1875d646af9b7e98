// Issue 22 in the page: when the merge joins the robots into several
// groups, the Merge panel lists every group as the command line reports it,
// draws each group's merged map (tabs) in its robots' colours, offers each
// group's map for download, and says why a robot stays alone.
//
// Driven as a user: import tests/data/two-buildings.json (two buildings
// and a room, five robots: tests/data/README.md), run it at 50×, merge,
// pick each group's tab. The command line's report of the same scenario
// (`node web/cli.mjs run FILE --json`, run meanwhile) is the reference.
//
// Needs the wasm build in web/pkg (`./build.sh build`). Alone:
//   node --test tests/page-groups.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { readFile } from 'node:fs/promises';
import { ARTIFACTS, ROOT, newPage, useBrowser, waitReady } from './support/browser.mjs';
import { runCliAsync } from './support/cli.mjs';

const env = useBrowser();
const SCENARIO = path.join(ROOT, 'tests/data/two-buildings.json');

/** Pixels of `#merge-map` near each robot's colour (within 40 a channel), by robot index. */
function colourCounts(page) {
  return page.evaluate(async () => {
    const colours = JSON.parse((await import('/web/pkg/slamlab.js')).robotColours());
    const c = document.querySelector('#merge-map');
    const data = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    const counts = colours.map(() => 0);
    for (let p = 0; p < data.length; p += 4) {
      colours.forEach(([r, g, b], i) => {
        if (Math.abs(data[p] - r) <= 40 && Math.abs(data[p + 1] - g) <= 40 && Math.abs(data[p + 2] - b) <= 40) counts[i] += 1;
      });
    }
    return counts;
  });
}

test('several groups: the panel lists the CLI\u2019s groups, draws each group\u2019s map, says why a robot is alone', { timeout: 300000 }, async () => {
  const cli = runCliAsync('run', SCENARIO, '--json');
  const { context, page, problems } = await newPage(env.browser, { width: 1366, height: 768 });
  await page.goto(env.baseUrl);
  await waitReady(page);
  await page.setInputFiles('#import-file', SCENARIO);
  await page.waitForFunction(() => window.slamlab.scenario().name === 'two-buildings');
  await page.locator('#speed').fill('50');
  await page.getByRole('button', { name: 'Run', exact: true }).click();
  await page.waitForFunction(() => window.slamlab.state().finished, null, { timeout: 150000, polling: 250 });
  await page.selectOption('#merge-method', 'auto');
  await page.locator('#merge-run').click();
  await page.waitForFunction(() => document.querySelector('#merge-verdict')?.textContent.length > 0, null, { timeout: 150000, polling: 250 });

  // The same groups as the command line's report, in the same frames.
  const r = await cli;
  assert.equal(r.code, 0, r.stderr);
  const expected = JSON.parse(r.stdout).merge.groups;
  const view = await page.evaluate(() => JSON.parse(window.slamlab.lab.mergeViewJson()));
  assert.deepEqual(view.report.groups, expected);
  assert.deepEqual(expected.map((g) => g.robots), [['robot1', 'robot2'], ['robot3', 'robot4'], ['robot5']]);

  // The list says it in words: a line a group, the alone robot with its reason.
  const items = await page.locator('#merge-group-list li').allInnerTexts();
  assert.equal(items.length, expected.length);
  expected.forEach((g, k) => {
    if (g.robots.length > 1) assert.equal(items[k], `Group ${k + 1}: ${g.robots.join(', ')} \u2014 merged map`);
  });
  const why = expected[2].reason.replace(/^robot5 joined no other robot: /, '');
  assert.ok(why.length > 20 && items[2].startsWith('robot5 alone: '), items[2]);
  assert.ok(items[2].includes(why.slice(0, 40)), `the reason shown: ${items[2]}`);
  assert.match(await page.locator('#merge-groups').innerText(), /These robots form 3 groups that saw nothing in common/);
  assert.match(await page.locator('#status').innerText(), /^Maps merged in 2 groups \(robot1 \+ robot2; robot3 \+ robot4\); robot5 stays alone\./);

  // One tab per group with a merged map; each draws that group in its robots' colours only.
  const tabs = page.getByRole('tab');
  assert.deepEqual(await tabs.allInnerTexts(), ['Group 1 (2 robots)', 'Group 2 (2 robots)']);
  assert.equal(await tabs.first().getAttribute('aria-selected'), 'true');
  const groupColours = [[0, 1], [2, 3]];
  for (const k of [0, 1]) {
    await tabs.nth(k).click();
    assert.equal(await tabs.nth(k).getAttribute('aria-selected'), 'true');
    const counts = await colourCounts(page);
    for (let i = 0; i < 5; i++) {
      if (groupColours[k].includes(i)) assert.ok(counts[i] > 40, `group ${k + 1}'s map shows robot${i + 1}'s path: ${counts}`);
      // (a few anti-aliased pixels where two paths cross come near other colours: 6 seen)
      else assert.ok(counts[i] <= 10, `group ${k + 1}'s map has no robot${i + 1}: ${counts}`);
    }
    assert.deepEqual(await page.locator('#merge-map-legend').innerText().then((t) => t.split(/\s+/).filter(Boolean)),
      groupColours[k].map((i) => `robot${i + 1}`));
    const rows = await page.locator('#merge-transforms tr td:first-child').allInnerTexts();
    assert.deepEqual(rows, expected[k].robots);
  }
  // Group 2's transform table scores robot4 in robot3's frame: right, not flagged.
  assert.equal(await page.locator('#merge-transforms td.bad').count(), 0);
  assert.match(await page.locator('#merge-transforms caption').innerText(), /^Group 2: .*robot3’s/);
  await page.locator('.merge-panel').scrollIntoViewIfNeeded();
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-groups.png') });

  // Group 2's downloads: its own PGM and YAML names, a map of its own size.
  const got = [];
  page.on('download', (d) => got.push(d));
  await page.getByRole('button', { name: 'Group 2 ROS map (PGM + YAML)' }).click();
  for (let t = 0; t < 50 && got.length < 2; t++) await page.waitForTimeout(100);
  assert.deepEqual(got.map((d) => d.suggestedFilename()).sort(), ['merged-group2.pgm', 'merged-group2.yaml']);
  const yaml = await readFile(await got.find((d) => d.suggestedFilename().endsWith('.yaml')).path(), 'utf8');
  assert.match(yaml, /^image: "merged-group2\.pgm"\nresolution: /);
  const pgm = await readFile(await got.find((d) => d.suggestedFilename().endsWith('.pgm')).path());
  const m = /^P5\n(?:#[^\n]*\n)*(\d+) (\d+)\n255\n/.exec(pgm.subarray(0, 200).toString('latin1'));
  assert.ok(m, 'a binary PGM');
  assert.equal(pgm.length, m[0].length + Number(m[1]) * Number(m[2]));

  // "merged map" in the list shows that group; the arrow keys move between the tabs.
  await page.locator('#merge-group-list li[data-group="0"] button').click();
  assert.equal(await tabs.first().getAttribute('aria-selected'), 'true');
  assert.equal(await page.evaluate(() => document.activeElement.id), 'merge-group-tab-0');
  await page.keyboard.press('ArrowRight');
  assert.equal(await tabs.nth(1).getAttribute('aria-selected'), 'true');
  await page.keyboard.press('ArrowLeft');
  assert.equal(await tabs.first().getAttribute('aria-selected'), 'true');
  assert.equal(await page.evaluate(() => document.activeElement.id), 'merge-group-tab-0');

  // The Summary lists the groups and shows group 2's merged map.
  await page.getByRole('button', { name: 'Summary of the run, printable' }).click();
  await page.waitForFunction(() => !document.querySelector('#summary').hidden);
  const lines = await page.locator('.summary-groups li').allInnerTexts();
  assert.equal(lines.length, 3);
  assert.match(lines[1], /^Group 2: robot3, robot4 — merged map in robot3’s frame \(worst error 0\.\d{3} m against the ground truth\)$/);
  assert.ok(lines[2].startsWith(items[2]), lines[2]);
  assert.equal(await page.locator('#summary img[alt="The merged map of group 2"]').count(), 1);
  await page.keyboard.press('Escape');
  await page.waitForFunction(() => document.querySelector('#summary').hidden);

  // A phone-sized screen keeps the list and the map readable.
  await page.setViewportSize({ width: 390, height: 844 });
  await page.locator('#merge-groups').scrollIntoViewIfNeeded();
  await page.screenshot({ path: path.join(ARTIFACTS, 'page-groups-phone.png') });
  const overflow = await page.evaluate(() => document.querySelector('#merge-groups').scrollWidth - document.querySelector('#merge-groups').clientWidth);
  assert.ok(overflow <= 1, `the groups fit the panel's width (${overflow} px over)`);

  assert.deepEqual(problems, [], 'no console errors or page errors');
  await context.close();
});
