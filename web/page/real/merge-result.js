// A merge's result as the page shows it, wherever maps are merged in a
// worker: "Your maps" (panel.js, saved ROS maps) and "Your log"
// (log-merge-view.js, the robots' log maps). The same parts in both: the
// verdict with its reason and confidence, each map's frame in the first
// map's frame (metres, degrees, and the arguments of ROS's
// static_transform_publisher), each pair's own verdict, the joined maps
// overlaid in their colours (drawn by the worker into a canvas handed over
// once, report.js has the words) and the downloads. Element ids start
// with the view's prefix (`real`, `log`): `${p}-result`, `${p}-verdict`,
// `${p}-transforms`, `${p}-pairs`, `${p}-alpha`, `${p}-overlay`,
// `${p}-legend`, `${p}-downloads`, and `${p}-groups` (maps of several
// buildings: one group of maps shown at a time, map-groups.js).

import { joinedGroups, transformRows, transformsJson, unverifiedMaps, verdictText } from './report.js';

/**
 * The Merge maps row (`#${p}-merge`, a busy dot, the stage line `#stage`,
 * the button's `tip`) and the result under it (`resultHtml`).
 */
export function mergeHtml(p, { stage, tip = '', ...words }) {
  return `
  <div class="real-merge-row">
    <button type="button" id="${p}-merge" class="primary"${tip ? ` title="${tip}"` : ''}>Merge maps</button>
    <span class="real-busy" aria-hidden="true"></span>
    <span id="${stage}" class="real-stage" aria-live="polite"></span>
  </div>${resultHtml(p, words)}`;
}

/**
 * The result's HTML: `p` the id prefix; `words`: `{frames}` (the
 * transforms table's caption), `{title}` (the overlay's heading),
 * `{overlay}` (the canvas's label), `{extra}` (HTML put between the tables
 * and the overlay, e.g. "Place a map by hand").
 */
export function resultHtml(p, { frames, title, overlay, extra = '' }) {
  return `
  <div id="${p}-result" class="real-result" hidden>
    <p id="${p}-verdict" class="real-verdict"></p>
    <div id="${p}-groups" class="real-groups" hidden></div>
    <table id="${p}-transforms" class="summary-table"><caption>${frames}</caption></table>
    <table id="${p}-pairs" class="summary-table"><caption>Each pair's own verdict</caption></table>${extra}
    <div class="real-overlay-head">
      <h2 id="${p}-overlay-title">${title}</h2>
      <label for="${p}-alpha">Opacity</label>
      <input id="${p}-alpha" type="range" min="15" max="100" value="85" aria-label="Opacity of the maps in the overlay">
    </div>
    <canvas id="${p}-overlay" class="real-overlay" aria-label="${overlay}"></canvas>
    <p id="${p}-legend" class="real-legend"></p>
    <p id="${p}-unverified" class="real-unverified-note" hidden>These files join a map where you placed it: the merge's tests did not verify it.</p>
    <div id="${p}-downloads" class="real-downloads">
      <button type="button" data-file="pgm">Merged map PGM</button>
      <button type="button" data-file="yaml">Merged map YAML</button>
      <button type="button" data-file="png">Merged map PNG</button>
      <button type="button" data-file="json">Transforms JSON</button>
    </div>
  </div>`;
}

/**
 * Fills the verdict and the two tables of a merge (`merge`: the report's
 * `merge`); `name(map)` is how a map is called in them, `what` the first
 * column's heading; `group`: with maps of several buildings, the group
 * (an entry of `merge.groups`) whose transforms the table shows, `groups`
 * whether the view lists the groups (the verdict then names them). Enables
 * the downloads there are files for.
 */
export function showMerge(root, p, merge, hasFiles, { name = (m) => m, what = 'map', group = null, groups = false } = {}) {
  const q = (s) => root.querySelector(s);
  q(`#${p}-result`).hidden = false;
  const v = q(`#${p}-verdict`);
  v.textContent = verdictText(merge, name, groups);
  const shown = group ? { ...merge, transforms: group.transforms } : merge;
  const verified = (group ?? merge).verified !== false;
  const joined = groups && joinedGroups(merge).length > 0;
  v.className = `real-verdict ${!verified ? 'unverified' : merge.status === 'merged' || joined ? 'ok' : 'no'}`;
  const unsure = unverifiedMaps(shown);
  const rows = transformRows(shown).map((r) => [name(r.map) + (unsure.has(r.map) ? ' (placed by hand, not verified)' : ''), r.x, r.y, r.deg, r.args]);
  const others = group ? (merge.groups ?? []).flatMap((g) => (g === group ? [] : g.maps)) : merge.unjoined;
  for (const m of others) rows.push([name(m), '–', '–', '–', group ? 'in another group' : 'not joined']);
  const table = q(`#${p}-transforms`);
  const reference = shown.transforms[0]?.map;
  table.querySelector('caption').textContent = reference === undefined
    ? `No ${what} joined another`
    : `Each ${what}'s frame in the frame of ${name(reference)} (the reference)${verified ? '' : ', with your placement, not verified'}`;
  fillTable(table, [what, 'x (m)', 'y (m)', 'θ (°)', 'static_transform_publisher'], rows);
  fillTable(
    q(`#${p}-pairs`),
    ['pair', 'verdict', 'confidence', 'reason'],
    merge.pairs.map((r) => [`${name(r.a)} + ${name(r.b)}`, r.status === 'merged' ? 'merged' : 'not merged', r.confidence.toFixed(2), r.reason]),
  );
  for (const b of root.querySelectorAll(`#${p}-downloads button`)) {
    b.disabled = b.dataset.file !== 'json' && !hasFiles;
    b.textContent = b.textContent.replace(/ \(not verified\)$/, '') + (verified ? '' : ' (not verified)');
  }
  const note = q(`#${p}-unverified`);
  if (note) note.hidden = verified;
}

/**
 * Downloads `kind` of a merge: the merged map's `pgm`, `yaml`, `png`, or
 * the transforms' `json`; `files.stem` names them (`merged`, or
 * `merged-group-2` for a group), `group` the group the JSON is of.
 */
export function saveMerge(download, report, files, kind, group = -1) {
  const stem = files?.stem ?? 'merged';
  if (kind === 'json' && report) {
    download(stem === 'merged' ? 'transforms.json' : `transforms-${stem.slice('merged-'.length)}.json`, transformsJson(report, group), 'application/json');
    return;
  }
  if (!files) return;
  if (kind === 'pgm') download(`${stem}.pgm`, files.pgm, 'image/x-portable-graymap');
  if (kind === 'png') download(`${stem}.png`, files.png, 'image/png');
  if (kind === 'yaml') download(`${stem}.yaml`, files.yaml, 'application/yaml');
}

/**
 * The overlay canvas of a view, drawn by its worker: `root`, `p` (the id
 * prefix), `client` (the worker's), `types`: the worker's requests that
 * take the canvas (`canvas`) and draw into it (`draw`). One drawing at a
 * time: a slider's many events make one more at most.
 */
export class OverlayCanvas {
  constructor(root, p, client, types = { canvas: 'canvas', draw: 'draw' }) {
    Object.assign(this, { root, p, client, types });
    this.drawing = false;
    this.again = false;
    this.resizes = null;
  }

  /** Redraws when the canvas changes size (`draw`: the view's redraw). */
  watch(draw) {
    this.resizes = new ResizeObserver(draw);
    this.resizes.observe(this.canvas());
  }

  canvas() {
    return this.root.querySelector(`#${this.p}-overlay`);
  }

  /** Asks the worker to draw; `onError(e)` if it fails, `onDrawn(answer)` when drawn. */
  draw(onError = () => {}, onDrawn = () => {}) {
    if (this.drawing) {
      this.again = true;
      return;
    }
    const canvas = this.attach();
    const dpr = window.devicePixelRatio || 1;
    const size = {
      width: Math.max(1, Math.round(canvas.clientWidth * dpr)),
      height: Math.max(1, Math.round(canvas.clientHeight * dpr)),
      dpr,
      alpha: this.root.querySelector(`#${this.p}-alpha`).value / 100,
      // The user's zoom (zoom.js) and the maps unticked, when the view offers them.
      zoom: this.zoom?.toJSON() ?? null,
      hidden: this.hidden?.() ?? [],
    };
    this.drawing = true;
    this.client
      .request({ type: this.types.draw, ...size })
      .then(onDrawn)
      .catch(onError)
      .finally(() => {
        this.drawing = false;
        if (this.again) {
          this.again = false;
          this.draw(onError, onDrawn);
        }
      });
  }

  /** Hands the canvas to the worker (once per worker); returns the canvas. */
  attach() {
    let canvas = this.canvas();
    if (this.worker === this.client.worker && this.client.worker) return canvas;
    this.client.start();
    if (this.worker) {
      // A restarted worker needs a canvas of its own: control moves once.
      const fresh = canvas.cloneNode();
      canvas.replaceWith(fresh);
      this.resizes?.observe(fresh);
      canvas = fresh;
    }
    const offscreen = canvas.transferControlToOffscreen();
    this.client.request({ type: this.types.canvas, canvas: offscreen }, [offscreen]);
    this.worker = this.client.worker;
    return canvas;
  }
}

/** A colour swatch with a name (the overlay's legend). */
export function swatch(colour, name) {
  const s = document.createElement('span');
  s.className = 'real-swatch';
  s.style.setProperty('--c', colour);
  s.textContent = name;
  return s;
}

/** Fills `table` (keeping its caption) with a heading row and rows of text cells. */
export function fillTable(table, head, rows) {
  const caption = table.querySelector('caption');
  const tr = (cells, tag) => {
    const r = document.createElement('tr');
    for (const c of cells) {
      const td = document.createElement(tag);
      td.textContent = c;
      r.append(td);
    }
    return r;
  };
  table.replaceChildren(caption, tr(head, 'th'), ...rows.map((r) => tr(r, 'td')));
}
