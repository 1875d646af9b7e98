// "Your maps": merge saved ROS map_server maps in the page (issue 20).
//
// A view over the lab (like the summary) where a user opens two to sixteen
// saved maps — each YAML with its PGM or PNG image, picked together
// or dropped, or an image alone at a typed resolution — sees each one,
// merges them automatically and reads the verdict with its reason and
// confidence, each map's transform (metres, degrees, and the arguments of
// ROS's static_transform_publisher) and each pair's verdict, sees the
// joined maps overlaid in their colours, and downloads the merged map (PGM
// + YAML + PNG) and the transforms (JSON); a pair the merge declined can be
// placed by hand and refined (adjust.js). The reading, drawing and merging
// run in a Web Worker (merge-worker.js), so the page stays responsive; the
// lab's own scenario and runs behind this view are never touched.

import { ADJUST_HTML, PlaceByHand } from './adjust.js';
import { SavedMapsClient } from './client.js';
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
    this.busy = false;
    this.queue = Promise.resolve();
    this.client = new SavedMapsClient((text) => this.progress(text));
    this.overlay = new OverlayCanvas(root, 'real', this.client);
    this.adjust = new PlaceByHand(root, this.client, {
      maps: () => this.maps,
      report: () => this.report,
      refined: (out) => {
        this.report = out.report;
        this.files = out.files;
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
      this.maps.push(...out.added);
      if (out.added.length) this.dropResult();
      if (out.errors.length) this.say(`Not opened: ${out.errors.join(' · ')}`, 'error');
      else this.say(`Opened ${out.added.map((m) => m.name).join(', ')}.`, 'ok');
      this.refresh();
      performance.mark('real-listed');
      if (out.added.length && this.maps.length >= 2) {
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
    if (this.adjust.active) await this.adjust.stop();
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
    this.files = out.files;
    this.mergeMs = performance.now() - t0;
    this.stage(`merged in ${(this.mergeMs / 1000).toFixed(2)} s (the merge itself ${(out.report.timings_ms.merge / 1000).toFixed(2)} s)`);
    await nextFrame();
    this.showResult();
    performance.mark('real-shown');
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
    this.report = null;
    this.files = null;
    this.root.querySelector('#real-result').hidden = true;
    this.stage('');
  }

  /** The map cards and the state of the buttons. */
  refresh() {
    const q = (s) => this.root.querySelector(s);
    q('#real-merge').disabled = this.busy || this.maps.length < 2;
    q('#real-clear').disabled = this.busy || this.maps.length === 0;
    const list = q('#real-maps');
    if (list.childElementCount === this.maps.length) return;
    list.replaceChildren(...this.maps.map((m) => (m.card ??= card(m))));
  }

  showResult() {
    showMerge(this.root, 'real', this.report.merge, !!this.files);
    this.adjust.show(this.report);
    // The overlay in a task of its own, after the tables are laid out.
    nextFrame().then(() => this.drawOverlay());
  }

  /** The joined maps in the first map's frame, each in its colour: drawn by the worker (merge-result.js). */
  drawOverlay() {
    if (!this.report || this.root.hidden) return;
    this.overlay.draw(
      (e) => this.say(e.message, 'error'),
      (r) => {
        if (this.adjust.active && r?.view) this.adjust.view = r.view;
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
    const placing = this.adjust.active;
    this.root.querySelector('#real-overlay-title').textContent = placing ? `Placing ${placing.b.name} by hand` : 'Merged overlay';
    if (placing) {
      legend.replaceChildren(swatch(placing.a.colour, placing.a.name), swatch(placing.b.colour, `${placing.b.name} (drag it)`));
      return;
    }
    if (!this.report) return;
    const byName = new Map(this.maps.map((m) => [m.name, m]));
    const placed = this.report.merge.transforms.filter((t) => byName.has(t.map)).map((t) => ({ map: byName.get(t.map) }));
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
    saveMerge(this.download, this.report, this.files, kind);
  }

  /** For tests and the console: what the view holds. */
  snapshot() {
    return {
      maps: this.maps.map(({ name, width, height, resolution, origin }) => ({ name, width, height, resolution, origin })),
      report: this.report,
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

/** One opened map: its picture, name, size and resolution. */
function card(m) {
  const div = document.createElement('figure');
  div.className = 'real-card';
  div.style.borderColor = m.colour;
  // The worker made the thumbnail at its shown size (a large canvas shrunk
  // by CSS would be shrunk again at every repaint of the page).
  const c = document.createElement('canvas');
  c.width = m.thumb.width;
  c.height = m.thumb.height;
  c.getContext('bitmaprenderer').transferFromImageBitmap(m.thumb);
  c.setAttribute('aria-label', `${m.name}, drawn in its colour`);
  const cap = document.createElement('figcaption');
  const o = m.origin.map((v) => Number(v.toFixed(3)));
  cap.innerHTML = `<b style="color:${m.colour}"></b><br>${m.width} × ${m.height} cells · ${m.resolution} m · origin [${o.join(', ')}]`;
  cap.querySelector('b').textContent = m.imageName === m.name ? m.name : `${m.name} + ${m.imageName}`;
  div.append(c, cap);
  return div;
}
