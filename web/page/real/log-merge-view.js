// The merge of the robots' log maps as "Your log" shows it (log-panel.js):
// the Merge maps button, then what "Your maps" shows of a merge
// (merge-result.js): the verdict with its reason and confidence, each
// robot's frame in the first robot's frame (metres, degrees, and the
// arguments of ROS's static_transform_publisher), each pair's verdict, the
// joined maps and the robots' paths overlaid in their colours (drawn by
// the log worker; zoomed and panned with zoom.js, Reset view, a robot
// unticked in the legend hidden) and the downloads: the merged map as PGM + YAML + PNG
// and the transforms as JSON. Robots of two buildings cannot all be
// joined: their maps merge into groups, each in the frame of its first
// robot; the verdict then names the groups, and the list and tabs of
// map-groups.js (as "Your maps" shows them) pick which group's
// transforms, overlay and downloads the view shows. The merge itself runs
// in the log worker (log-merge.js).

import { nextFrame } from './panel.js';
import { OverlayCanvas, mergeHtml, saveMerge, showMerge } from './merge-result.js';
import { MapGroupsView, showsGroups } from './map-groups.js';
import { joinedGroups } from './report.js';
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
    this.client = client;
    this.download = download;
    this.overlay = new OverlayCanvas(root, 'log', client, { canvas: 'mergeCanvas', draw: 'drawMerge' });
    this.report = null;
    this.files = null;
    this.robots = [];
    /** Each group's merged map files (null for a robot alone), and the group shown (its position in `merge.groups`). */
    this.groupFiles = [];
    this.group = -1;
    this.groups = null;
  }

  wire() {
    this.groups = new MapGroupsView(this.root.querySelector('#log-groups'), {
      select: (k) => this.showGroup(k),
      colour: (map) => this.robots.find((r) => r.name === robotName(map))?.colour ?? '',
      label: robotName,
    });
    this.root.querySelector('#log-alpha').addEventListener('input', () => this.draw());
    for (const b of this.root.querySelectorAll('#log-downloads button')) {
      b.addEventListener('click', () => this.save(b.dataset.file));
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
    this.groupFiles = [];
    this.group = -1;
    this.groups?.hide();
    this.root.querySelector('#log-result').hidden = true;
    this.stage('');
  }

  /**
   * Shows a merge: `report` (merge-maps'), `files` (the first group's
   * merged map, null when no robot joined another), `robots` ([{name,
   * colour}]), `groupFiles` (each group's merged map, null for a robot alone).
   */
  async show(report, files, robots, groupFiles = [files]) {
    this.report = report;
    this.robots = robots;
    this.groupFiles = groupFiles;
    this.group = this.groups.show(report.merge);
    this.showTables();
    await nextFrame();
    this.draw();
  }

  /** The verdict, the tables and the downloads of the group shown (every robot when one group). */
  showTables() {
    const merge = this.report.merge;
    this.files = this.groupFiles[this.group] ?? null;
    const group = showsGroups(merge) ? merge.groups[this.group] : null;
    showMerge(this.root, 'log', merge, !!this.files, { name: robotName, what: 'robot', group, groups: true });
  }

  /** Shows group `k`: its transforms, its downloads and its overlay (drawn by the log worker). */
  async showGroup(k) {
    this.group = k;
    this.showTables();
    await this.client.request({ type: 'group', group: k });
    this.draw();
  }

  /** Downloads `kind` (pgm, yaml, png, json) of the group shown. */
  save(kind) {
    saveMerge(this.download, this.report, this.files, kind, showsGroups(this.report.merge) ? this.group : -1);
  }

  /** The robots' maps the overlay shows: the group shown, else every joined one. */
  shownTransforms() {
    const merge = this.report.merge;
    return (showsGroups(merge) ? merge.groups[this.group]?.transforms : null) ?? merge.transforms;
  }

  /** "Merged maps", or with groups listed "Merged maps of group 2: ring-1 + ring-2". */
  overlayTitle() {
    const merge = this.report.merge;
    const g = showsGroups(merge) ? merge.groups[this.group] : null;
    if (!g) return 'Merged maps';
    const n = joinedGroups(merge).findIndex((j) => j.k === this.group) + 1;
    return `Merged maps of group ${n}: ${g.maps.map(robotName).join(' + ')}`;
  }

  /** The joined maps in the first robot's frame, each in its robot's colour, and their legend (a box a robot, to hide its map and path). */
  draw() {
    if (!this.report || this.root.hidden) return;
    this.overlay.draw();
    this.root.querySelector('#log-overlay-title').textContent = this.overlayTitle();
    const joined = new Set(this.shownTransforms().map((t) => robotName(t.map)));
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
