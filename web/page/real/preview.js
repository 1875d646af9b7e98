// A map's picture for the page, made in the merge worker: the grid shrunk
// to at most MAX_SIDE pixels a side (a block shows a wall if any of its
// cells is one, else free if any is free, else unknown), walls in the
// map's colour, free space in a pale wash of it, unknown transparent, so
// that maps laid over each other show whose wall is whose.

export const MAX_SIDE = 1024;

/** `#rrggbb` as [r, g, b]. */
export function rgbOf(hex) {
  const n = parseInt(hex.slice(1), 16);
  return [(n >> 16) & 255, (n >> 8) & 255, n & 255];
}

/**
 * `grey`: map_server shades, top row first (wall < 128, free >= 250, the
 * rest unknown), `width` x `height`. Returns `{bitmap, width, height, step}`:
 * an ImageBitmap of ceil(width / step) x ceil(height / step) pixels.
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
  for (let i = 0; i < w * h; i++) {
    if (kind[i] === 2) rgba.set([r, g, b, 255], i * 4);
    else if (kind[i] === 1) rgba.set([r, g, b, 40], i * 4);
  }
  const bitmap = await createImageBitmap(new ImageData(rgba, w, h));
  return { bitmap, width: w, height: h, step };
}
