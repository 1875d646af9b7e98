// What a run's SLAM error is made of, robot by robot (issue 22's ATE): the
// SLAM path (`robots[].estimate`, in the robot's start frame) against the
// truth moved into that frame, fitted by a similarity (Umeyama 1991: the
// rotation, translation and scale that best lay the truth on the estimate).
// A path that is right but turned about its start has a large start-aligned
// ATE (`slam.ate_m`), a small residual after the fit, and the turn as its
// `rotation`; a path stretched by odometry's scale shows it in `scale`.
// Then the heading error every `--every` seconds over the first `--until`
// seconds (odometry's in brackets), to see when a turn came in.
//
// Usage: node web/cli.mjs run S.json --json > R.json
//        node tests/bench/slam_shape.mjs R.json [--robots 7,11,15] [--every 10] [--until 300]
import { readFileSync } from 'node:fs';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const at = args.indexOf(name);
  return at >= 0 ? args[at + 1] : fallback;
};
const report = JSON.parse(readFileSync(args[0], 'utf8'));
const every = Number(option('--every', '10'));
const until = Number(option('--until', '300'));
const chosen = option('--robots', '');
const wanted = chosen ? new Set(chosen.split(',').map((n) => `robot${n}`)) : null;
const wrap = (t) => Math.atan2(Math.sin(t), Math.cos(t));
const deg = (t) => (t * 180) / Math.PI;

/** The truth's poses in its start frame, as [time, x, y, theta]. */
function inStartFrame(truth) {
  const [, x0, y0, t0] = truth[0];
  const [c, s] = [Math.cos(t0), Math.sin(t0)];
  return truth.map(([t, x, y, th]) => {
    const [dx, dy] = [x - x0, y - y0];
    return [t, c * dx + s * dy, -s * dx + c * dy, wrap(th - t0)];
  });
}

/** The similarity Q ≈ scale · R(rotation) · P + t of two point lists, and its residuals. */
function similarity(P, Q) {
  const n = P.length;
  const mean = (A) => A.reduce((m, p) => [m[0] + p[0] / n, m[1] + p[1] / n], [0, 0]);
  const [mp, mq] = [mean(P), mean(Q)];
  let [sxx, sxy, vp] = [0, 0, 0];
  for (let k = 0; k < n; k++) {
    const [ax, ay] = [P[k][0] - mp[0], P[k][1] - mp[1]];
    const [bx, by] = [Q[k][0] - mq[0], Q[k][1] - mq[1]];
    sxx += ax * bx + ay * by;
    sxy += ax * by - ay * bx;
    vp += ax * ax + ay * ay;
  }
  const rotation = Math.atan2(sxy, sxx);
  const scale = Math.hypot(sxx, sxy) / vp;
  const [c, s] = [Math.cos(rotation), Math.sin(rotation)];
  const rms = (f) => {
    let e = 0;
    for (let k = 0; k < n; k++) {
      const [ax, ay] = [P[k][0] - mp[0], P[k][1] - mp[1]];
      const [x, y] = [f * (c * ax - s * ay) + mq[0], f * (s * ax + c * ay) + mq[1]];
      e += (x - Q[k][0]) ** 2 + (y - Q[k][1]) ** 2;
    }
    return Math.sqrt(e / n);
  };
  return { rotation, scale, rigid: rms(1), similar: rms(scale) };
}

for (const robot of report.robots) {
  if (wanted && !wanted.has(robot.name)) continue;
  const truth = inStartFrame(robot.truth);
  const fit = similarity(
    truth.map((p) => [p[1], p[2]]),
    robot.estimate.map((p) => [p[1], p[2]]),
  );
  console.log(
    `${robot.name} (${robot.follow}): ATE ${robot.slam.ate_m.toFixed(3)} m from the start, ` +
      `${fit.rigid.toFixed(3)} m after the best turn and shift (turned ${deg(fit.rotation).toFixed(3)} deg), ` +
      `${fit.similar.toFixed(3)} m with scale ${fit.scale.toFixed(5)}`,
  );
  const line = [];
  for (let k = 0; k < truth.length && truth[k][0] <= until + 1e-9; k++) {
    if (Math.abs(truth[k][0] / every - Math.round(truth[k][0] / every)) > 1e-6) continue;
    const slam = deg(wrap(robot.estimate[k][3] - truth[k][3]));
    const odometry = deg(wrap(robot.odometry[k][3] - truth[k][3]));
    line.push(`${truth[k][0].toFixed(0)} s ${slam.toFixed(2)} (${odometry.toFixed(1)})`);
  }
  console.log(`  heading error, deg: ${line.join(', ')}`);
}
