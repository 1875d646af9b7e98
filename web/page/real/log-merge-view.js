// The merge of the robots' log maps as "Your log" shows it (log-panel.js):
// the Merge maps button, then the verdict with its reason and confidence,
// each robot's frame in the first robot's frame (metres, degrees, and the
// arguments of ROS's static_transform_publisher), each pair's verdict, the
// joined maps overlaid in the robots' colours (drawn by the log worker
// into a canvas handed over once) and the downloads: the merged map as
// PGM + YAML + PNG and the transforms as JSON. The words and tables are
// those of "Your maps" (report.js, panel.js); the merge itself runs in the
// log worker (log-merge.js).

import { fillTable, nextFrame, swatch } from './panel.js';
import { transformRows, transformsJson, verdictText } from './report.js';

export const MERGE_HTML = `
  <div class="real-merge-row">
    <button type="button" id="log-merge" class="primary"
      title="Replay what is left of every robot, then merge the robots' maps">Merge maps</button>
    <span class="real-busy" aria-hidden="true"></span>
    <span id="log-merge-stage" class="real-stage" aria-live="polite"></span>
  </div>
  <div id="log-result" class="real-result" hidden>
    <p id="log-verdict" class="real-verdict"></p>
    <table id="log-transforms" class="summary-table"><caption>Each robot's frame (its first scan) in the first robot's frame</caption></table>
    <table id="log-pairs" class="summary-table"><caption>Each pair's own verdict</caption></table>
    <div class="real-overlay-head">
      <h2>Merged maps</h2>
      <label for="log-alpha">Opacity</label>
      <input id="log-alpha" type="range" min="15" max="100" value="85" aria-label="Opacity of the maps in the merged view">
    </div>
    <canvas id="log-overlay" class="real-overlay" aria-label="The robots' joined maps in their colours"></canvas>
    <p id="log-merge-legend" class="real-legend"></p>
    <div class="real-downloads log-merge-downloads">
      <button type="button" data-merged="pgm">Merged map PGM</button>
      <button type="button" data-merged="yaml">Merged map YAML</button>
      <button type="button" data-merged="png">Merged map PNG</button>
      <button type="button" data-merged="json">Transforms JSON</button>
    </div>
  </div>`;

export class LogMergeView {
  /** `root`: the log view (holding MERGE_HTML); `client`: the log worker's; `download(name, data, type)`. */
  constructor(root, client, download) {
    this.root = root;
    this.client = client;
    this.download = download;
    this.report = null;
    this.files = null;
    this.robots = [];
  }

  wire() {
    const q = (s) => this.root.querySelector(s);
    q('#log-alpha').addEventListener('input', () => this.draw());
    for (const b of this.root.querySelectorAll('.log-merge-downloads button')) {
      b.addEventListener('click', () => this.save(b.dataset.merged));
    }
    this.resizes = new ResizeObserver(() => this.draw());
    this.resizes.observe(q('#log-overlay'));
  }

  stage(text) {
    this.root.querySelector('#log-merge-stage').textContent = text;
  }

  /** Forgets the last merge (new logs, a new cut). */
  drop() {
    this.report = null;
    this.files = null;
    this.root.querySelector('#log-result').hidden = true;
    this.stage('');
  }

  /** Shows a merge: `report` (merge-maps'), `files` (null on no_merge), `robots` ([{name, colour}]). */
  async show(report, files, robots) {
    this.report = report;
    this.files = files;
    this.robots = robots;
    const q = (s) => this.root.querySelector(s);
    const merge = report.merge;
    q('#log-result').hidden = false;
    const v = q('#log-verdict');
    v.textContent = verdictText(merge);
    v.className = `real-verdict ${merge.status === 'merged' ? 'ok' : 'no'}`;
    const rows = transformRows(merge).map((r) => [r.map.replace(/\.yaml$/, ''), r.x, r.y, r.deg, r.args]);
    for (const name of merge.unjoined) rows.push([name.replace(/\.yaml$/, ''), '–', '–', '–', 'not joined']);
    fillTable(q('#log-transforms'), ['robot', 'x (m)', 'y (m)', 'θ (°)', 'static_transform_publisher'], rows);
    fillTable(
      q('#log-pairs'),
      ['pair', 'verdict', 'confidence', 'reason'],
      merge.pairs.map((p) => [`${p.a.replace(/\.yaml$/, '')} + ${p.b.replace(/\.yaml$/, '')}`, p.status, p.confidence.toFixed(2), p.reason]),
    );
    for (const b of this.root.querySelectorAll('.log-merge-downloads button')) {
      b.disabled = b.dataset.merged !== 'json' && !this.files;
    }
    await nextFrame();
    this.draw();
  }

  /** The joined maps, drawn by the worker; one drawing at a time (a slider's many events make one more at most). */
  draw() {
    if (!this.report || this.root.hidden) return;
    if (this.drawing) {
      this.again = true;
      return;
    }
    const canvas = this.attachCanvas();
    const dpr = window.devicePixelRatio || 1;
    const size = {
      width: Math.max(1, Math.round(canvas.clientWidth * dpr)),
      height: Math.max(1, Math.round(canvas.clientHeight * dpr)),
      dpr,
      alpha: this.root.querySelector('#log-alpha').value / 100,
    };
    this.drawing = true;
    this.client
      .request({ type: 'drawMerge', ...size })
      .catch(() => {})
      .finally(() => {
        this.drawing = false;
        if (this.again) {
          this.again = false;
          this.draw();
        }
      });
    const joined = new Set(this.report.merge.transforms.map((t) => t.map));
    const legend = this.root.querySelector('#log-merge-legend');
    const placed = this.robots.filter((r) => joined.has(`${r.name}.yaml`));
    legend.replaceChildren(
      ...placed.map((r) => swatch(r.colour, r.name)),
      placed.length > 1 ? 'Walls of two robots that fall on each other show dark.' : '',
    );
  }

  /** Hands the overlay canvas to the worker (once per worker); returns the canvas. */
  attachCanvas() {
    let canvas = this.root.querySelector('#log-overlay');
    if (this.canvasWorker === this.client.worker && this.client.worker) return canvas;
    this.client.start();
    if (this.canvasWorker) {
      // A restarted worker needs a canvas of its own: control moves once.
      const fresh = canvas.cloneNode();
      canvas.replaceWith(fresh);
      this.resizes.observe(fresh);
      canvas = fresh;
    }
    const offscreen = canvas.transferControlToOffscreen();
    this.client.request({ type: 'mergeCanvas', canvas: offscreen }, [offscreen]);
    this.canvasWorker = this.client.worker;
    return canvas;
  }

  save(kind) {
    if (kind === 'json' && this.report) {
      this.download('transforms.json', transformsJson(this.report), 'application/json');
      return;
    }
    if (!this.files) return;
    if (kind === 'pgm') this.download('merged.pgm', this.files.pgm, 'image/x-portable-graymap');
    if (kind === 'png') this.download('merged.png', this.files.png, 'image/png');
    if (kind === 'yaml') this.download('merged.yaml', this.files.yaml, 'application/yaml');
  }
}
