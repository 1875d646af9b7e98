// "Your log": replay a CARMEN laser log in the page (issue 21, item 3).
//
// A view over the lab, like "Your maps": the user opens a log (.log, .clf,
// gzip or not; picker or drop) and replays it through the lab's log SLAM
// (scan matching, pose graph, loop closures) with Play, Pause, Step and a
// speed (scans per step), watching the map grow, the odometry's path
// beside SLAM's and the loop closures drawn as they are found; at the end
// the map is offered as ROS map_server PGM + YAML and PNG. The replay and
// all drawing run in a Web Worker (log-worker.js, log-draw.js): the page
// only sends requests and shows the counts, so it stays responsive.

import { WorkerClient } from './client.js';

const HTML = `
  <div class="real-head">
    <h1 id="log-title">Your log: replay a CARMEN laser log</h1>
    <button type="button" class="real-close" aria-label="Close your log and go back to the lab">Close</button>
  </div>
  <p class="real-note">Open a CARMEN log (<code>.log</code>, <code>.clf</code>, gzip-compressed or not: FLASER,
    ROBOTLASER1, ODOM records) and replay it through the lab's SLAM, as <code>node web/cli.mjs run-log</code> does.
    Dashed grey: the path the odometry believes; blue: SLAM's; orange: loop closures as they are found.</p>
  <div class="real-drop" tabindex="0" aria-label="Drop a log file here">
    <span>Drop a log here, or</span>
    <label class="button" for="log-file">Open log…</label>
    <input id="log-file" type="file" accept=".log,.clf,.gz,.txt" hidden>
    <span id="log-name" class="real-stage"></span>
  </div>
  <div id="log-message" class="real-message" role="alert" hidden></div>
  <div class="real-merge-row log-controls" role="group" aria-label="Replay">
    <button type="button" id="log-play" class="primary">Play</button>
    <button type="button" id="log-pause">Pause</button>
    <button type="button" id="log-step" title="One step of as many scans as the speed says">Step</button>
    <label for="log-speed">Speed</label>
    <input id="log-speed" type="range" min="1" max="40" value="5" aria-label="Scans per step">
    <output id="log-speed-value" for="log-speed">5 scans a step</output>
    <span id="log-progress" class="real-stage" aria-live="polite"></span>
  </div>
  <canvas id="log-canvas" class="real-overlay" aria-label="The map as it grows, the odometry and SLAM paths, and the loop closures"></canvas>
  <p class="real-legend"><span class="real-swatch" style="--c:#7a7a7a">odometry</span>
    <span class="real-swatch" style="--c:#1f5fbf">SLAM</span>
    <span class="real-swatch" style="--c:#e07b00">loop closure</span></p>
  <div class="real-downloads">
    <button type="button" data-file="pgm">Map PGM</button>
    <button type="button" data-file="yaml">Map YAML</button>
    <button type="button" data-file="png">Map PNG</button>
  </div>`;

export class LogView {
  /** `root`, `opener`: the view and its toolbar button; `download`; `covers` (cover.js). */
  constructor(root, opener, { download, covers }) {
    this.root = root;
    this.opener = opener;
    this.download = download;
    this.covers = covers;
    this.client = new WorkerClient(new URL('./log-worker.js', import.meta.url));
    this.state = { name: '', records: 0, done: 0, total: 0, closures: 0, left: 0, finished: false };
    this.playing = false;
    this.busy = false;
    this.files = null;
  }

  wire() {
    this.root.innerHTML = HTML;
    const q = (s) => this.root.querySelector(s);
    this.opener.addEventListener('click', () => this.toggle(true));
    q('.real-close').addEventListener('click', () => this.toggle(false));
    this.root.addEventListener('keydown', (e) => {
      if (e.key === 'Escape') this.toggle(false);
      e.stopPropagation(); // the lab's shortcuts stay with the lab
    });
    q('#log-file').addEventListener('change', (e) => {
      const f = e.target.files[0];
      e.target.value = '';
      if (f) this.open(f);
    });
    this.root.addEventListener('dragover', (e) => e.preventDefault());
    this.root.addEventListener('drop', (e) => {
      e.preventDefault();
      const f = e.dataTransfer?.files?.[0];
      if (f) this.open(f);
    });
    q('#log-play').addEventListener('click', () => this.play());
    q('#log-pause').addEventListener('click', () => this.pause());
    q('#log-step').addEventListener('click', () => this.stepOnce());
    q('#log-speed').addEventListener('input', () => this.showSpeed());
    for (const b of this.root.querySelectorAll('.real-downloads button')) {
      b.addEventListener('click', () => this.save(b.dataset.file));
    }
    new ResizeObserver(() => this.redraw()).observe(q('#log-canvas'));
    this.showSpeed();
    this.refresh();
  }

  toggle(open) {
    this.root.hidden = !open;
    this.opener.setAttribute('aria-expanded', String(open));
    this.covers.set(this, open);
    if (open) this.root.querySelector('.real-close').focus();
    else {
      this.pause();
      this.opener.focus();
    }
  }

  showSpeed() {
    const n = this.speed();
    this.root.querySelector('#log-speed-value').textContent = `${n} scan${n > 1 ? 's' : ''} a step`;
  }

  speed() {
    return Number(this.root.querySelector('#log-speed').value);
  }

  /** The canvas's size in device pixels; the canvas goes to the worker once. */
  size() {
    const canvas = this.root.querySelector('#log-canvas');
    if (this.canvasWorker !== this.client.worker || !this.client.worker) {
      this.client.start();
      const offscreen = canvas.transferControlToOffscreen();
      this.client.request({ type: 'canvas', canvas: offscreen }, [offscreen]);
      this.canvasWorker = this.client.worker;
    }
    const dpr = window.devicePixelRatio || 1;
    return {
      width: Math.max(1, Math.round(canvas.clientWidth * dpr)),
      height: Math.max(1, Math.round(canvas.clientHeight * dpr)),
      dpr,
    };
  }

  async open(file) {
    this.pause();
    this.say('', 'info');
    const bytes = await file.arrayBuffer();
    const size = this.size();
    try {
      const out = await this.client.request({ type: 'open', bytes }, [bytes]);
      this.state = { name: file.name, records: out.records, done: 0, total: out.records, closures: 0, left: out.records, finished: false };
      this.files = null;
      this.refresh();
      await this.client.request({ type: 'step', n: 0, size });
    } catch (e) {
      this.state = { ...this.state, name: '', records: 0, left: 0 };
      this.say(`${file.name}: ${e.message}`, 'error');
    }
    this.refresh();
  }

  /** One step of `speed` scans; at the end, settles the graph and offers the map. */
  async advance() {
    if (this.busy || !this.state.records || this.state.finished) return;
    this.busy = true;
    try {
      const out = await this.client.request({ type: 'step', n: this.speed(), size: this.size() });
      Object.assign(this.state, out);
      if (out.left === 0) await this.finish();
    } catch (e) {
      this.pause();
      this.say(e.message, 'error');
    } finally {
      this.busy = false;
    }
    this.refresh();
  }

  async finish() {
    const out = await this.client.request({ type: 'finish' });
    this.files = out.files;
    this.state.finished = true;
    this.state.closures = out.summary.closures;
    this.summary = out.summary;
    this.pause();
    await this.client.request({ type: 'step', n: 0, size: this.size() });
  }

  play() {
    if (!this.state.records || this.state.finished) return;
    this.playing = true;
    const loop = async () => {
      if (!this.playing) return;
      await this.advance();
      // The next step in a fresh task, after the page has drawn.
      if (this.playing) setTimeout(loop, 0);
    };
    loop();
    this.refresh();
  }

  pause() {
    this.playing = false;
    this.refresh();
  }

  stepOnce() {
    this.pause();
    this.advance();
  }

  redraw() {
    if (!this.state.records || this.root.hidden) return;
    this.client.request({ type: 'redraw', size: this.size() }).catch((e) => this.say(e.message, 'error'));
  }

  say(text, kind) {
    const m = this.root.querySelector('#log-message');
    m.textContent = text;
    m.className = `real-message ${kind}`;
    m.hidden = !text;
  }

  refresh() {
    const q = (s) => this.root.querySelector(s);
    const s = this.state;
    const can = s.records > 0 && !s.finished;
    q('#log-play').disabled = !can || this.playing;
    q('#log-pause').disabled = !this.playing;
    q('#log-step').disabled = !can || this.playing;
    q('#log-name').textContent = s.name ? `${s.name}: ${s.records} laser records` : '';
    const closures = `${s.closures} loop closure${s.closures === 1 ? '' : 's'}`;
    q('#log-progress').textContent = !s.records
      ? ''
      : s.finished
        ? `done: ${s.done} scans, ${closures}; map ${this.summary.map.width} × ${this.summary.map.height} cells`
        : `scan ${s.done} of ${s.total} · ${closures}`;
    for (const b of this.root.querySelectorAll('.real-downloads button')) b.disabled = !this.files;
  }

  save(kind) {
    if (!this.files) return;
    const base = (this.state.name.replace(/(\.gz)?$/i, '').replace(/\.[^.]*$/, '') || 'log').replace(/[^\w.-]+/g, '_');
    if (kind === 'pgm') this.download(`${base}.pgm`, this.files.pgm, 'image/x-portable-graymap');
    if (kind === 'png') this.download(`${base}.png`, this.files.png, 'image/png');
    if (kind === 'yaml') this.download(`${base}.yaml`, this.files.yaml.replace('log-map.pgm', `${base}.pgm`), 'application/yaml');
  }

  /** For tests and the console. */
  snapshot() {
    return { ...this.state, playing: this.playing, busy: this.busy, summary: this.summary ?? null };
  }
}
