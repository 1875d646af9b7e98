// The merge report (web/cli/merge-maps.mjs prints the same one) in the
// words and numbers the page shows: the verdict line, each map's transform
// in metres and degrees and as the arguments of ROS's
// `static_transform_publisher`, and each pair's own verdict. Maps of two
// buildings merge into groups (the report's `merge.groups`, each joined in
// the frame of its first map): the verdict then names every group, and the
// transforms and their JSON are those of one group.

const deg = (rad) => (rad * 180) / Math.PI;

/** A ROS frame name for a map file: its name without folder and extension. */
export function frameName(file) {
  return String(file).split(/[\\/]/).pop().replace(/\.[^.]*$/, '').replace(/[^\w]+/g, '_') || 'map';
}

/** Names of the maps joined by a placement kept by hand (not the reference of `merge`'s transforms). */
export function unverifiedMaps(merge) {
  const reference = merge.transforms[0]?.map;
  return new Set(merge.pairs.filter((p) => p.verified === false).flatMap((p) => [p.a, p.b]).filter((m) => m !== reference));
}

/** The groups of two or more maps, with their positions in `merge.groups`. */
export function joinedGroups(merge) {
  return (merge.groups ?? []).map((g, k) => ({ ...g, k })).filter((g) => g.maps.length > 1);
}

/** "a, b and c". */
export function nameList(names) {
  return names.length < 2 ? names.join('') : `${names.slice(0, -1).join(', ')} and ${names[names.length - 1]}`;
}

/**
 * "Merged (confidence 0.93): …", "No merge, because …", or, for a view
 * that shows the groups (`groups`), with maps of several buildings
 * "Merged into 2 groups: a + b; c + d." (and the maps left alone);
 * `name(map)` is how a map is called.
 */
export function verdictText(merge, name = (m) => m, groups = false) {
  const joined = groups ? joinedGroups(merge) : [];
  const several = joined.length > 1 || (joined.length === 1 && merge.status !== 'merged');
  if (several) {
    const alone = (merge.groups ?? []).filter((g) => g.maps.length === 1).map((g) => name(g.maps[0]));
    const head = joined.length > 1 ? `Merged into ${joined.length} groups that share no wall with each other` : 'Merged in part';
    const list = joined.map((g) => g.maps.map(name).join(' + ') + (g.verified === false ? ' (placed by hand, not verified)' : '')).join('; ');
    const rest = alone.length ? `; ${nameList(alone)} ${alone.length > 1 ? 'join' : 'joins'} no other map (see each pair's verdict)` : '';
    return `${head}: ${list}${rest}.`;
  }
  if (merge.status === 'merged' && merge.verified === false) return `Merged where you placed a map, not verified by the merge's tests: ${merge.reason}`;
  if (merge.status === 'merged') return `Merged (confidence ${merge.confidence.toFixed(2)}): ${merge.reason}`;
  return `No merge, because ${merge.reason}`;
}

/**
 * One row per joined map but the reference (the first, whose frame the
 * others are given in: tf2 refuses a transform of a frame to itself):
 * `{map, x, y, deg, args}`, `args` the arguments of `rosrun tf2_ros
 * static_transform_publisher x y z yaw pitch roll parent child` that
 * publish the map's frame in the reference map's frame.
 */
export function transformRows(merge) {
  const parent = frameName(merge.transforms[0]?.map ?? 'map');
  return merge.transforms.slice(1).map(({ map, pose: [x, y, th] }) => ({
    map,
    x: x.toFixed(3),
    y: y.toFixed(3),
    deg: deg(th).toFixed(2),
    args: `${x.toFixed(4)} ${y.toFixed(4)} 0 ${th.toFixed(6)} 0 0 ${parent} ${frameName(map)}`,
  }));
}

/**
 * The transforms as the JSON the page offers for download; with several
 * groups, those of group `group` (its position in `merge.groups`), in the
 * frame of its first map.
 */
export function transformsJson(report, group = -1) {
  const g = report.merge.groups?.[group];
  const merge = g ? { ...report.merge, transforms: g.transforms } : report.merge;
  const rows = transformRows(merge);
  const out = {
    status: g ? 'merged' : merge.status,
    verified: (g ?? report.merge).verified !== false,
    reason: g ? verdictText(report.merge, undefined, true) : merge.reason,
    confidence: g ? g.confidence : merge.confidence,
    frame: frameName(merge.transforms[0]?.map ?? ''),
    transforms: merge.transforms.map((t, i) => (i ? { ...t, static_transform_publisher: rows[i - 1].args } : { ...t, reference: true })),
    unjoined: g ? report.merge.groups.flatMap((o) => (o === g ? [] : o.maps)) : merge.unjoined,
    pairs: merge.pairs,
  };
  if (g) out.group = joinedGroups(report.merge).findIndex((j) => j.k === group) + 1;
  return JSON.stringify(out, null, 2);
}
