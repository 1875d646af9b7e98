// Robots' maps as ROS bags: a saved map's cells written as the last
// nav_msgs/OccupancyGrid on /map of an MCAP (CDR), as a robot recording its
// SLAM's map leaves it. Used by tests/bag-maps.test.mjs (merge-maps) and
// tests/page-real.test.mjs ("Your maps…").
import { Bytes, MCAP_MAGIC, mcap } from './bags.mjs';

/** The cells of a binary PGM as nav_msgs/OccupancyGrid data: rows from the bottom, 0 free, 100 wall, -1 unknown. */
export function gridOf(pgm) {
  const text = pgm.subarray(0, 32).toString('latin1');
  const [, w, h] = text.match(/^P5\s+(\d+)\s+(\d+)\s+255\s/).map(Number);
  const start = pgm.length - w * h;
  const data = new Int8Array(w * h);
  for (let row = 0; row < h; row++) {
    for (let col = 0; col < w; col++) {
      const v = pgm[start + (h - 1 - row) * w + col];
      data[row * w + col] = v === 254 ? 0 : v === 0 ? 100 : -1;
    }
  }
  return { w, h, data };
}

/** An OccupancyGrid in CDR: header, map metadata (origin at `origin` [x, y, yaw]), cells. */
export function occupancyGrid({ w, h, data }, origin, res = 0.05) {
  const b = new Bytes({ cdr: true });
  b.i32(1700000000).u32(0).string('map');
  b.i32(0).u32(0).f32(res).u32(w).u32(h);
  b.f64(origin[0]).f64(origin[1]).f64(0);
  b.f64(0).f64(0).f64(Math.sin(origin[2] / 2)).f64(Math.cos(origin[2] / 2));
  b.u32(data.length).raw(Buffer.from(data.buffer));
  return b.bytes();
}

/** An MCAP holding one /map message (no chunks, no summary: a linear read takes it). */
export function mapBag(grid, origin) {
  return Buffer.concat([
    MCAP_MAGIC, mcap.header(),
    mcap.schema(1, 'nav_msgs/msg/OccupancyGrid'), mcap.channel(1, 1, '/map'),
    mcap.message(1, 0, 1700000000000000000n, occupancyGrid(grid, origin)),
    mcap.dataEnd(), mcap.footer(), MCAP_MAGIC,
  ]);
}

