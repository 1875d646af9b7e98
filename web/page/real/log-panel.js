// "Your log": replay a CARMEN laser log or a ROS bag in the page (issue 21,
// item 3; issue 53, item 4).
//
// A view over the lab, like "Your maps": the user opens a log (.log, .clf,
// gzip or not) or a ROS bag (a ROS 1 .bag, an .mcap, a rosbag2 .db3 or
// folder), by the picker or a drop, and replays it through the lab's log SLAM
// (scan matching, pose graph, loop closures) with Play, Pause, Step (five
// scans) and a speed in × real time (the log's seconds per second),
// watching the map grow, the odometry's path beside SLAM's and the loop
// closures drawn as they are found; a timeline under the map (timeline.js)
// looks back at any moment replayed, drawn as the SLAM had it then, and
// Start over replays them again without opening the files; the map zooms
// and pans and its layers can be hidden (map-controls.js); at the end
// the map is offered as ROS map_server PGM + YAML and PNG. The replay and
// all drawing run in a Web Worker (log-worker.js, log-draw.js): the page
// only sends requests and shows the counts, so it stays responsive. A bag
// is read in the worker in pieces (bag-read.js), with a progress bar here;
// then its card (bag-picks.js) lists its topics and what the replay picked
// and why, with selects to pick others, and a bag's ground truth is drawn
// beside SLAM's path with the position error over time under the map
// (truth-plot.js). A benchmark's `.relations` file (Kümmerle et al. 2009)
// opened with a log or bag, or afterwards, goes with it (by name, or as
// the one log opened with it): its relation errors are shown as the
// replay goes, plotted along the run, and the worst drawn on the map
// (relations-view.js; the worker's side in log-relations.js).
//
// Several logs, or one log cut into N stretches of its laser records, are
// several robots (issue 21, item 3): each replayed on its own, in its own
// colour and tile, then **Merge maps** joins their finished maps with the
// saved-maps merge of `merge-maps` (log-merge.js, log-merge-view.js).

import { BagPicks } from './bag-picks.js';
import { WorkerClient } from './client.js';
import { droppedFiles, picked } from './dropped.js';
import { LogMergeView, MERGE_HTML } from './log-merge-view.js';
import { WORST_COLOUR } from './log-draw.js';
import { MAP_COLOURS } from './panel.js';
import { RELATIONS_HTML, RelationsView } from './relations-view.js';
import { MapControls, MAP_CONTROLS_HTML } from './map-controls.js';
import { Timeline, TIMELINE_HTML } from './timeline.js';
import { ErrorPlot } from './truth-plot.js';

/** Scans a press of Step replays. */
const STEP_SCANS = 5;
/** The longest wall-clock time one play step accounts for (s): a replay slower than asked does not run behind its clock. */
const MAX_TICK_S = 0.25;

const HTML = `
  <div class="real-head">
    <h1 id="log-title">Your log: replay a CARMEN laser log or a ROS bag</h1>
    <button type="button" class="real-close" aria-label="Close your log and go back to the lab">Close</button>
  </div>
  <p class="real-note">Open a CARMEN log (<code>.log</code>, <code>.clf</code>, gzip-compressed or not: FLASER,
    ROBOTLASER1, ODOM records) or a ROS bag (ROS 1 <code>.bag</code>, ROS 2 <code>.mcap</code> or <code>.db3</code>;
    a rosbag2 folder: drop the folder, or pick its <code>metadata.yaml</code> with its data files) and replay it
    through the lab's SLAM, as <code>node web/cli.mjs run-log</code> does. A bag's card lists its topics and what the
    replay uses and why; pick others there. Dashed grey: the path the odometry believes; in the robot's colour:
    SLAM's; dotted black: a bag's ground truth; orange: loop closures as they are found.
    Two or more logs or bags, or one cut into stretches, are as many robots: each replays on its own, then
    <b>Merge maps</b> joins their maps by the maps' own evidence, as <code>merge-maps</code> does.
    A benchmark's <code>.relations</code> file opened with its log (<code>aces.relations</code> with
    <code>aces.bag</code>) scores the replay against it, as <code>run-log --relations</code> does.</p>
  <div class="real-drop" tabindex="0" aria-label="Drop logs, bags, a rosbag2 folder or relations files here">
    <span>Drop logs, bags (with their <code>.relations</code>) or a rosbag2 folder here, or</span>
    <label class="button" for="log-file">Open log or bag…</label>
    <input id="log-file" type="file" multiple accept=".log,.clf,.gz,.txt,.bag,.mcap,.db3,.db3-wal,.yaml,.yml,.relations" hidden>
    <label for="log-cut" title="Each stretch of a log is replayed as a robot of its own">Cut each log into</label>
    <input id="log-cut" type="number" min="1" max="16" step="1" value="1" class="num"><span class="unit">stretches</span>
    <button type="button" id="log-clear">Clear logs</button>
    <span id="log-name" class="real-stage"></span>
  </div>
  <p id="log-robots" class="real-legend" aria-label="The robots"></p>
  <div id="log-message" class="real-message" role="alert" hidden></div>
  <div id="log-reading" class="bag-reading" role="status" hidden>
    <label for="log-reading-bar" id="log-reading-name"></label>
    <progress id="log-reading-bar" max="1" value="0"></progress>
    <span id="log-reading-bytes" class="real-stage"></span>
  </div>
  <div id="log-bags" class="bag-cards" hidden></div>
  <div class="real-merge-row log-controls" role="group" aria-label="Replay">
    <button type="button" id="log-play" class="primary">Play</button>
    <button type="button" id="log-pause">Pause</button>
    <button type="button" id="log-step" title="The next ${STEP_SCANS} scans">Step</button>
    <label for="log-speed">Speed</label>
    <input id="log-speed" type="range" min="1" max="100" value="10" aria-label="Speed, times real time">
    <output id="log-speed-value" for="log-speed">10× real time</output>
    <span id="log-progress" class="real-stage" aria-live="polite"></span>
  </div>
  ${MAP_CONTROLS_HTML}
  <canvas id="log-canvas" class="real-overlay" aria-label="The map as it grows, the odometry and SLAM paths, and the loop closures"></canvas>${TIMELINE_HTML}
  <p class="real-legend"><span id="log-odom-key" class="real-swatch" style="--c:#7a7a7a">odometry</span>
    <span class="real-swatch" style="--c:#1f77b4">SLAM (in the robot's colour)</span>
    <span class="real-swatch" style="--c:#e07b00">loop closure</span>
    <span id="log-truth-key" class="real-swatch" style="--c:#111" hidden>ground truth (dotted), laid onto SLAM's frame</span>
    <span id="log-rel-key" class="real-swatch" style="--c:${WORST_COLOUR}" hidden>worst relations: both scans' poses
      (rings, with their headings) joined, numbered as in the table below</span></p>
  <div id="log-truth" class="truth-plot" hidden>
    <h2>Position error against the ground truth</h2>
    <p class="real-stage">At each scan replayed: the distance from SLAM's pose to the true pose at the scan's time,
      the truth laid onto SLAM's path by the one rigid motion that fits them best. The ATE (absolute trajectory
      error) is its root mean square.</p>
    <div class="truth-row">
      <canvas id="log-error" aria-label="Each robot's position error against its bag's ground truth over time"></canvas>
      <ul id="log-ate" class="truth-ate" aria-label="Each robot's ATE"></ul>
    </div>
  </div>${RELATIONS_HTML}
  <div id="log-map-downloads" class="real-downloads">
    <label for="log-map-of" hidden>Map of</label>
    <select id="log-map-of" hidden></select>
    <button type="button" data-file="pgm">Map PGM</button>
    <button type="button" data-file="yaml">Map YAML</button>
    <button type="button" data-file="png">Map PNG</button>
  </div>${MERGE_HTML}`;

export class LogView {
  /** `root`, `opener`: the view and its toolbar button; `download`; `covers` (cover.js). */
  constructor(root, opener, { download, covers }) {
    Object.assign(this, { root, opener, download, covers });
    this.client = new WorkerClient(new URL('./log-worker.js', import.meta.url), (text, m) =>
      m.reading ? this.showReading(m.reading) : this.merged.stage(text),
    );
    this.merged = new LogMergeView(root, this.client, download);
    this.state = emptyState();
    this.playing = false;
    this.busy = false;
    this.files = null;
    this.queue = Promise.resolve();
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
      const files = [...e.target.files].map(picked);
      e.target.value = '';
      this.open(files);
    });
    this.root.addEventListener('dragover', (e) => e.preventDefault());
    this.root.addEventListener('drop', (e) => {
      e.preventDefault();
      this.open(droppedFiles(e.dataTransfer));
    });
    this.picks = new BagPicks(q('#log-bags'), (id, picks, truthHidden) => this.enqueue(() => this.repick(id, picks, truthHidden)));
    this.plot = new ErrorPlot(q('#log-truth'), q('#log-error'), q('#log-ate'));
    this.relations = new RelationsView(q('#log-relations'), (name, k) => this.highlight(name, k));
    q('#log-cut').addEventListener('change', () => this.enqueue(() => this.recut()));
    q('#log-clear').addEventListener('click', () => this.enqueue(() => this.clear()));
    q('#log-play').addEventListener('click', () => this.play());
    q('#log-pause').addEventListener('click', () => this.pause());
    q('#log-step').addEventListener('click', () => this.stepOnce());
    this.controls = new MapControls(this.root, q('#log-canvas'), () => this.redraw());
    this.timeline = new Timeline(this.root, { seek: (t) => this.seek(t), again: () => this.enqueue(() => this.again()) });
    q('#log-speed').addEventListener('input', () => this.showSpeed(this.timeline.pace(false)));
    q('#log-merge').addEventListener('click', () => this.enqueue(() => this.merge()));
    for (const b of this.root.querySelectorAll('#log-map-downloads button')) {
      b.addEventListener('click', () => this.save(b.dataset.file));
    }
    new ResizeObserver(() => this.redraw()).observe(q('#log-canvas'));
    new ResizeObserver(() => this.plot.show(this.state.robots ?? [])).observe(q('#log-error'));
    new ResizeObserver(() => this.relations.draw()).observe(q('#log-rel-plot'));
    this.merged.wire();
    this.showSpeed();
    this.refresh();
  }

  toggle(open) {
    this.root.hidden = !open;
    this.opener.setAttribute('aria-expanded', String(open));
    this.covers.set(this, open);
    if (open) {
      this.root.querySelector('.real-close').focus();
      this.merged.draw();
      this.refresh();
    } else {
      this.pause();
      this.opener.focus();
    }
  }

  /**
   * Pauses and waits for the step under way: the worker answers one request
   * at a time, but a step awaits its pictures, so nothing may change the
   * robots while one runs.
   */
  async idle() {
    this.pause();
    while (this.busy) await new Promise((r) => setTimeout(r, 20));
  }

  /** Runs `job` after whatever is under way (opening, merging) has finished. */
  enqueue(job) {
    this.queue = this.queue.then(job).catch((e) => {
      this.pause();
      this.say(e.message, 'error');
    });
    return this.queue;
  }

  /** The speed asked for, and while playing slower than that (the SLAM cannot keep up) how fast it goes. */
  showSpeed(pace = null) {
    const slow = pace !== null && pace < 0.8 * this.speed() ? ` (replaying at ${pace.toFixed(pace < 10 ? 1 : 0)}×)` : '';
    this.root.querySelector('#log-speed-value').textContent = `${this.speed()}× real time${slow}`;
  }

  speed() {
    return Number(this.root.querySelector('#log-speed').value);
  }

  cut() {
    const n = Math.round(Number(this.root.querySelector('#log-cut').value));
    return Number.isFinite(n) ? Math.min(16, Math.max(1, n)) : 1;
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
      ...this.controls.request(),
    };
  }

  /**
   * Opens picked or dropped files (`[{file, path}]`, or a promise of them:
   * dropped.js); each log or bag is one robot, or as many as the cut says.
   * The worker reads them (the files themselves go to it, not their bytes).
   */
  open(entries) {
    this.pause();
    return this.enqueue(async () => {
      const files = await entries;
      if (!files.length) return;
      await this.idle();
      this.say('', 'info');
      const size = this.size();
      let out;
      try {
        out = await this.client.request({ type: 'open', files, cut: this.cut(), colours: MAP_COLOURS });
      } finally {
        this.showReading(null);
      }
      if (out.added) this.restart(out, out.opened);
      else if (out.attached.length) this.state.robots = out.robots;
      const problems = [
        out.errors.length ? `Not opened: ${out.errors.join(' · ')}` : '',
        out.relationErrors.length ? `Relations not used: ${out.relationErrors.join(' · ')}` : '',
      ];
      if (problems.some(Boolean)) this.say(problems.filter(Boolean).join(' — '), 'error');
      this.refresh();
      if (out.added || out.attached.length) await this.client.request({ type: 'step', n: 0, size });
    });
  }

  /** The progress bar while a bag is read: `r` `{name, read, total, bag, of}` (bytes), or null to hide it. */
  showReading(r) {
    const q = (s) => this.root.querySelector(s);
    q('#log-reading').hidden = !r;
    if (!r) return;
    const mb = (b) => (b / 1e6).toFixed(1);
    q('#log-reading-name').textContent = `Reading ${r.name}${r.of > 1 ? ` (bag ${r.bag} of ${r.of})` : ''}`;
    const bar = q('#log-reading-bar');
    bar.max = Math.max(1, r.total);
    bar.value = r.read;
    q('#log-reading-bytes').textContent = `${mb(r.read)} of ${mb(r.total)} MB`;
  }

  /** Bag `id`'s replays made anew with `picks` (bag-picks.js): its robots start again, the others go on. */
  async repick(id, picks, truthHidden) {
    await this.idle();
    const out = await this.client.request({ type: 'pick', log: id, picks, truthHidden });
    this.restart(out);
    this.refresh();
    await this.client.request({ type: 'step', n: 0, size: this.size() });
  }

  /** New robots (`out`: the worker's answer to open, cut or pick; `opened`: the names opened); a replay under way goes on. */
  restart(out, opened = []) {
    this.names = [...(this.names ?? []), ...opened];
    const sum = (k) => out.robots.reduce((s, r) => s + r[k], 0);
    const [done, total] = [sum('done'), sum('total')];
    this.state = { ...emptyState(), name: this.names.join(', '), records: out.records, done, total, left: total - done, closures: sum('closures'), robots: out.robots, bags: out.bags };
    this.files = null;
    this.summary = null;
    this.merged.drop();
  }

  async recut() {
    if (!this.state.records) return;
    await this.idle();
    const out = await this.client.request({ type: 'cut', cut: this.cut(), colours: MAP_COLOURS });
    this.restart(out);
    this.refresh();
    await this.client.request({ type: 'step', n: 0, size: this.size() });
  }

  async clear() {
    await this.idle();
    await this.client.request({ type: 'clear' });
    this.names = [];
    this.state = emptyState();
    this.files = null;
    this.merged.drop();
    this.say('', 'info');
    this.refresh();
    await this.client.request({ type: 'step', n: 0, size: this.size() }).catch(() => {});
  }

  /**
   * One step of every robot: `STEP_SCANS` scans, or while playing the
   * scans up to the log's clock (`this.until`, s from each robot's first
   * scan), which runs at the speed (× real time) since the last step; at
   * the end, settles the graphs and offers the maps.
   */
  async advance(playing) {
    if (this.busy || !this.state.records || this.state.finished) return;
    this.busy = true;
    try {
      let ask = { n: STEP_SCANS };
      if (playing) {
        const now = performance.now();
        const live = this.timeline.live;
        const ahead = this.speed() * MAX_TICK_S;
        const clock = Math.min(this.until ?? live, live + ahead);
        this.until = clock + this.speed() * Math.min(MAX_TICK_S, (now - this.tick) / 1000);
        this.tick = now;
        ask = { until: this.until };
      }
      const out = await this.client.request({ type: 'step', ...ask, size: this.size() });
      this.lookingBack = false;
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

  /** Shows every robot at `t` s after its first scan (timeline.js). */
  async seek(t) {
    if (!this.state.records) return;
    this.pause();
    while (this.busy) await new Promise((r) => setTimeout(r, 20));
    this.busy = true;
    try {
      const out = await this.client.request({ type: 'seek', t, size: this.size() });
      this.state.robots = out.robots;
      this.lookingBack = out.robots.some((r) => r.at !== null);
    } catch (e) {
      this.say(e.message, 'error');
    } finally {
      this.busy = false;
    }
    this.refresh();
  }

  /** Replays every log again from its first scan (the files are not read again), and plays. */
  async again() {
    if (!this.state.records) return;
    await this.idle();
    const out = await this.client.request({ type: 'cut', cut: this.cut(), colours: MAP_COLOURS });
    this.restart(out);
    this.lookingBack = false;
    this.refresh();
    await this.client.request({ type: 'step', n: 0, size: this.size() });
    this.play();
  }

  async finish() {
    const out = await this.client.request({ type: 'finish' });
    this.files = out.files;
    this.state.robots = out.robots;
    this.state.finished = true;
    this.state.done = this.state.total;
    this.state.left = 0;
    this.state.closures = out.robots.reduce((s, r) => s + r.summary.closures, 0);
    this.summary = out.robots[0].summary;
    this.pause();
    await this.client.request({ type: 'step', n: 0, size: this.size() });
  }

  /** Replays what is left of every robot, then merges their maps. */
  async merge() {
    if ((this.state.robots?.length ?? 0) < 2) {
      this.say('Open two or more logs, or cut this one into stretches, to merge maps.', 'warn');
      return;
    }
    await this.idle();
    this.setBusy(true);
    try {
      if (!this.state.finished) {
        this.merged.stage('replaying what is left of each robot…');
        await this.finish();
      }
      const n = this.state.robots.length;
      this.merged.stage(`merging ${n} maps (${(n * (n - 1)) / 2} pair${n > 2 ? 's' : ''})…`);
      const t0 = performance.now();
      const out = await this.client.request({ type: 'merge' });
      this.mergeMs = performance.now() - t0;
      this.merged.stage(`merged in ${(this.mergeMs / 1000).toFixed(2)} s`);
      await this.merged.show(out.report, out.files, this.state.robots, out.groupFiles);
    } finally {
      this.setBusy(false);
    }
  }

  setBusy(busy) {
    this.merging = busy;
    this.root.classList.toggle('busy', busy);
    this.refresh();
  }

  play() {
    if (!this.state.records || this.state.finished || this.merging) return;
    this.playing = true;
    this.tick = performance.now();
    this.until = null;
    const loop = async () => {
      if (!this.playing) return;
      await this.advance(true);
      // The next step in a fresh task, after the page has drawn; the
      // log's clock moves on meanwhile.
      if (this.playing) setTimeout(loop, 15);
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

  /** Draws robot `name`'s worst relation `k` stronger on the map (`name` null: none). */
  highlight(name, k) {
    if (!this.state.records || this.root.hidden) return;
    this.client.request({ type: 'highlight', robot: name, k, size: this.size() }).catch((e) => this.say(e.message, 'error'));
  }

  redraw() {
    if (!this.state.records || this.root.hidden) return Promise.resolve();
    return this.client.request({ type: 'redraw', size: this.size() }).catch((e) => this.say(e.message, 'error'));
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
    const robots = s.robots ?? [];
    const can = s.records > 0 && !s.finished && !this.merging;
    q('#log-play').disabled = !can || this.playing;
    q('#log-pause').disabled = !this.playing;
    q('#log-step').disabled = !can || this.playing;
    q('#log-clear').disabled = !s.records || this.merging;
    q('#log-merge').disabled = robots.length < 2 || this.merging;
    this.timeline.show(robots, !!this.lookingBack, s.records > 0 && !this.merging);
    this.showSpeed(this.timeline.pace(this.playing && !s.finished));
    q('#log-name').textContent = s.name ? `${s.name}: ${s.records} laser records` : '';
    const closures = `${s.closures} loop closure${s.closures === 1 ? '' : 's'}`;
    const many = robots.length > 1 ? ` · ${robots.length} robots` : '';
    q('#log-progress').textContent = !s.records
      ? ''
      : s.finished
        ? `done: ${s.done} scans${many}, ${closures}; ${many ? 'a map each' : `map ${this.summary.map.width} × ${this.summary.map.height} cells`}`
        : `scan ${s.done} of ${s.total}${many} · ${closures}`;
    this.listRobots(robots);
    this.picks.show(s.bags, robots);
    this.plot.show(robots);
    q('#log-truth-key').hidden = !robots.some((r) => r.truth);
    this.relations.show(robots);
    q('#log-rel-key').hidden = !robots.some((r) => r.relations?.worst.length);
    // Bags replayed by scan matching alone draw no odometry.
    const bagOf = (r) => (s.bags ?? []).find((b) => b.id === r.logId);
    q('#log-odom-key').hidden = robots.length > 0 && robots.every((r) => bagOf(r)?.picked.odometry === null);
    for (const b of this.root.querySelectorAll('#log-map-downloads button')) b.disabled = !this.files;
  }

  /** With several robots: each one's swatch, stretch and progress, and the pick of whose map to download. */
  listRobots(robots) {
    const list = this.root.querySelector('#log-robots');
    const pick = this.root.querySelector('#log-map-of');
    const many = robots.length > 1;
    pick.hidden = !many;
    pick.previousElementSibling.hidden = !many;
    if (!many) {
      list.replaceChildren();
      return;
    }
    list.replaceChildren(
      ...robots.map((r) => {
        const span = document.createElement('span');
        span.className = 'real-swatch';
        span.style.setProperty('--c', r.colour);
        const c = r.summary?.closures ?? r.closures;
        span.textContent = `${r.name}: records ${r.from}–${r.to} of ${r.log}, ${r.done} of ${r.total} replayed, ${c} loop closure${c === 1 ? '' : 's'}`;
        return span;
      }),
    );
    if (pick.options.length !== robots.length || [...pick.options].some((o, i) => o.value !== robots[i].name)) {
      pick.replaceChildren(...robots.map((r, i) => new Option(r.name, r.name, i === 0, i === 0)));
    }
  }

  save(kind) {
    if (!this.files) return;
    const robots = this.state.robots ?? [];
    const at = Math.max(0, robots.findIndex((r) => r.name === this.root.querySelector('#log-map-of').value));
    const files = this.files[at];
    const base = robots[at]?.name ?? 'log';
    if (kind === 'pgm') this.download(`${base}.pgm`, files.pgm, 'image/x-portable-graymap');
    if (kind === 'png') this.download(`${base}.png`, files.png, 'image/png');
    if (kind === 'yaml') this.download(`${base}.yaml`, files.yaml.replace('log-map.pgm', `${base}.pgm`), 'application/yaml');
  }

  /** For tests and the console. */
  snapshot() {
    return {
      ...this.state,
      playing: this.playing,
      busy: this.busy,
      merging: !!this.merging,
      summary: this.summary ?? null,
      merge: this.merged.report,
      timeline: this.timeline.snapshot(),
      view: this.controls.zoom.toJSON(),
      mergeView: this.merged.zoom?.toJSON() ?? null,
      layers: this.controls.layers(),
    };
  }
}

function emptyState() {
  return { name: '', records: 0, done: 0, total: 0, closures: 0, left: 0, finished: false, robots: [], bags: [] };
}
