// The view transform of the "Your maps" and "Your log" canvases: zoom
// with the mouse wheel or a pinch of two fingers, pan by dragging, reset.
//
// Each canvas is drawn fitted to its rectangle (fit.js, overlay.js's
// `fitView`): the whole map in view. The user's view is one more
// transform applied after that fit, in device pixels: a uniform scale `k`
// and a shift `(x, y)`, so a pixel `p` of the fitted drawing lands at
// `k · p + (x, y)`. Zooming by a factor `f` about a point `c` of the
// screen keeps the point under `c` still:
//   k' = f · k,   t' = c − f · (c − t)
// (for every p: k'·p + t' − c = f · (k·p + t − c)). A drag shifts `t` by
// the pointer's motion; a pinch does both at once, about the two fingers'
// midpoint, by the ratio of their distances. The transform is plain data
// (`{k, x, y}`), posted to the worker that draws, which applies it with
// `applyView` before drawing in world coordinates.

/** The farthest in and out a view zooms, against the fitted drawing. */
export const ZOOM_LIMITS = [0.5, 64];

export class Zoom {
  constructor() {
    this.reset();
  }

  /** Back to the fitted drawing. */
  reset() {
    Object.assign(this, { k: 1, x: 0, y: 0 });
  }

  /** Scales by `factor` about device pixel (`cx`, `cy`), which stays put (within ZOOM_LIMITS). */
  zoomAt(cx, cy, factor) {
    const k = Math.min(ZOOM_LIMITS[1], Math.max(ZOOM_LIMITS[0], this.k * factor));
    const f = k / this.k;
    this.x = cx - f * (cx - this.x);
    this.y = cy - f * (cy - this.y);
    this.k = k;
  }

  /** Shifts the view by (`dx`, `dy`) device pixels. */
  pan(dx, dy) {
    this.x += dx;
    this.y += dy;
  }

  /** Where the fitted drawing's device pixel `[px, py]` is shown. */
  toScreen([px, py]) {
    return [this.k * px + this.x, this.k * py + this.y];
  }

  /** Which fitted drawing's device pixel is shown at `[sx, sy]`. */
  fromScreen([sx, sy]) {
    return [(sx - this.x) / this.k, (sy - this.y) / this.k];
  }

  isIdentity() {
    return this.k === 1 && this.x === 0 && this.y === 0;
  }

  /** The transform as plain data, for a worker: `{k, x, y}`. */
  toJSON() {
    return { k: this.k, x: this.x, y: this.y };
  }
}

/**
 * Puts the view `{k, x, y}` (a Zoom's `toJSON`; null or undefined: none)
 * in front of `ctx`'s current transform; returns its scale (1 without).
 */
export function applyView(ctx, view) {
  if (!view || (view.k === 1 && view.x === 0 && view.y === 0)) return 1;
  const m = ctx.getTransform();
  ctx.setTransform(new DOMMatrix([view.k, 0, 0, view.k, view.x, view.y]).multiply(m));
  return view.k;
}

/** The wheel's scroll in pixels, whatever unit the browser reports it in. */
function wheelPixels(e) {
  return e.deltaY * (e.deltaMode === 1 ? 16 : e.deltaMode === 2 ? 400 : 1);
}

/**
 * Lets the user zoom and pan `element` (a canvas): the wheel zooms about
 * the pointer, one pointer dragging pans, two pinch. `changed()` is called
 * after each change. While `active()` is false the canvas is left alone
 * (it uses the wheel and drags for something else then, as placing a map
 * by hand does). Returns a function that removes the listeners.
 */
export function attachZoom(element, zoom, changed, { active = () => true } = {}) {
  const dpr = () => window.devicePixelRatio || 1;
  const at = (e) => {
    const r = element.getBoundingClientRect();
    return [(e.clientX - r.left) * dpr(), (e.clientY - r.top) * dpr()];
  };
  const pointers = new Map();
  const wheel = (e) => {
    if (!active()) return;
    e.preventDefault();
    const [cx, cy] = at(e);
    zoom.zoomAt(cx, cy, Math.exp(-wheelPixels(e) * 0.002));
    changed();
  };
  const down = (e) => {
    if (e.button !== 0 || !active()) return;
    element.setPointerCapture?.(e.pointerId);
    pointers.set(e.pointerId, at(e));
    element.classList.add('panning');
  };
  const move = (e) => {
    const last = pointers.get(e.pointerId);
    if (!last) return;
    const now = at(e);
    if (pointers.size === 2) {
      const [other] = [...pointers.entries()].filter(([id]) => id !== e.pointerId).map(([, p]) => p);
      const mid = (a, b) => [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
      const [m0, m1] = [mid(last, other), mid(now, other)];
      const d0 = Math.hypot(last[0] - other[0], last[1] - other[1]);
      const d1 = Math.hypot(now[0] - other[0], now[1] - other[1]);
      zoom.pan(m1[0] - m0[0], m1[1] - m0[1]);
      if (d0 > 0 && d1 > 0) zoom.zoomAt(m1[0], m1[1], d1 / d0);
    } else if (pointers.size === 1) {
      zoom.pan(now[0] - last[0], now[1] - last[1]);
    }
    pointers.set(e.pointerId, now);
    changed();
  };
  const up = (e) => {
    pointers.delete(e.pointerId);
    if (!pointers.size) element.classList.remove('panning');
  };
  const listeners = [['wheel', wheel, { passive: false }], ['pointerdown', down], ['pointermove', move], ['pointerup', up], ['pointercancel', up]];
  for (const [type, f, o] of listeners) element.addEventListener(type, f, o);
  element.style.touchAction = 'none';
  return () => {
    for (const [type, f, o] of listeners) element.removeEventListener(type, f, o);
  };
}
