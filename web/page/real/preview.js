// A map's picture for the page, made in the merge worker: the grid shrunk
// to at most MAX_SIDE pixels a side (a block shows a wall if any of its
// cells is one, else free if any is free, else unknown), walls in the
// map's colour, free space in a pale wash of it, unknown transparent, so
// that maps laid over each other show whose wall is whose. The card's
// thumbnail is cropped to the box round the known pixels (a map saved in a
// large image of unknown shows as what it knows).

export const MAX_SIDE = 1024;

/** The largest thumbnail the page shows (CSS pixels). */
export const THUMB = [250, 200];

/** `#rrggbb` as [r, g, b]. */
export function rgbOf(hex) {
  const n = parseInt(hex.slice(1), 16);
  return [(n >> 16) & 255, (n >> 8) & 255, n & 255];
}

/**
 * `grey`: map_server shades, top row first (wall < 128, free >= 250, the
 * rest unknown), `width` x `height`. Returns `{bitmap, width, height, step,
 * rows}`: an ImageBitmap of ceil(width / step) x ceil(height / step)
 * pixels, and for each of its rows with a known pixel [row, first column,
 * last column + 1] (so a view can fit what the map knows, turned any way).
 */
export async function previewOf(grey, width, height, colour) {
  const step = Math.max(1, Math.ceil(Math.max(width, height) / MAX_SIDE));
  const w = Math.ceil(width / step);
  const h = Math.ceil(height / step);
  const kind = new Uint8Array(w * h); // 0 unknown, 1 free, 2 wall
  for (let row = 0; row < height; row++) {
    const line = ((row / step) | 0) * w;
    for (let col = 0; col < width; col++) {
      const g = grey[row * width + col];
      const k = g < 128 ? 2 : g >= 250 ? 1 : 0;
      const at = line + ((col / step) | 0);
      if (k > kind[at]) kind[at] = k;
    }
  }
  const [r, g, b] = rgbOf(colour);
  const rgba = new Uint8ClampedArray(w * h * 4);
  const rows = [];
  for (let row = 0; row < h; row++) {
    let first = -1, last = -1;
    for (let col = 0; col < w; col++) {
      const i = row * w + col;
      if (kind[i] === 0) continue;
      rgba.set(kind[i] === 2 ? [r, g, b, 255] : [r, g, b, 40], i * 4);
      if (first < 0) first = col;
      last = col;
    }
    if (first >= 0) rows.push([row, first, last + 1]);
  }
  if (!rows.length) rows.push([0, 0, w], [h - 1, 0, w]);
  const bitmap = await createImageBitmap(new ImageData(rgba, w, h));
  // The card shows what the map knows: the box round its known pixels, not the unknown around it.
  const [x0, y0, cw, ch] = knownBox(rows, w, h);
  const k = Math.min(1, THUMB[0] / cw, THUMB[1] / ch);
  const thumb = await createImageBitmap(bitmap, x0, y0, cw, ch, {
    resizeWidth: Math.max(1, Math.round(cw * k)),
    resizeHeight: Math.max(1, Math.round(ch * k)),
    resizeQuality: 'high',
  });
  return { bitmap, thumb, width: w, height: h, step, rows };
}

/** `[x, y, width, height]` of the box round the known pixels (`rows` as previewOf makes them), a margin of one pixel. */
export function knownBox(rows, w, h) {
  const top = Math.max(0, rows[0][0] - 1), bottom = Math.min(h, rows[rows.length - 1][0] + 2);
  const left = Math.max(0, Math.min(...rows.map((r) => r[1])) - 1);
  const right = Math.min(w, Math.max(...rows.map((r) => r[2])) + 1);
  return [left, top, Math.max(1, right - left), Math.max(1, bottom - top)];
}
