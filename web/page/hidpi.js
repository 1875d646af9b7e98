// Canvases at the screen's pixel density. A canvas's backing store is
// sized to its CSS box times `devicePixelRatio`, and its context is scaled
// so that the panels keep drawing in their own logical units (a 300 × 70
// plot stays 300 × 70 in the code); on a HiDPI screen the lines and text
// are then drawn at 2×, not stretched from 1×. The world canvas does the
// same in web/page/world-view.js.

/** The device pixel ratio (1 where there is none). */
export const dpr = () => (typeof window !== 'undefined' && window.devicePixelRatio) || 1;

/**
 * Sizes `canvas` for a drawing of `w × h` logical units shown at its CSS
 * width (or at `w` CSS pixels while it is not laid out), and returns its
 * 2-D context scaled from logical units to device pixels.
 */
export function fitCanvas(canvas, w, h) {
  const cssW = canvas.clientWidth || w;
  const bw = Math.max(1, Math.round(cssW * dpr()));
  const bh = Math.max(1, Math.round((bw * h) / w));
  if (canvas.width !== bw) canvas.width = bw;
  if (canvas.height !== bh) canvas.height = bh;
  const ctx = canvas.getContext('2d');
  ctx.setTransform(bw / w, 0, 0, bh / h, 0, 0);
  return ctx;
}
