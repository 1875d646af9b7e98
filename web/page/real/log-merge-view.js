// The merge of the robots' log maps as "Your log" shows it (log-panel.js):
// the Merge maps button, then what "Your maps" shows of a merge
// (merge-result.js): the verdict with its reason and confidence, each
// robot's frame in the first robot's frame (metres, degrees, and the
// arguments of ROS's static_transform_publisher), each pair's verdict, the
// joined maps and the robots' paths overlaid in their colours (drawn by
// the log worker; zoomed and panned with zoom.js, Reset view, a robot
// unticked in the legend hidden) and the downloads: the merged map as PGM + YAML + PNG
// and the transforms as JSON. The merge itself runs in the log worker (log-merge.js).

import { nextFrame } from './panel.js';
import { OverlayCanvas, mergeHtml, saveMerge, showMerge } from './merge-result.js';
import { attachZoom, Zoom } from './zoom.js';

export const MERGE_HTML = `${mergeHtml('log', {
  stage: 'log-merge-stage',
  tip: "Replay what is left of every robot, then merge the robots' maps",
  frames: "Each robot's frame (its first scan) in the first robot's frame",
  title: 'Merged maps',
  overlay: "The robots' joined maps in their colours (wheel or pinch to zoom, drag to move)",
})}
  <style>
    #log-overlay { width: 100%; height: max(520px, calc(100vh - 160px)); cursor: grab; }
    #log-overlay.panning { cursor: grabbing; }
  </style>`;

/** A robot's name from its map's name in the merge report. */
const robotName = (map) => map.replace(/\.yaml$/, '');

export class LogMergeView {
  /** `root`: the log view (holding MERGE_HTML); `client`: the log worker's; `download(name, data, type)`. */
  constructor(root, client, download) {
    this.root = root;
    this.download = download;
    this.overlay = new OverlayCanvas(root, 'log', client, { canvas: 'mergeCanvas', draw: 'drawMerge' });
    this.report = null;
    this.files = null;
    this.robots = [];
  }

  wire() {
    this.root.querySelector('#log-alpha').addEventListener('input', () => this.draw());
    for (const b of this.root.querySelectorAll('#log-downloads button')) {
      b.addEventListener('click', () => saveMerge(this.download, this.report, this.files, b.dataset.file));
    }
    this.overlay.watch(() => this.draw());
    // The user's zoom and pan (zoom.js), Reset view beside the opacity, and
    // the robots unticked in the legend: they go with each drawing.
    this.zoom = this.overlay.zoom = new Zoom();
    this.overlay.hidden = () => [...this.root.querySelectorAll('#log-legend input:not(:checked)')].map((c) => c.dataset.robot);
    const reset = Object.assign(document.createElement('button'), { type: 'button', id: 'log-merge-reset', textContent: 'Reset view', disabled: true });
    this.root.querySelector('#log-alpha').after(reset);
    const changed = () => {
      reset.disabled = this.zoom.isIdentity();
      this.draw();
    };
    this.root.querySelector('#log-legend').addEventListener('change', changed);
    reset.addEventListener('click', () => {
      this.zoom.reset();
      changed();
    });
    attachZoom(this.overlay.canvas(), this.zoom, changed);
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
    showMerge(this.root, 'log', report.merge, !!files, { name: robotName, what: 'robot' });
    await nextFrame();
    this.draw();
  }

  /** The joined maps in the first robot's frame, each in its robot's colour, and their legend (a box a robot, to hide its map and path). */
  draw() {
    if (!this.report || this.root.hidden) return;
    this.overlay.draw();
    const joined = new Set(this.report.merge.transforms.map((t) => robotName(t.map)));
    const placed = this.robots.filter((r) => joined.has(r.name));
    const legend = this.root.querySelector('#log-legend');
    const names = placed.map((r) => r.name).join('\n');
    if (legend.dataset.names === names) return;
    legend.dataset.names = names;
    legend.replaceChildren(
      ...placed.map((r) => {
        const label = document.createElement('label');
        label.className = 'real-swatch';
        label.style.setProperty('--c', r.colour);
        const box = Object.assign(document.createElement('input'), { type: 'checkbox', checked: true });
        box.dataset.robot = r.name;
        label.append(box, ` ${r.name}`);
        return label;
      }),
      placed.length > 1 ? 'Walls of two robots that fall on each other show dark; each robot\'s SLAM path in its colour, a dot where it starts. Untick a robot to hide its map and path.' : '',
    );
  }
}
