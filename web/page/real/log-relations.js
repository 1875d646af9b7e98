// The SLAM benchmark's relations in "Your log", on the log worker's side
// (log-worker.js; issue 54).
//
// R. Kümmerle et al., "On measuring the accuracy of SLAM algorithms",
// Autonomous Robots 27(4), 2009, scored SLAM on the raw Freiburg logs by
// relations: pairs of scans matched and checked by hand, each line of a
// `.relations` file `t1 t2 x y z roll pitch yaw`, the pose of the scan
// stamped t2 in the frame of the scan stamped t1. A trajectory's error on
// one relation is δ = (p_t1⁻¹ ⊕ p_t2)⁻¹ ⊕ r, translational |δ.xy| and
// rotational |δ.θ|; the replay scores them (web/log-replay.js:
// `setRelations`, `relationScore`; crate/src/slam/eval/
// benchmark_relations.rs), here for the scans replayed so far.
//
// A `.relations` file picked or dropped with logs or bags, or on its own
// while they are open, goes with the log whose name has its stem
// (`aces.relations` with `aces.bag` or `aces.clf.gz`), or, when it is the
// only relations file and one log was opened with it (or one log is open),
// with that one. Every robot made from that log scores against it; a
// stretch of the log scores only the relations whose two scans it
// replayed (the others count as unmatched). What goes to the page is what
// it shows: the counts and spreads, the worst relations with the scans
// they join, and each relation's error as a flat `[time, metres, …]`
// list, the time that of its later scan since the log's first scan. Once
// a replay is finished, its relations are also checked against their own
// scans and the wheels (`relationCheckFigures`, as `run-log
// --check-relations` does).

import { LogReplay } from '../../log-replay.js';

/** The name a relations file has. */
export const RELATIONS_NAME = /\.relations$/i;
/** How many of the worst relations the page shows and draws. */
export const WORST_SHOWN = 5;
/** A file larger than this is not a relations file (the benchmark's are under 300 kB). */
const MAX_RELATIONS_BYTES = 64 << 20;

const message = (e) => (e instanceof Error ? e.message : String(e));
const baseName = (p) => String(p).split(/[\\/]/).pop();

/** Splits picked or dropped entries (`[{file, path}]`) into relations files and the rest. */
export function splitRelations(entries) {
  const relations = entries.filter((e) => RELATIONS_NAME.test(e.path));
  return { relations, rest: entries.filter((e) => !relations.includes(e)) };
}

/**
 * Which log each relations file goes with: `files` ([{file, path}]),
 * `logs` all logs open, `openedNow` those opened with them, `stem(name)`
 * a name without folder and extension. Returns `{pairs: [{entry, log}],
 * errors: [text]}`.
 */
export function matchRelations(files, logs, openedNow, stem) {
  const pairs = [];
  const errors = [];
  const unmatched = [];
  for (const entry of files) {
    const name = baseName(entry.path);
    const same = logs.filter((l) => stem(l.name) === stem(name));
    if (same.length === 1) pairs.push({ entry, log: same[0] });
    else if (same.length > 1) errors.push(`${name}: ${same.map((l) => l.name).join(' and ')} are both called ${stem(name)}; clear the logs and open it with one of them`);
    else unmatched.push(entry);
  }
  const only = openedNow.length === 1 ? openedNow[0] : !openedNow.length && logs.length === 1 ? logs[0] : null;
  if (unmatched.length === 1 && files.length === 1 && only) {
    pairs.push({ entry: unmatched[0], log: only });
    return { pairs, errors };
  }
  for (const entry of unmatched) {
    const name = baseName(entry.path);
    errors.push(
      logs.length
        ? `${name}: no open log or bag is called ${stem(name)} (open: ${logs.map((l) => l.name).join(', ')}); name it after its log (aces.relations goes with aces.bag), or pick or drop it together with that one log`
        : `${name}: no log or bag is open to score it against; pick or drop it together with its log or bag`,
    );
  }
  return { pairs, errors };
}

/** A relations file's text; throws, naming the file, when it is too large to be one. */
export async function relationsText(entry) {
  const name = baseName(entry.path);
  if (entry.file.size > MAX_RELATIONS_BYTES) throw new Error(`${name}: ${entry.file.size} bytes is too large for a relations file`);
  return entry.file.text();
}

/**
 * Sets `text` (of the file `name`) as the relations of every replay in
 * `replays`; returns how many relations it holds. A malformed file throws
 * the line at fault, naming the file, before any replay has changed (the
 * first replay parses it, and keeps what it had when it cannot).
 */
export function setRelations(replays, name, text) {
  let count = 0;
  for (const replay of replays) {
    try {
      count = replay.setRelations(text);
    } catch (e) {
      throw new Error(`${name}: ${message(e).replace(/^relations: /, '')}`);
    }
  }
  return count;
}

/**
 * The time of `log`'s first laser record (s): a replay of that record
 * alone, finished, reports it. Kept on the log (`firstTime`). `wasm`: the
 * loaded wasm-bindgen module.
 */
export function firstScanTime(wasm, log) {
  if (log.firstTime !== undefined) return log.firstTime;
  const probe = log.bag ? log.bag.replay(LogReplay, log.picks) : LogReplay.open(wasm, log.bytes);
  try {
    probe.setRange(0, 0);
    probe.finish();
    log.firstTime = probe.report().scans[0]?.time ?? null;
  } finally {
    probe.free();
  }
  return log.firstTime;
}

/**
 * What the page shows of a replay scored against its relations (`file`
 * their file's name, `t0` the log's first scan time): `{file, count,
 * matched, trans_m, rot_deg, worst, errors}`, `worst` the WORST_SHOWN
 * largest translational errors `{t1, t2, scan1, scan2, trans_m, rot_deg,
 * at}` (`at` the later scan's time since `t0`; `scan1`, `scan2` the scans'
 * places in the replay's view), `errors` a Float64Array `[at, trans_m,
 * …]` in the file's order.
 */
export function relationFigures(replay, file, t0) {
  const s = replay.relationScore();
  const start = t0 ?? Math.min(...s.errors.map((e) => Math.min(e.t1, e.t2)));
  const at = (e) => Math.max(e.t1, e.t2) - start;
  const errors = new Float64Array(2 * s.errors.length);
  s.errors.forEach((e, i) => {
    errors[2 * i] = at(e);
    errors[2 * i + 1] = e.trans_m;
  });
  const worst = s.worst.slice(0, WORST_SHOWN).map(({ t1, t2, scan1, scan2, trans_m, rot_deg }) => ({ t1, t2, scan1, scan2, trans_m, rot_deg, at: at({ t1, t2 }) }));
  return { file, count: s.count, matched: s.matched, trans_m: s.trans_m, rot_deg: s.rot_deg, worst, errors };
}

/**
 * A finished replay's relations checked against their own scans and the
 * wheels (`run-log --check-relations`), as the page shows it: the counts,
 * how far the relations and the replay each lie from what the scans
 * settle, and the errors against the relations no witness contradicts.
 */
export function relationCheckFigures(replay) {
  const c = replay.relationCheck();
  if (!c) return null;
  const { checked, settled, by_scans, by_odometry, relations_vs_scans, ours_vs_scans, uncontradicted, trans_m, rot_deg } = c;
  return { checked, settled, by_scans, by_odometry, relations_vs_scans, ours_vs_scans, uncontradicted, trans_m, rot_deg };
}
