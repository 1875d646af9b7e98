// Canvases at the screen's pixel density. A canvas's backing store is
// sized to its CSS box times `devicePixelRatio`, and its context is scaled
// so that the panels keep drawing in their own logical units (a 300 × 70
// plot stays 300 × 70 in the code); on a HiDPI screen the lines and text
// are then drawn at 2×, not stretched from 1×. The world canvas does the
// same in web/page/world-view.js.
//
// Reading a canvas's `clientWidth` after the page changed forces the
// browser to lay the page out there and then; with many panels redrawn
// while a run goes, that dominated the frame (issue 22). So each canvas's
// CSS width is read once and then kept up to date by a ResizeObserver,
// which reports it after layout, when it is free to read. A backing store
// is reassigned only when its size really changes (assigning `width`
// reallocates and clears the canvas even to the same value).

/** The device pixel ratio (1 where there is none). */
export const dpr = () => (typeof window !== 'undefined' && window.devicePixelRatio) || 1;

/** CSS widths of the canvases seen so far (0: not laid out, read again). */
const cssWidths = new WeakMap();
let observer = null;

/** How many times a backing store was resized: for the page tests. */
export const fitStats = { resized: 0 };

function cssWidth(canvas) {
  const known = cssWidths.get(canvas);
  if (known) return known;
  const w = canvas.clientWidth;
  cssWidths.set(canvas, w);
  if (known === undefined && typeof ResizeObserver !== 'undefined') {
    observer ??= new ResizeObserver((entries) => {
      for (const e of entries) cssWidths.set(e.target, e.target.clientWidth);
    });
    observer.observe(canvas);
  }
  return w;
}

/**
 * Sizes `canvas` for a drawing of `w × h` logical units shown at its CSS
 * width (or at `w` CSS pixels while it is not laid out), and returns its
 * 2-D context scaled from logical units to device pixels.
 */
export function fitCanvas(canvas, w, h) {
  const cssW = cssWidth(canvas) || w;
  const bw = Math.max(1, Math.round(cssW * dpr()));
  const bh = Math.max(1, Math.round((bw * h) / w));
  if (canvas.width !== bw || canvas.height !== bh) fitStats.resized++;
  if (canvas.width !== bw) canvas.width = bw;
  if (canvas.height !== bh) canvas.height = bh;
  const ctx = canvas.getContext('2d');
  ctx.setTransform(bw / w, 0, 0, bh / h, 0, 0);
  return ctx;
}
