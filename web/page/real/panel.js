// "Your maps": merge saved ROS map_server maps in the page (issue 20).
//
// A view over the lab (like the summary) where a user opens two to sixteen
// saved maps — each YAML with its PGM or PNG image, picked together
// or dropped, or an image alone at a typed resolution — sees each one,
// merges them automatically and reads the verdict with its reason and
// confidence, each map's transform (metres, degrees, and the arguments of
// ROS's static_transform_publisher) and each pair's verdict, sees the
// joined maps overlaid in their colours, and downloads the merged map (PGM
// + YAML + PNG) and the transforms (JSON); maps of several buildings form
// groups, each with its own transforms, overlay and downloads
// (map-groups.js); a pair the merge declined can be placed by hand and
// refined (adjust.js). The reading, drawing and merging
// run in a Web Worker (merge-worker.js), so the page stays responsive; the
// lab's own scenario and runs behind this view are never touched.

import { ADJUST_HTML, PlaceByHand } from './adjust.js';
import { mapCard } from './card.js';
import { scaleHintText } from './scale-probe.js';
import { SavedMapsClient } from './client.js';
import { MapGroupsView, showsGroups } from './map-groups.js';
import { OverlayCanvas, mergeHtml, saveMerge, showMerge, swatch } from './merge-result.js';
import { attachZoom, Zoom } from './zoom.js';

/** One colour per map (up to 16), told apart on white. */
export const MAP_COLOURS = [
  '#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf', '#8c564b', '#e377c2',
  '#7f7f7f', '#bcbd22', '#393b79', '#ad494a', '#637939', '#7b4173', '#843c39', '#3182bd',
];

const HTML = `
  <div class="real-head">
    <h1 id="real-title">Your maps: merge saved ROS maps</h1>
    <button type="button" class="real-close" aria-label="Close your maps and go back to the lab">Close</button>
  </div>
  <p class="real-note">Open two to sixteen ROS <code>map_server</code> maps, each a YAML with the PGM or PNG image it
    names (pick or drop them together), or a ROS bag (<code>.bag</code>, <code>.mcap</code>, <code>.db3</code>) whose
    <code>/map</code> topic holds a robot's map (its last <code>nav_msgs/OccupancyGrid</code>). The lab merges them with the same automatic merge as
    <code>node web/cli.mjs merge-maps</code>, off the page's main thread. Your scenario and runs stay as they are.</p>
  <div class="real-drop" tabindex="0" aria-label="Drop map files here">
    <span>Drop map files here, or</span>
    <label class="button primary" for="real-files">Open maps…</label>
    <input id="real-files" type="file" multiple accept=".yaml,.yml,.pgm,.png,.bag,.mcap,.db3" hidden>
    <label for="real-resolution" title="For an image picked without a YAML">Resolution of an image without YAML</label>
    <input id="real-resolution" type="number" min="0.001" step="0.01" value="0.05" class="num"><span class="unit">m</span>
    <button type="button" id="real-clear">Clear maps</button>
  </div>
  <div id="real-message" class="real-message" role="alert" hidden></div>
  <div id="real-maps" class="real-maps" aria-label="The maps you opened"></div>${mergeHtml('real', {
    stage: 'real-stage',
    frames: "Each map's frame in the first map's frame",
    title: 'Merged overlay',
    overlay: 'The joined maps overlaid in their colours',
    extra: ADJUST_HTML,
  })}`;

export class SavedMapsView {
  /**
   * `root`: the view's element; `opener`: the toolbar button;
   * `download(name, data, type)`; `covers`: the views over the lab (cover.js).
   */
  constructor(root, opener, { download, covers }) {
    this.root = root;
    this.covers = covers;
    this.opener = opener;
    this.download = download;
    this.maps = [];
    this.report = null;
    this.files = null;
    /** Each group's merged map files (null for a map alone), and the group shown. */
    this.groupFiles = [];
    this.group = -1;
    this.busy = false;
    this.queue = Promise.resolve();
    this.client = new SavedMapsClient((text) => this.progress(text));
    this.overlay = new OverlayCanvas(root, 'real', this.client);
    this.adjust = new PlaceByHand(root, this.client, {
      maps: () => this.maps,
      report: () => this.report,
      refined: (out) => {
        this.report = out.report;
        this.groupFiles = out.groupFiles ?? [];
        this.showResult();
      },
      say: (text, kind) => this.say(text, kind),
      busy: (on, text) => this.setBusy(on, text),
      changed: () => this.legend(),
    });
  }

  /** Builds the view and connects its controls. */
  wire() {
    const root = this.root;
    root.innerHTML = HTML;
    this.adjust.wire();
    const q = (s) => root.querySelector(s);
    this.groups = new MapGroupsView(q('#real-groups'), {
      select: (k) => this.showGroup(k),
      colour: (name) => this.maps.find((m) => m.name === name)?.colour ?? '#111',
    });
    this.opener.addEventListener('click', () => this.toggle(true));
    q('.real-close').addEventListener('click', () => this.toggle(false));
    root.addEventListener('keydown', (e) => {
      if (e.key === 'Escape') this.toggle(false);
      e.stopPropagation(); // the lab's shortcuts stay with the lab
    });
    q('#real-files').addEventListener('change', (e) => {
      this.open([...e.target.files]);
      e.target.value = '';
    });
    root.addEventListener('dragover', (e) => {
      e.preventDefault();
      q('.real-drop').classList.add('over');
    });
    root.addEventListener('dragleave', () => q('.real-drop').classList.remove('over'));
    root.addEventListener('drop', (e) => {
      e.preventDefault();
      q('.real-drop').classList.remove('over');
      this.open([...(e.dataTransfer?.files ?? [])]);
    });
    q('#real-clear').addEventListener('click', () => this.enqueue(() => this.clear()));
    q('#real-merge').addEventListener('click', () => this.enqueue(() => this.merge()));
    q('#real-alpha').addEventListener('input', () => this.drawOverlay());
    for (const b of root.querySelectorAll('#real-downloads button')) {
      b.addEventListener('click', () => this.save(b.dataset.file));
    }
    this.overlay.watch(() => this.drawOverlay());
    this.zoomable(q('#real-overlay'));
    this.refresh();
  }

  /**
   * The merged overlay zooms with the wheel or a pinch and pans by a drag
   * (zoom.js), but not while a map is placed by hand (its drags move the
   * map); Reset view fits it again; a map unticked in the legend is hidden.
   */
  zoomable(canvas) {
    const zoom = (this.overlay.zoom = new Zoom());
    const reset = Object.assign(document.createElement('button'), { type: 'button', id: 'real-view-reset', textContent: 'Reset view', disabled: true });
    this.root.querySelector('#real-alpha').after(reset);
    const changed = () => {
      reset.disabled = zoom.isIdentity();
      this.drawOverlay();
    };
    reset.addEventListener('click', () => {
      zoom.reset();
      changed();
    });
    attachZoom(canvas, zoom, changed, { active: () => !this.adjust.active });
    this.overlay.hidden = () => [...this.root.querySelectorAll('#real-legend input:not(:checked)')].map((c) => c.dataset.map);
    this.root.querySelector('#real-legend').addEventListener('change', () => this.drawOverlay());
  }

  toggle(open) {
    this.root.hidden = !open;
    // The lab behind is kept as it is, but not painted nor animated while covered.
    this.covers.set(this, open);
    this.opener.setAttribute('aria-expanded', String(open));
    if (open) this.root.querySelector('.real-close').focus();
    else this.opener.focus();
    if (open) this.drawOverlay();
  }

  /** Runs `job` after whatever is under way (picks, merges) has finished. */
  enqueue(job) {
    this.queue = this.queue.then(job).catch((e) => this.say(e.message, 'error'));
    return this.queue;
  }

  /** Opens picked or dropped files: adds their maps, then merges if two or more. */
  open(files) {
    if (!files.length) return this.queue;
    return this.enqueue(async () => {
      performance.mark('real-open');
      this.attachCanvas();
      const read = await Promise.all(files.map(async (f) => ({ name: f.name, bytes: await f.arrayBuffer() })));
      const resolution = this.root.querySelector('#real-resolution').value;
      this.setBusy(true, `reading ${files.length} file${files.length > 1 ? 's' : ''}…`);
      let out;
      try {
        out = await this.client.add(read, resolution, MAP_COLOURS);
      } finally {
        this.setBusy(false, '');
      }
      performance.mark('real-added');
      const replaced = this.place(out.added);
      if (out.added.length) this.dropResult();
      const again = replaced.length ? ` Opened again, in place of the one open: ${replaced.join(', ')}.` : '';
      const one = this.maps.length === 1
        ? ` One map is open: open one more (or several) to merge it with, the map of another robot or another run of the same building.`
        : '';
      if (out.errors.length) this.say(`Not opened: ${out.errors.join(' · ')}${again}${one}`, 'error');
      else this.say(`Opened ${out.added.map((m) => m.name).join(', ')}.${again}${one}`, one ? 'info' : 'ok');
      this.refresh();
      performance.mark('real-listed');
      if (out.added.length && this.maps.length >= 2) {
        await nextFrame();
        await this.merge();
      }
    });
  }

  /** Puts maps the worker read into the list: a map named as one open takes its place. Returns the names replaced. */
  place(added) {
    const replaced = [];
    for (const m of added) {
      const at = this.maps.findIndex((o) => o.name === m.name);
      if (at < 0) {
        this.maps.push(m);
        continue;
      }
      this.maps[at] = m;
      replaced.push(m.name);
    }
    return replaced;
  }

  /**
   * Reads image-only map `name` again at `resolution`, with every image
   * read at the same assumed resolution (opened together, most likely
   * from one robot), and merges again.
   */
  reread(name, resolution) {
    return this.enqueue(async () => {
      const assumed = this.maps.find((m) => m.name === name)?.assumed;
      const names = this.maps.filter((m) => m.name === name || (assumed && m.assumed === assumed)).map((m) => m.name);
      this.setBusy(true, `reading ${names.join(', ')} again at ${resolution} m per cell…`);
      const read = [];
      try {
        for (const n of names) read.push((await this.client.reread(n, resolution)).map);
      } finally {
        this.setBusy(false, '');
      }
      this.place(read);
      this.dropResult();
      this.say(`Read ${names.join(', ')} again at ${read[0].resolution} m per cell.`, 'ok');
      this.refresh(true);
      if (this.maps.length >= 2) {
        await nextFrame();
        await this.merge();
      }
    });
  }

  async clear() {
    await this.client.clear();
    this.maps = [];
    this.dropResult();
    this.say('', 'info');
    this.refresh();
  }

  async merge() {
    if (this.maps.length < 2) {
      this.say('Open two or more maps to merge them.', 'warn');
      return;
    }
    if (this.adjust.active || this.adjust.kept) await this.adjust.stop();
    const n = this.maps.length;
    const t0 = performance.now();
    // Nothing ticks or animates while it runs: the page's main thread stays
    // idle until the worker answers (a progress line comes after each pair).
    this.setBusy(true, `merging ${n} maps (${(n * (n - 1)) / 2} pair${n > 2 ? 's' : ''})…`);
    let out;
    try {
      out = await this.client.merge();
    } finally {
      this.setBusy(false, '');
    }
    performance.mark('real-merged');
    this.report = out.report;
    this.groupFiles = out.groupFiles ?? [];
    this.mergeMs = performance.now() - t0;
    this.stage(`merged in ${(this.mergeMs / 1000).toFixed(2)} s (the merge itself ${(out.report.timings_ms.merge / 1000).toFixed(2)} s)`);
    await nextFrame();
    this.showResult();
    performance.mark('real-shown');
    if (this.maps.some((m) => m.assumed)) this.scaleHints(out.report);
  }

  /** After a merge with images at an assumed resolution: says which merge at another (measured). */
  async scaleHints(report) {
    const { hints } = await this.client.scales();
    if (this.report !== report || !hints.length) return;
    this.say(hints.map(scaleHintText).join(' '), 'warn');
  }

  progress(text) {
    this.stage(text);
  }

  stage(text) {
    this.root.querySelector('#real-stage').textContent = text;
  }

  say(text, kind) {
    const m = this.root.querySelector('#real-message');
    m.textContent = text;
    m.className = `real-message ${kind}`;
    m.hidden = !text;
  }

  setBusy(busy, text) {
    this.busy = busy;
    this.root.classList.toggle('busy', busy);
    this.stage(text);
    this.refresh();
  }

  dropResult() {
    this.adjust.active = null;
    this.adjust.kept = null;
    this.report = null;
    this.files = null;
    this.groupFiles = [];
    this.group = -1;
    this.groups?.hide();
    this.root.querySelector('#real-result').hidden = true;
    this.stage('');
  }

  /** The map cards and the state of the buttons (`cards`: build the list again). */
  refresh(cards = false) {
    const q = (s) => this.root.querySelector(s);
    q('#real-merge').disabled = this.busy || this.maps.length < 2;
    q('#real-clear').disabled = this.busy || this.maps.length === 0;
    const list = q('#real-maps');
    const shown = [...list.children];
    if (!cards && shown.length === this.maps.length && this.maps.every((m, i) => m.card === shown[i])) return;
    list.replaceChildren(...this.maps.map((m) => (m.card ??= mapCard(m, (name, r) => this.reread(name, r)))));
  }

  showResult() {
    this.group = this.groups.show(this.report.merge);
    this.showTables();
    this.adjust.show(this.report);
    // The overlay in a task of its own, after the tables are laid out.
    nextFrame().then(() => this.drawOverlay());
  }

  /** The verdict, the tables and the downloads of the group shown (all maps when one group). */
  showTables() {
    this.files = this.groupFiles[this.group] ?? null;
    const group = showsGroups(this.report.merge) ? this.report.merge.groups[this.group] : null;
    showMerge(this.root, 'real', this.report.merge, !!this.files, { group, groups: true });
  }

  /** Shows group `k`: its transforms, its downloads and its overlay. */
  async showGroup(k) {
    this.group = k;
    this.showTables();
    await this.client.showGroup(k);
    this.drawOverlay();
  }

  /** "Merged overlay", or with groups listed "Merged overlay of group 2: c + d" (its downloads below it). */
  overlayTitle() {
    const merge = this.report?.merge;
    if (!merge || !showsGroups(merge)) return 'Merged overlay';
    const joined = merge.groups.filter((g) => g.maps.length > 1);
    const g = merge.groups[this.group];
    return g ? `Merged overlay of group ${joined.indexOf(g) + 1}: ${g.maps.join(' + ')}` : 'Merged overlay';
  }

  /** The maps placed in the overlay: the group shown, else every joined map. */
  placedTransforms() {
    const merge = this.report.merge;
    return (showsGroups(merge) ? merge.groups[this.group]?.transforms : null) ?? merge.transforms;
  }

  /** The joined maps in the first map's frame, each in its colour: drawn by the worker (merge-result.js). */
  drawOverlay() {
    if (!this.report || this.root.hidden) return;
    this.overlay.draw(
      (e) => this.say(e.message, 'error'),
      (r) => {
        if ((this.adjust.active || this.adjust.kept) && r?.view) this.adjust.view = r.view;
      },
    );
    this.legend();
  }

  /** Hands the overlay canvas to the worker (once per worker); returns the canvas. */
  attachCanvas() {
    return this.overlay.attach();
  }

  legend() {
    const legend = this.root.querySelector('#real-legend');
    const placing = this.adjust.active, kept = this.adjust.kept;
    this.root.querySelector('#real-overlay-title').textContent = placing
      ? `Placing ${placing.b.name} by hand`
      : kept ? `Your placement of ${kept.b.name} (refused by Refine)`
        : this.report?.merge.verified === false ? 'Merged overlay (your placement, not verified)' : this.overlayTitle();
    if (placing) {
      legend.replaceChildren(swatch(placing.a.colour, placing.a.name), swatch(placing.b.colour, `${placing.b.name} (drag it)`));
      return;
    }
    if (kept) {
      legend.replaceChildren(swatch(kept.a.colour, kept.a.name), swatch(kept.b.colour, `${kept.b.name} where you put it`),
        kept.judged ? swatch('#c2410c', 'dashed: the refined overlay that was judged and refused') : '');
      return;
    }
    if (!this.report) return;
    const byName = new Map(this.maps.map((m) => [m.name, m]));
    const placed = this.placedTransforms().filter((t) => byName.has(t.map)).map((t) => ({ map: byName.get(t.map) }));
    const hidden = this.overlay.hidden?.() ?? [];
    legend.replaceChildren(
      ...placed.map(({ map }) => {
        const label = document.createElement('label');
        label.className = 'real-swatch';
        label.style.setProperty('--c', map.colour);
        const box = Object.assign(document.createElement('input'), { type: 'checkbox', checked: !hidden.includes(map.name) });
        box.dataset.map = map.name;
        label.append(box, ` ${map.name}`);
        return label;
      }),
      placed.length > 1 ? 'Walls of two maps that fall on each other show dark. Untick a map to hide it.' : '',
    );
  }

  save(kind) {
    saveMerge(this.download, this.report, this.files, kind, showsGroups(this.report.merge) ? this.group : -1);
  }

  /** For tests and the console: what the view holds. */
  snapshot() {
    return {
      maps: this.maps.map(({ name, width, height, resolution, origin }) => ({ name, width, height, resolution, origin })),
      report: this.report,
      group: this.group,
      mergeMs: this.mergeMs,
      busy: this.busy,
      adjust: this.adjust.snapshot(),
    };
  }
}

/** Resolves after the next frame has been drawn (work split into short tasks). */
export function nextFrame() {
  return new Promise((resolve) => requestAnimationFrame(() => setTimeout(resolve, 0)));
}
