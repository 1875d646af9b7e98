// The merge report (web/cli/merge-maps.mjs prints the same one) in the
// words and numbers the page shows: the verdict line, each map's transform
// in metres and degrees and as the arguments of ROS's
// `static_transform_publisher`, and each pair's own verdict.

const deg = (rad) => (rad * 180) / Math.PI;

/** A ROS frame name for a map file: its name without folder and extension. */
export function frameName(file) {
  return String(file).split(/[\\/]/).pop().replace(/\.[^.]*$/, '').replace(/[^\w]+/g, '_') || 'map';
}

/** "Merged (confidence 0.93): …" or "No merge, because …". */
export function verdictText(merge) {
  if (merge.status === 'merged') return `Merged (confidence ${merge.confidence.toFixed(2)}): ${merge.reason}`;
  return `No merge, because ${merge.reason}`;
}

/**
 * One row per joined map: `{map, x, y, deg, args}`, `args` the arguments
 * of `rosrun tf2_ros static_transform_publisher x y z yaw pitch roll
 * parent child` that publish the map's frame in the first map's frame.
 */
export function transformRows(merge) {
  const parent = frameName(merge.transforms[0]?.map ?? 'map');
  return merge.transforms.map(({ map, pose: [x, y, th] }) => ({
    map,
    x: x.toFixed(3),
    y: y.toFixed(3),
    deg: deg(th).toFixed(2),
    args: `${x.toFixed(4)} ${y.toFixed(4)} 0 ${th.toFixed(6)} 0 0 ${parent} ${frameName(map)}`,
  }));
}

/** The transforms as the JSON the page offers for download. */
export function transformsJson(report) {
  const rows = transformRows(report.merge);
  return JSON.stringify(
    {
      status: report.merge.status,
      reason: report.merge.reason,
      confidence: report.merge.confidence,
      frame: frameName(report.merge.transforms[0]?.map ?? ''),
      transforms: report.merge.transforms.map((t, i) => ({ ...t, static_transform_publisher: rows[i].args })),
      unjoined: report.merge.unjoined,
      pairs: report.merge.pairs,
    },
    null,
    2,
  );
}
