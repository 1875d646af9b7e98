// The merge's verdict in plain words, for the merge panel, the status line
// and the run summary alike.
//
// A method judges a merge by what the robots saw; the lab also knows the
// ground truth (for scoring only, the methods never see it). A merge whose
// transform puts a robot's map more than WRONG_M metres or WRONG_DEG
// degrees from where it really belongs is a wrong merge, however confident
// the method is (exercise 5: one texture everywhere, and the thesis
// method's best pair joins two different walls), and the page says so.

export const WRONG_M = 0.5;
export const WRONG_DEG = 5;

/** The worst joined robot's error against the truth (the first robot, the
 *  reference frame, left out), or null. */
export function worstError(report) {
  const first = report?.transforms?.[0]?.robot;
  let worst = null;
  for (const e of report?.errors ?? []) {
    if (e.robot === first) continue;
    if (!worst || e.error_m > worst.error_m) worst = e;
  }
  return worst;
}

/** Is one robot's transform error beyond what a right merge can be off? */
export const isWrong = (e) => Boolean(e) && (e.error_m > WRONG_M || Math.abs(e.error_deg) > WRONG_DEG);

/** A merged report whose worst robot is wrong: that robot's error; else null. */
export function wrongMerge(report) {
  if (report?.status !== 'merged') return null;
  const first = report.transforms?.[0]?.robot;
  const bad = (report.errors ?? []).filter((e) => e.robot !== first && isWrong(e));
  if (!bad.length) return null;
  return bad.reduce((a, b) => (b.error_m > a.error_m ? b : a));
}

/** "robot2's map is 16.2 m and 90° from where it belongs". */
export function wrongWords(e) {
  return `${e.robot}\u2019s map is placed ${e.error_m.toFixed(1)} m and ${Math.abs(e.error_deg).toFixed(0)}\u00b0 ` +
    'from where it really belongs';
}

/**
 * The method's reason without repeating the verdict, in plain words: its
 * terms explained, no status names (`merged`, `no_merge`) and no "inf
 * times" (a margin over a rival that does not exist).
 */
export function plainReason(reason) {
  return String(reason ?? '')
    .replace(/^merged: /, '')
    .replace(/: merged: /g, ': ')
    .replace(/: no_merge: /g, ': no merge, ')
    .replace(/\bno_merge\b/g, 'no merge')
    .replace(/\binf times\b/g, 'incomparably more than')
    .replace(/(\d+) wall cells\b/, '$1 wall cells (grid cells that are wall in both maps once joined)');
}

/** The verdict's headline: "Merged (confidence 0.92)", "Merged, but WRONG…", "No merge". */
export function verdictTitle(report, fmt) {
  if (report.status !== 'merged') return 'No merge';
  const wrong = wrongMerge(report);
  const conf = `confidence ${fmt(report.confidence)}`;
  return wrong ? `Wrong merge (${conf}): ${wrongWords(wrong)}` : `Merged (${conf})`;
}
