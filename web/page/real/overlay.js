// Drawing the user's maps: each alone (a thumbnail) and all joined maps in
// the first map's frame (the merged overlay), every map in its colour.
//
// Frames, as in ROS: a map's YAML `origin` is the pose of its image's
// lower-left corner in the map's frame; the merge gives each joined map's
// frame as a pose in the first map's frame. So an image pixel (u, v) (v
// down from the top row) lands in the first map's frame at
//   pose ∘ origin ∘ (u · r, (h − v) · r)
// which is three canvas transforms after the view's own (metres to
// pixels, y up).

/** `a ∘ b` for poses [x, y, theta]. */
export function compose([ax, ay, at], [bx, by, bt]) {
  const c = Math.cos(at), s = Math.sin(at);
  return [ax + c * bx - s * by, ay + s * bx + c * by, at + bt];
}

/** The corners of map `m`'s image in the frame where its map frame is `pose`. */
export function corners(m, pose) {
  const [x, y, t] = compose(pose, m.origin);
  const c = Math.cos(t), s = Math.sin(t);
  const w = m.width * m.resolution, h = m.height * m.resolution;
  return [[0, 0], [w, 0], [w, h], [0, h]].map(([u, v]) => [x + c * u - s * v, y + s * u + c * v]);
}

/** Sizes `canvas` to its box (device pixels) and returns its 2-D context, cleared. */
function fresh(canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, w, h);
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, w, h);
  return ctx;
}

/** Draws map `m`'s picture with its map frame at `pose` (view transform set). */
function drawMap(ctx, m, pose) {
  const [x, y, t] = compose(pose, m.origin);
  const r = m.resolution;
  ctx.save();
  ctx.transform(Math.cos(t), Math.sin(t), -Math.sin(t), Math.cos(t), x, y);
  ctx.transform(r, 0, 0, -r, 0, m.height * r);
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(m.preview.bitmap, 0, 0, m.width, m.height);
  ctx.restore();
}

/** A scale bar of a round length in the lower-left corner. */
function scaleBar(ctx, k, height) {
  const dpr = window.devicePixelRatio || 1;
  const want = (120 * dpr) / k;
  const len = [0.5, 1, 2, 5, 10, 20, 50, 100, 200, 500].find((l) => l >= want / 2) ?? 1000;
  const x0 = 12 * dpr, y0 = height - 12 * dpr;
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.strokeStyle = '#222';
  ctx.lineWidth = 2 * dpr;
  ctx.beginPath();
  ctx.moveTo(x0, y0);
  ctx.lineTo(x0 + len * k, y0);
  ctx.stroke();
  ctx.fillStyle = '#222';
  ctx.font = `${12 * dpr}px sans-serif`;
  ctx.fillText(`${len} m`, x0, y0 - 5 * dpr);
}

/**
 * Draws `placed` ([{map, pose}]: maps with their map frame's pose in one
 * common frame) fitted into `canvas`; `alpha` the maps' opacity.
 */
export function drawPlaced(canvas, placed, alpha = 1) {
  const ctx = fresh(canvas);
  if (!placed.length) return;
  const pts = placed.flatMap(({ map, pose }) => corners(map, pose));
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const pad = 8 * (window.devicePixelRatio || 1);
  const k = Math.min((canvas.width - 2 * pad) / (x1 - x0 || 1), (canvas.height - 2 * pad) / (y1 - y0 || 1));
  const ox = (canvas.width - k * (x1 - x0)) / 2, oy = (canvas.height - k * (y1 - y0)) / 2;
  ctx.setTransform(k, 0, 0, -k, ox - k * x0, oy + k * y1);
  ctx.globalAlpha = alpha;
  for (const { map, pose } of placed) drawMap(ctx, map, pose);
  ctx.globalAlpha = 1;
  scaleBar(ctx, k, canvas.height);
}
