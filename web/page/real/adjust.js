// "Your maps": placing one map on another by hand, then Refine (issue 20).
//
// When the automatic merge says no_merge (a building that looks the same
// turned round, too little to go on), a person can often see where a map
// belongs. Here they pick a pair, drag its second map roughly onto the
// first in the overlay (Shift-drag, or the "drag turns" box, turns it about
// its middle; the arrow keys move it and Q / E turn it), and press Refine:
// the merge worker aligns the map from that guess and judges it with the
// same tests as the automatic merge (crate/src/merge/saved/refine.rs), and the
// view shows the new verdict, transforms and downloads. The map is drawn by
// the worker while it moves (one drawing in flight at a time), in a view
// that stays still so the map stays under the pointer.
//
// A refused Refine keeps the person's placement on screen, with the
// refined overlay that was judged outlined (dashed) and the reason, and
// offers "Use my placement (not verified)": the maps are then joined
// exactly there, and the verdict, the transforms, the downloads and the
// JSON say it is not verified. "Place by hand" starts again from the last
// placement of that pair.

import { compose } from './overlay.js';

const HELP = `Drag the map roughly onto the other, then press Refine. Drag moves it; Shift-drag (or tick
  “drag turns it”) turns it about its middle, the ring mark; the arrow keys move it and Q / E turn it
  (hold Shift for bigger steps). The lab then aligns it from where you put it and judges the result
  with the same tests as the automatic merge.`;

export const ADJUST_HTML = `
  <div id="real-adjust" class="real-adjust">
    <h2>Place a map by hand</h2>
    <p class="real-note">Not merged, but you can see where a map belongs? Place it by hand and press Refine.</p>
    <div class="real-adjust-row">
      <label for="real-pair">Pair</label>
      <select id="real-pair"></select>
      <button type="button" id="real-adjust-start">Place by hand</button>
      <button type="button" id="real-refine" class="primary" disabled>Refine</button>
      <button type="button" id="real-adjust-cancel" disabled>Cancel</button>
      <button type="button" id="real-keep" hidden title="Join the map where you put it, without the merge's tests">Use my placement (not verified)</button>
      <label class="real-turn"><input type="checkbox" id="real-turn"> drag turns it</label>
    </div>
    <p id="real-adjust-help" class="real-adjust-help" hidden>${HELP}</p>
    <p id="real-refined" class="real-verdict" hidden></p>
  </div>`;

/** `pose` [x, y, θ] turned by `d` about the point `q` [x, y] (same frame). */
export function turnAbout(pose, q, d) {
  const c = Math.cos(d), s = Math.sin(d);
  const dx = pose[0] - q[0], dy = pose[1] - q[1];
  return [q[0] + c * dx - s * dy, q[1] + s * dx + c * dy, pose[2] + d];
}

/** The middle of map `m`'s image in its own map frame. */
export function middleOf(m) {
  const [x, y] = compose(m.origin, [(m.width * m.resolution) / 2, (m.height * m.resolution) / 2, 0]);
  return [x, y];
}

/** The inverse of pose `p` [x, y, θ]. */
export function inverse([x, y, t]) {
  const c = Math.cos(t), s = Math.sin(t);
  return [-c * x - s * y, s * x - c * y, -t];
}

/** Map b's frame in map a's, b's image just right of a's, unturned. */
function beside(a, b) {
  const xs = [0, 1].flatMap((u) => [0, 1].map((v) => compose(a.origin, [u * a.width * a.resolution, v * a.height * a.resolution, 0])));
  const right = Math.max(...xs.map((p) => p[0]));
  const mid = (Math.min(...xs.map((p) => p[1])) + Math.max(...xs.map((p) => p[1]))) / 2;
  const [bx, by] = middleOf(b);
  const gap = 0.1 * a.width * a.resolution;
  return [right + gap + (b.width * b.resolution) / 2 - bx, mid - by, 0];
}

export class PlaceByHand {
  /**
   * `root`: the view's element (holding ADJUST_HTML and the overlay canvas);
   * `client`: the SavedMapsClient; `hooks`: `maps()` (the opened maps, with
   * `index`), `report()`, `size()` (the overlay's size for drawing),
   * `refined(out)` (a refine's `{pair, report, files}`), `say(text, kind)`,
   * `busy(on, text)`, `changed()` (the view's state changed: redraw legend).
   */
  constructor(root, client, hooks) {
    this.root = root;
    this.client = client;
    this.hooks = hooks;
    this.active = null; // {a, b, pose, pivot} while placing
    this.kept = null; // {a, b, pose, judged, reason} after a refused refine
    this.last = new Map(); // the last placement of each pair ("a|b" names): map b's frame in map a's
    this.view = null;
    this.drag = null;
    this.sending = false;
    this.pending = false;
  }

  wire() {
    const q = (s) => this.root.querySelector(s);
    const said = (job) => () => job().catch((e) => this.hooks.say(e.message, 'error'));
    q('#real-adjust-start').addEventListener('click', said(() => this.start()));
    q('#real-adjust-cancel').addEventListener('click', said(() => this.stop()));
    q('#real-refine').addEventListener('click', said(() => this.refine()));
    q('#real-keep').addEventListener('click', said(() => this.keep()));
    // The overlay canvas may be replaced (a restarted worker): listen on the view.
    this.root.addEventListener('pointerdown', (e) => this.down(e));
    this.root.addEventListener('pointermove', (e) => this.move(e));
    this.root.addEventListener('pointerup', (e) => this.up(e));
    this.root.addEventListener('pointercancel', (e) => this.up(e));
    this.root.addEventListener('keydown', (e) => this.key(e), true);
  }

  /** Fills the pair list from `report` (the first pair not merged first chosen). */
  show(report) {
    const select = this.root.querySelector('#real-pair');
    const pairs = report?.merge.pairs ?? [];
    const keep = select.value;
    select.replaceChildren(
      ...pairs.map((p, i) => {
        const o = document.createElement('option');
        o.value = String(i);
        const state = p.verified === false ? 'placed by hand, not verified' : p.status === 'merged' ? 'merged' : 'not merged';
        o.textContent = `${p.b} onto ${p.a} (${state})`;
        return o;
      }),
    );
    const open = pairs.findIndex((p) => p.status !== 'merged');
    select.value = keep && Number(keep) < pairs.length ? keep : String(Math.max(0, open));
    this.controls();
  }

  controls() {
    const q = (s) => this.root.querySelector(s);
    const placing = !!this.active;
    q('#real-adjust-start').disabled = placing || !q('#real-pair').options.length;
    q('#real-pair').disabled = placing;
    q('#real-refine').disabled = !placing;
    q('#real-adjust-cancel').disabled = !placing && !this.kept;
    q('#real-keep').hidden = !this.kept;
    q('#real-adjust-help').hidden = !placing;
    q('#real-overlay').classList.toggle('placing', placing);
    q('#real-overlay').tabIndex = placing ? 0 : -1;
  }

  /** Starts placing the chosen pair's second map on its first. */
  async start() {
    const pair = this.hooks.report()?.merge.pairs[Number(this.root.querySelector('#real-pair').value)];
    if (!pair) return;
    const byName = new Map(this.hooks.maps().map((m) => [m.name, m]));
    const a = byName.get(pair.a), b = byName.get(pair.b);
    if (!a || !b) return;
    const last = this.last.get(`${a.name}|${b.name}`);
    const pose = last ? [...last] : pair.status === 'merged' && pair.pose ? [...pair.pose] : beside(a, b);
    this.kept = null;
    this.active = { a, b, pose, pivot: middleOf(b) };
    this.root.querySelector('#real-refined').hidden = true;
    this.controls();
    this.hooks.changed();
    this.view = (await this.client.adjust(a.index, b.index, pose, true)).view;
    const canvas = this.root.querySelector('#real-overlay');
    canvas.scrollIntoView({ block: 'nearest' });
    canvas.focus({ preventScroll: true });
    this.hooks.say(`Drag ${b.name} roughly onto ${a.name}, then press Refine.`, 'info');
  }

  async stop() {
    this.active = null;
    this.kept = null;
    this.drag = null;
    this.controls();
    this.hooks.changed();
    this.view = (await this.client.endAdjust()).view;
    this.hooks.say('', 'info');
  }

  /** Sends the pose to the worker to draw; one request in flight, the latest pose wins. */
  async send() {
    if (this.sending) {
      this.pending = true;
      return;
    }
    this.sending = true;
    const canvas = this.root.querySelector('#real-overlay');
    canvas.dataset.sending = 'yes'; // for tests: a drawing is under way
    try {
      do {
        this.pending = false;
        const { a, b, pose } = this.active ?? {};
        if (!a) break;
        this.view = (await this.client.adjust(a.index, b.index, pose)).view ?? this.view;
      } while (this.pending);
    } finally {
      this.sending = false;
      delete canvas.dataset.sending;
    }
  }

  /** A pointer event's position in metres, in map a's frame. */
  world(e) {
    const canvas = this.root.querySelector('#real-overlay');
    const r = canvas.getBoundingClientRect(), v = this.view;
    const px = (e.clientX - r.left) * v.dpr, py = (e.clientY - r.top) * v.dpr;
    return [(px - v.e) / v.k, (v.f - py) / v.k];
  }

  pivotNow() {
    const { pose, pivot } = this.active;
    return compose(pose, [pivot[0], pivot[1], 0]);
  }

  down(e) {
    if (!this.active || !this.view || e.target.id !== 'real-overlay' || e.button !== 0) return;
    e.preventDefault();
    e.target.setPointerCapture(e.pointerId);
    e.target.focus({ preventScroll: true });
    const turn = e.shiftKey || this.root.querySelector('#real-turn').checked;
    this.drag = { id: e.pointerId, turn, last: this.world(e) };
  }

  move(e) {
    if (!this.drag || e.pointerId !== this.drag.id) return;
    const p = this.world(e), last = this.drag.last;
    this.drag.last = p;
    const a = this.active;
    if (this.drag.turn) {
      const [cx, cy] = this.pivotNow();
      const d = Math.atan2(p[1] - cy, p[0] - cx) - Math.atan2(last[1] - cy, last[0] - cx);
      a.pose = turnAbout(a.pose, [cx, cy], Math.atan2(Math.sin(d), Math.cos(d)));
    } else {
      a.pose = [a.pose[0] + p[0] - last[0], a.pose[1] + p[1] - last[1], a.pose[2]];
    }
    this.send();
  }

  up(e) {
    if (this.drag && e.pointerId === this.drag.id) this.drag = null;
  }

  /** Arrow keys move the map by 0.1 m (Shift: 1 m), Q and E turn it by 1° (Shift: 10°). */
  key(e) {
    if (!this.active || e.target.id !== 'real-overlay') return;
    const step = e.shiftKey ? 1 : 0.1, turn = ((e.shiftKey ? 10 : 1) * Math.PI) / 180;
    const moves = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, step], ArrowDown: [0, -step] };
    const a = this.active;
    const k = e.key.length === 1 ? e.key.toLowerCase() : e.key;
    if (moves[k]) a.pose = [a.pose[0] + moves[k][0], a.pose[1] + moves[k][1], a.pose[2]];
    else if (k === 'q' || k === 'e') a.pose = turnAbout(a.pose, this.pivotNow(), k === 'q' ? turn : -turn);
    else return;
    e.preventDefault();
    this.send();
  }

  /** Aligns from the map's place and shows the verdict. */
  async refine() {
    if (!this.active) return;
    const { a, b, pose } = this.active;
    this.drag = null;
    this.root.querySelector('#real-refine').disabled = true;
    this.hooks.busy(true, `refining ${b.name} on ${a.name} from where you put it…`);
    let out;
    try {
      out = await this.client.refine(a.index, b.index, pose);
    } finally {
      this.hooks.busy(false, '');
      this.controls();
    }
    this.active = null;
    this.last.set(`${a.name}|${b.name}`, [...pose]);
    this.lastPair = out.pair;
    const merged = out.pair.status === 'merged';
    // The pair comes back in the order the merge judged it: its pose is then a's frame in b's.
    const judged = out.pair.pose && (out.pair.a === a.name ? out.pair.pose : inverse(out.pair.pose));
    this.kept = merged ? null : { a, b, pose, judged, reason: out.pair.reason };
    this.controls();
    this.tell(merged
      ? `Refine of ${b.name} on ${a.name}: merged (confidence ${out.pair.confidence.toFixed(2)}): ${out.pair.reason}`
      : `Refine of ${b.name} on ${a.name}: refused, because ${out.pair.reason}. Your placement stays on screen; ` +
        'the dashed outline is the refined overlay that was judged. Place it again, or use your placement as it is (not verified).', merged ? 'ok' : 'no');
    this.hooks.refined(out);
    this.hooks.say('', 'info');
    this.hooks.changed();
    if (this.kept) this.view = (await this.client.adjust(a.index, b.index, pose, true, judged)).view;
  }

  /** Joins the kept placement as it is, not verified. */
  async keep() {
    if (!this.kept) return;
    const { a, b, pose } = this.kept;
    this.hooks.busy(true, `joining ${b.name} where you put it…`);
    let out;
    try {
      out = await this.client.keep(a.index, b.index, pose);
    } finally {
      this.hooks.busy(false, '');
    }
    this.kept = null;
    this.controls();
    this.lastPair = out.pair;
    this.tell(`${b.name} joined to ${a.name} where you put it: not verified by the merge's tests.`, 'unverified');
    this.hooks.refined(out);
  }

  /** The line under the pair row: what the last Refine or keep did. */
  tell(text, kind) {
    const line = this.root.querySelector('#real-refined');
    line.textContent = text;
    line.className = `real-verdict ${kind}`;
    line.hidden = false;
  }

  /** For tests and the console. */
  snapshot() {
    const a = this.active;
    return {
      placing: a ? { a: a.a.name, b: a.b.name, pose: [...a.pose], pivot: [...a.pivot] } : null,
      kept: this.kept ? { a: this.kept.a.name, b: this.kept.b.name, pose: [...this.kept.pose], judged: this.kept.judged } : null,
      view: this.view,
      pair: this.lastPair ?? null,
    };
  }
}
