// Does a picked image look like an occupancy grid? (used by the merge worker)
//
// A ROS map_server image holds three kinds of cell: free (near white),
// occupied (near black) and unknown (a middle grey, 205 in map_saver's
// files), so its grey histogram has a few tall peaks that hold almost all
// of its pixels, even in a map saved with graded (`scale`) shades. A
// photograph spreads over the whole grey range: its three commonest grey
// levels hold a few per cent of its pixels. The merge reads any image, so
// this only warns, with the figures it measured.

/** Below this share of pixels in the three commonest grey levels, an image is not map-like. */
export const MIN_TOP3_SHARE = 0.5;

/**
 * Measures grey values `grey` (any array of 0..255; `skip(i)` true for
 * pixels that do not count, e.g. transparent ones): `{levels, top3}`, the
 * number of grey levels used by at least 0.1 % of the pixels and the share
 * of pixels in the three commonest levels.
 */
export function greyLevels(grey, skip = () => false) {
  const counts = new Float64Array(256);
  const step = Math.max(1, Math.floor(grey.length / 2e6)); // a large image: a sample of it
  let n = 0;
  for (let i = 0; i < grey.length; i += step) {
    if (skip(i)) continue;
    counts[grey[i]] += 1;
    n += 1;
  }
  if (!n) return { levels: 0, top3: 1 };
  const sorted = [...counts].sort((a, b) => b - a);
  return { levels: sorted.filter((c) => c >= n * 0.001).length, top3: (sorted[0] + sorted[1] + sorted[2]) / n };
}

/** The grey values of a binary 8-bit PGM (P5), or null for another image. */
function pgmGrey(bytes) {
  const head = new TextDecoder('latin1').decode(bytes.subarray(0, 256)).replace(/#[^\n]*\n/g, (c) => ' '.repeat(c.length));
  const m = /^P5\s+(\d+)\s+(\d+)\s+(\d+)\s/.exec(head);
  if (!m || Number(m[3]) > 255) return null;
  return bytes.subarray(m[0].length, m[0].length + Number(m[1]) * Number(m[2]));
}

/** `{levels, top3}` of an image file's bytes (PGM P5 or anything the browser decodes), null if unread. */
export async function imageLevels(bytes) {
  const pgm = pgmGrey(bytes);
  if (pgm) return greyLevels(pgm);
  try {
    const bitmap = await createImageBitmap(new Blob([bytes]));
    const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
    const ctx = canvas.getContext('2d');
    ctx.drawImage(bitmap, 0, 0);
    const rgba = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
    const grey = new Uint8Array(rgba.length / 4);
    for (let i = 0; i < grey.length; i++) grey[i] = Math.round((rgba[4 * i] + rgba[4 * i + 1] + rgba[4 * i + 2]) / 3);
    return greyLevels(grey, (i) => rgba[4 * i + 3] === 0);
  } catch {
    return null;
  }
}

/** A warning for an image that does not look like an occupancy grid, or '' when it does. */
export async function gridWarning(imageName, bytes) {
  const look = await imageLevels(bytes);
  if (!look || look.top3 >= MIN_TOP3_SHARE) return '';
  return `${imageName} does not look like an occupancy grid (a photograph?): it uses ${look.levels} grey levels, and its ` +
    `three commonest hold only ${Math.round(look.top3 * 100)} % of its pixels, where a map's free, occupied and unknown ` +
    'cells hold nearly all. It was read anyway; its merge means little.';
}
