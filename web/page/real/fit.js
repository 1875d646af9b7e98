// The two steps every drawing of the "Your maps" and "Your log" views
// begins with (overlay.js, log-draw.js): size and clear the canvas, then
// fit a box of the world (metres, y up) into a rectangle of it, which sets
// the view transform (only the renderer flips y).

/** Sizes `canvas` to `width` x `height` device pixels, fills it with `fill`; returns its 2-D context. */
export function clearCanvas(canvas, width, height, fill) {
  if (canvas.width !== width || canvas.height !== height) {
    canvas.width = width;
    canvas.height = height;
  }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.fillStyle = fill;
  ctx.fillRect(0, 0, width, height);
  return ctx;
}

/**
 * Sets `ctx`'s transform so that the world box `[x0, y0, x1, y1]` fills
 * the rectangle `[left, top, width, height]` (device pixels) less `pad`
 * on each side, centred, y up; returns the scale k (pixels a metre).
 */
export function fitBox(ctx, [x0, y0, x1, y1], [left, top, width, height], pad) {
  const k = Math.min((width - 2 * pad) / (x1 - x0 || 1), (height - 2 * pad) / (y1 - y0 || 1));
  const ox = left + (width - k * (x1 - x0)) / 2, oy = top + (height - k * (y1 - y0)) / 2;
  ctx.setTransform(k, 0, 0, -k, ox - k * x0, oy + k * y1);
  return k;
}
