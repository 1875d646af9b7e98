// The controls over "Your log"'s map (issue 55): which layers are drawn
// (SLAM's path, the odometry's, the loop closures) and the user's view of
// it (zoom.js: the wheel or a pinch zooms about the pointer, a drag pans,
// Reset view fits the whole map again). The canvas belongs to the log
// worker; these controls only hold the choices, which go with every
// drawing request (`request()`), and ask for a redraw when one changes
// (at most one redraw under way; the latest choice waits for it).

import { attachZoom, Zoom } from './zoom.js';

/** The layers a user may hide: their keys (as log-draw.js reads them) and names. */
export const LOG_LAYERS = [
  ['slam', "SLAM's path"],
  ['odometry', 'odometry'],
  ['closures', 'loop closures'],
];

export const MAP_CONTROLS_HTML = `
  <style>
    #log-canvas { width: 100%; height: max(520px, calc(100vh - 180px)); cursor: grab; }
    #log-canvas.panning { cursor: grabbing; }
    .log-map-controls label { font-size: 13px; }
  </style>
  <div class="real-merge-row log-map-controls" role="group" aria-label="Layers and view of the map">
    <span class="real-stage">Show:</span>
    ${LOG_LAYERS.map(([key, name]) => `<label><input type="checkbox" id="log-layer-${key}" checked> ${name}</label>`).join('\n    ')}
    <button type="button" id="log-view-reset" disabled>Reset view</button>
    <span class="real-stage">Wheel or pinch to zoom, drag to move the map.</span>
  </div>`;

export class MapControls {
  /** `root`: the view holding MAP_CONTROLS_HTML and `canvas`; `redraw()`: asks the worker to draw (a promise). */
  constructor(root, canvas, redraw) {
    this.root = root;
    this.redraw = redraw;
    this.zoom = new Zoom();
    this.running = false;
    this.again = false;
    this.reset = root.querySelector('#log-view-reset');
    attachZoom(canvas, this.zoom, () => this.changed());
    this.reset.addEventListener('click', () => {
      this.zoom.reset();
      this.changed();
    });
    for (const [key] of LOG_LAYERS) root.querySelector(`#log-layer-${key}`).addEventListener('change', () => this.changed());
  }

  /** The layers shown: `{slam, odometry, closures}` booleans. */
  layers() {
    return Object.fromEntries(LOG_LAYERS.map(([key]) => [key, this.root.querySelector(`#log-layer-${key}`).checked]));
  }

  /** What goes with a drawing request: the view and the layers. */
  request() {
    return { view: this.zoom.toJSON(), layers: this.layers() };
  }

  /** Something changed: redraw (coalesced). */
  async changed() {
    this.reset.disabled = this.zoom.isIdentity();
    if (this.running) {
      this.again = true;
      return;
    }
    this.running = true;
    do {
      this.again = false;
      await this.redraw().catch(() => {});
    } while (this.again);
    this.running = false;
  }
}
