// Pointer input on the map: selecting, dragging walls, wall ends and robots,
// turning a robot by its handle (or Shift-drag), drawing a wall with the
// Wall tool, panning (middle button, Space-drag or dragging the empty
// floor) and zooming with the wheel. A drag shows its change live in the
// Lab (`store.preview`) and commits it, with undo, on release; Esc or a
// cancelled pointer puts everything back.
import { handlePoint, hitRobot, hitWall, snapAngle, snapPoint, wallEnd, wrapAngle } from './geometry.js';
import { deg, fmt } from './dom.js';
import { setStatus } from './status.js';

const roundPt = (p) => p.map((v) => Number(v.toFixed(4)));

export class PointerInput {
  /**
   * @param {HTMLCanvasElement} canvas
   * @param {import('./state.js').Store} store
   * @param {import('./world-view.js').WorldView} view
   * @param {import('./editor.js').Editor} editor
   * @param {{guard: Function, editable: () => boolean, refreshPanels: () => void,
   *          refreshControls: () => void}} hooks
   */
  constructor(canvas, store, view, editor, hooks) {
    this.canvas = canvas;
    this.store = store;
    this.view = view;
    this.editor = editor;
    this.hooks = hooks;
    this.drag = null;
    this.preview = null; // the wall being drawn [x0, y0, x1, y1]
    this.pointer = null; // last pointer position, CSS px on the canvas
    this.spaceDown = false; // Space held: a drag pans (web/page/keys.js)
    this.spaceUsed = false; // ...and it did, so releasing Space does not run
  }

  listen() {
    const c = this.canvas;
    const guard = this.hooks.guard;
    c.addEventListener('mousedown', (e) => {
      if (e.button === 1) e.preventDefault(); // no auto-scroll on middle click
    });
    c.addEventListener('contextmenu', (e) => {
      if (this.drag) e.preventDefault();
    });
    c.addEventListener('pointerdown', guard((e) => this.down(e)));
    c.addEventListener('pointermove', guard((e) => this.move(e)));
    c.addEventListener('pointerup', guard((e) => this.finish(e)));
    c.addEventListener('pointercancel', guard(() => this.cancel()));
    c.addEventListener('lostpointercapture', guard((e) => this.drag && this.finish(e)));
    c.addEventListener('wheel', guard((e) => {
      e.preventDefault();
      const [px, py] = this.px(e);
      const unit = e.deltaMode === 1 ? 40 : e.deltaMode === 2 ? 400 : 1;
      this.view.zoomAt(px, py, Math.exp(-e.deltaY * unit * 0.0015));
    }), { passive: false });
  }

  px(e) {
    const r = this.canvas.getBoundingClientRect();
    return [e.clientX - r.left, e.clientY - r.top];
  }

  /** Starts a drag: `drag` is what it does; the pointer is captured. */
  begin(e, drag) {
    this.drag = drag;
    this.canvas.setPointerCapture(e.pointerId);
  }

  down(e) {
    if (!this.store.lab) return;
    const c = this.canvas;
    c.focus({ preventScroll: true });
    const px = this.px(e);
    this.pointer = px;
    const v = this.view.view;
    if (e.button === 1 || (e.button === 0 && this.spaceDown)) {
      this.spaceUsed = this.spaceDown;
      this.begin(e, { kind: 'pan', last: px });
      c.classList.add('panning');
      return;
    }
    if (e.button !== 0) return;
    const p = v.toWorld(px);
    const tol = 7 / v.scale;
    const poses = this.view.robotPoses();
    const scenario = this.store.scenario;
    const before = JSON.stringify(scenario);

    if (!this.hooks.editable()) {
      // While a run exists: click a robot to highlight its card, drag to pan.
      const r = hitRobot(poses, p, tol);
      if (r != null) {
        this.store.select({ kind: 'robot', index: r });
        this.hooks.refreshPanels();
      }
      this.begin(e, { kind: 'pan', last: px });
      this.view.invalidate();
      return;
    }
    const sel = this.store.selection;
    if (sel && sel.kind === 'robot' && this.overHandle(px)) {
      this.begin(e, { kind: 'turn', index: sel.index, before });
      return;
    }
    const r = hitRobot(poses, p, tol);
    if (r != null) {
      this.store.select({ kind: 'robot', index: r });
      const pose = scenario.robots[r].start;
      this.begin(e, e.shiftKey
        ? { kind: 'turn', index: r, before }
        : { kind: 'robot', index: r, before, offset: [p[0] - pose[0], p[1] - pose[1]] });
      this.hooks.refreshPanels();
      this.view.invalidate();
      return;
    }
    if (this.editor.tool === 'wall') {
      const from = snapPoint(p);
      this.begin(e, { kind: 'wall-new', from, to: from });
      this.preview = [...from, ...from];
      this.view.invalidate();
      return;
    }
    if (sel && sel.kind === 'wall') {
      const w = scenario.walls[sel.index];
      for (const end of ['from', 'to']) {
        const [ex, ey] = v.toPx(w[end]);
        if (Math.hypot(px[0] - ex, px[1] - ey) <= 9) {
          this.begin(e, { kind: 'wall-end', index: sel.index, end, before });
          return;
        }
      }
    }
    const wi = hitWall(scenario.walls, p, tol);
    if (wi != null) {
      this.store.select({ kind: 'wall', index: wi });
      const w = scenario.walls[wi];
      this.begin(e, { kind: 'wall-move', index: wi, before, start: p, from: w.from, to: w.to });
    } else {
      // Empty floor: deselect; a drag pans.
      this.store.select(null);
      this.begin(e, { kind: 'pan', last: px });
    }
    this.hooks.refreshPanels();
    this.hooks.refreshControls();
    this.view.invalidate();
  }

  /** Is the canvas point `px` on the selected robot's turning handle? */
  overHandle(px) {
    const sel = this.store.selection;
    const [hx, hy] = this.view.view.toPx(handlePoint(this.store.scenario.robots[sel.index].start, this.view.handleReach()));
    return Math.hypot(px[0] - hx, px[1] - hy) <= 9;
  }

  move(e) {
    if (!this.store.lab) return;
    const px = this.px(e);
    this.pointer = px;
    const d = this.drag;
    if (!d) return this.hover(px);
    const p = this.view.view.toWorld(px);
    if (d.kind === 'pan') {
      if (d.last[0] !== px[0] || d.last[1] !== px[1]) {
        this.view.panBy(px[0] - d.last[0], px[1] - d.last[1]);
        d.last = px;
        d.moved = true;
        this.canvas.classList.add('panning');
      }
    } else if (d.kind === 'wall-new') {
      d.to = wallEnd(d.from, p, e.altKey || e.shiftKey);
      this.preview = [...d.from, ...d.to];
      this.view.invalidate();
    } else {
      const next = this.dragged(d, p, e);
      if (!next) return;
      d.moved = d.kind === 'wall-move' ? next.moved : true;
      if (this.store.preview(next.scenario)) d.live = next.scenario;
      this.view.invalidate();
    }
  }

  /** The scenario as the drag `d` at world point `p` leaves it, or null for no change. */
  dragged(d, p, e) {
    const next = this.store.draft();
    switch (d.kind) {
      case 'wall-end': {
        const w = next.walls[d.index];
        const other = d.end === 'from' ? w.to : w.from;
        const end = wallEnd(other, p, e.altKey || e.shiftKey);
        if (Math.hypot(end[0] - other[0], end[1] - other[1]) < 1e-6) return null;
        w[d.end] = end;
        return { scenario: next };
      }
      case 'wall-move': {
        const delta = [p[0] - d.start[0], p[1] - d.start[1]];
        const dd = e.altKey ? roundPt(delta) : snapPoint(delta);
        next.walls[d.index].from = roundPt([d.from[0] + dd[0], d.from[1] + dd[1]]);
        next.walls[d.index].to = roundPt([d.to[0] + dd[0], d.to[1] + dd[1]]);
        return { scenario: next, moved: dd[0] !== 0 || dd[1] !== 0 };
      }
      case 'robot': {
        const s = next.robots[d.index].start;
        const at = [p[0] - d.offset[0], p[1] - d.offset[1]];
        const q = e.altKey ? roundPt(at) : snapPoint(at);
        next.robots[d.index].start = [q[0], q[1], s[2]];
        return { scenario: next };
      }
      case 'turn': {
        const s = next.robots[d.index].start;
        const a = Math.atan2(p[1] - s[1], p[0] - s[0]);
        s[2] = e.altKey ? Number(wrapAngle(a).toFixed(4)) : Number(snapAngle(a).toFixed(6));
        return { scenario: next };
      }
      default:
        return null;
    }
  }

  hover(px) {
    let cls = '';
    if (this.hooks.editable()) {
      const v = this.view.view;
      const p = v.toWorld(px);
      const tol = 7 / v.scale;
      const sel = this.store.selection;
      if (sel && sel.kind === 'robot' && this.overHandle(px)) cls = 'over-handle';
      if (!cls && hitRobot(this.view.robotPoses(), p, tol) != null) cls = 'over-item';
      if (!cls && this.editor.tool === 'select' && hitWall(this.store.scenario.walls, p, tol) != null) cls = 'over-item';
    }
    this.canvas.classList.toggle('over-item', cls === 'over-item');
    this.canvas.classList.toggle('over-handle', cls === 'over-handle');
  }

  /** The pointer let go: commit what the drag did. */
  finish(e) {
    const d = this.drag;
    if (!d) return;
    this.drag = null;
    this.canvas.classList.remove('panning');
    if (e && this.canvas.hasPointerCapture?.(e.pointerId)) this.canvas.releasePointerCapture(e.pointerId);
    if (d.kind === 'wall-new') {
      this.preview = null;
      this.addWall(d.from, d.to);
    } else if (d.kind !== 'pan') {
      if (d.moved && d.live) {
        this.store.commit(d.live, { undoFrom: d.before });
        if (d.kind === 'turn') {
          const s = d.live.robots[d.index];
          setStatus(`${s.name} now faces ${fmt(deg(s.start[2]), 0)}°.`, 'info');
        }
        this.editor.reportProblems();
      } else {
        this.hooks.refreshPanels();
      }
    }
    this.hooks.refreshControls();
    this.view.invalidate();
  }

  addWall(from, to) {
    const len = Math.hypot(to[0] - from[0], to[1] - from[1]);
    if (len < 1e-6) {
      setStatus('A click makes no wall: press and drag to draw one.', 'info');
      return;
    }
    const next = this.store.draft();
    next.walls.push({ from, to });
    this.store.select({ kind: 'wall', index: next.walls.length - 1 });
    this.store.commit(next);
    setStatus(
      `Wall ${next.walls.length} added: (${fmt(from[0], 1)}, ${fmt(from[1], 1)}) → (${fmt(to[0], 1)}, ${fmt(to[1], 1)}), ${fmt(len)} m.`,
      'info',
    );
    this.editor.reportProblems();
  }

  /** Esc during a drag: put everything back as it was; false when there was no drag. */
  cancel() {
    const d = this.drag;
    if (!d) return false;
    this.drag = null;
    this.preview = null;
    this.canvas.classList.remove('panning');
    if (d.before) this.store.revert(d.before);
    this.view.invalidate();
    setStatus('Cancelled.', 'info');
    return true;
  }

  /** Forgets a drag without touching the scenario (a new scenario, an error). */
  drop() {
    this.drag = null;
    this.preview = null;
  }
}
