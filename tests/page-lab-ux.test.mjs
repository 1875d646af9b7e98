// The simulated lab's panels as a new user meets them (issue 55), in
// headless Chromium driven by real mouse and key events
// (tests/support/browser.mjs):
//   - Guided step 3's pair view: the frames have room, its words sit under
//     them (never over them), the small map's labels keep apart, and the
//     status line follows the guide instead of running ahead of it; at
//     1366 × 768 and 1920 × 1080 (screenshots committed under docs/).
//
// Needs the wasm build in web/pkg (`./build.sh build`). Run alone with
//   node --test tests/page-lab-ux.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { ARTIFACTS, newPage, useBrowser, waitReady } from './support/browser.mjs';

const env = useBrowser();
const statusText = (page) => page.locator('#status').innerText();

/** Do two boxes `{x, y, width, height}` share any area? */
const intersects = (a, b) =>
  Math.min(a.x + a.width, b.x + b.width) > Math.max(a.x, b.x) && Math.min(a.y + a.height, b.y + b.height) > Math.max(a.y, b.y);

/** Waits until the guide's Next button can be pressed. */
const nextEnabled = (page, timeout = 120000) =>
  page.waitForFunction(() => document.querySelector('#guide-next')?.disabled === false, null, { timeout });

for (const viewport of [{ width: 1366, height: 768 }, { width: 1920, height: 1080 }]) {
  const size = `${viewport.width}x${viewport.height}`;
  test(`guided step 3 at ${size}: the pair view's words under its frames, the map's labels apart, the status line in step`, { timeout: 240000 }, async () => {
    const { context, page, problems } = await newPage(env.browser, viewport);
    await page.goto(env.baseUrl);
    await waitReady(page);

    // Step 1 as a user takes it: G opens the guide, its button loads the thesis and runs.
    await page.locator('#world').click({ position: { x: 5, y: 5 } });
    await page.keyboard.press('g');
    await page.getByRole('button', { name: 'Load the thesis map and run' }).click();
    await nextEnabled(page);
    const afterRun = await statusText(page);
    assert.match(afterRun, /^Guide, step 1 of 5/, `after the run the status line speaks for the guide: "${afterRun}"`);
    assert.doesNotMatch(afterRun, /Merge maps|merge the robots/i, 'it does not send the user to the Merge panel ahead of the guide');

    // Step 2 (selection), then step 3 (matching), with the Next button.
    await page.locator('#guide-next').click();
    await nextEnabled(page);
    await page.locator('#guide-next').click();
    await page.waitForFunction(() => document.querySelector('#guide-best-pair')?.disabled === false, null, { timeout: 120000 });
    await nextEnabled(page);
    const atStep3 = await statusText(page);
    assert.match(atStep3, /^Guide, step 3 of 5 \(§6\.2\.3 Image matching\)/, `status at step 3: "${atStep3}"`);
    assert.doesNotMatch(atStep3, /merged|no merge|wrong merge|waits for Next/i,
      'the status line does not announce the merge (step 5) or a stale step while the guide is at step 3');

    await page.getByRole('button', { name: 'Show the best pair\u2019s matches' }).click();
    await page.waitForSelector('#pair-overlay:not([hidden]) canvas.pair-map[data-labels]');
    const layout = await page.evaluate(() => {
      const box = (e) => {
        const r = e.getBoundingClientRect();
        return { x: r.x, y: r.y, width: r.width, height: r.height, what: `${e.tagName.toLowerCase()}.${e.className}` };
      };
      const o = document.querySelector('#pair-overlay');
      const map = o.querySelector('canvas.pair-map');
      return {
        overlay: box(o),
        side: box(document.querySelector('aside.side')),
        frames: box(o.querySelector('canvas.pair-canvas')),
        map: box(map),
        words: [...o.querySelectorAll('h2, p, figcaption, button')].map(box),
        labels: JSON.parse(map.dataset.labels),
        mapSize: [map.clientWidth, map.clientHeight],
      };
    });
    for (const w of layout.words) {
      for (const img of [layout.frames, layout.map]) {
        assert.ok(!intersects(w, img), `${w.what} ${JSON.stringify(w)} lies over ${img.what} ${JSON.stringify(img)}`);
      }
    }
    assert.ok(layout.frames.height >= 200, `the frames have room: ${layout.frames.height} px tall`);
    assert.ok(layout.overlay.x + layout.overlay.width <= layout.side.x,
      'the pair view leaves the side panel (the matched-pair table) in view');
    assert.ok(layout.overlay.y + layout.overlay.height <= viewport.height, 'the whole pair view is on screen');
    assert.equal(layout.labels.length, 2, 'one label a frame');
    for (const [x, y, w, h] of layout.labels) {
      assert.ok(x >= 0 && y >= 0 && x + w <= layout.mapSize[0] + 0.5 && y + h <= layout.mapSize[1] + 0.5,
        `label ${[x, y, w, h]} inside the ${layout.mapSize} map`);
    }
    const [a, b] = layout.labels.map(([x, y, width, height]) => ({ x, y, width, height }));
    assert.ok(!intersects(a, b), `the map's labels keep apart: ${JSON.stringify(layout.labels)}`);

    // docs/issue55-guided-step3-*.png are these, reduced to 256 colours.
    await page.screenshot({ path: path.join(ARTIFACTS, `issue55-guided-step3-${size}.png`) });
    await page.keyboard.press('Escape');
    assert.equal(await page.locator('#pair-overlay').isHidden(), true, 'Esc closes the pair view');

    assert.deepEqual(problems, [], 'no console errors or page errors');
    await context.close();
  });
}
