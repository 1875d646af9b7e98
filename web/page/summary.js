// A printable summary of a run: what a teacher pins to the wall or a
// student hands in.
//
// One page, built from what the lab shows: the scenario and seed (with the
// link that restores them), the world with the robots' paths, each robot's
// figures and position-error plot, the merge verdict with the transforms and
// their errors against the ground truth, the thesis's §6.2.4 numbers when
// that method ran, the matched-pair table, the merged map, and the transform
// error of every method merged on this run. The page's print stylesheet
// (web/style.css, `@media print`) prints only this view, so Ctrl+P anywhere
// prints it too (`Summary` rebuilds it on `beforeprint`).
//
// `Summary` gathers the data: the run's figures from the Lab, and from each
// panel what it shows, through the panel's own method (the world view's
// `snapshot`, the maps panel's `plots`, the merge panel's `summary`), as
// PNG data URLs taken when the summary is built. `buildSummary` only lays
// the data out.
import { deg, el, fmt } from './dom.js';
import { message, setStatus } from './status.js';
import { isWrong, plainReason, verdictTitle, wrongMerge } from './merge-words.js';
import { aloneReason } from './merge-groups.js';

const pct = (x) => (Number.isFinite(x) ? `${(100 * x).toFixed(0)} %` : '–');

function table(caption, head, rows) {
  return el('table', { class: 'summary-table' },
    el('caption', { text: caption }),
    el('tr', {}, ...head.map((h) => el('th', { text: h }))),
    ...rows.map((r) => el('tr', {}, ...r.map((c) => el('td', { text: String(c) })))));
}

function figure(src, alt, caption, cls = '') {
  if (!src) return '';
  return el('figure', { class: cls }, el('img', { src, alt }), el('figcaption', { text: caption }));
}

/** With several groups of robots: the list, and each other group's merged map. */
function groupParts(m) {
  const line = (g) => (g.robots.length > 1
    ? `Group ${g.group + 1}: ${g.robots.join(', ')} \u2014 merged map in ${g.robots[0]}\u2019s frame` +
      ` (worst error ${fmt(Math.max(...g.errors.map((e) => e.error_m)), 3)} m against the ground truth)`
    : `${g.robots[0]} alone: ${aloneReason(g)}`);
  return [
    el('h3', { text: `The robots form ${m.groups.length} groups` }),
    el('ul', { class: 'summary-groups' }, ...m.groups.map((g) => el('li', { text: line(g) }))),
    el('div', { class: 'summary-figures' }, ...m.groupImages.map((g) =>
      figure(g.src, `The merged map of group ${g.group + 1}`,
        `Group ${g.group + 1}\u2019s merged map (${g.robots.join(', ')}), in ${g.robots[0]}\u2019s frame.`))),
  ];
}

const METHOD_NAMES = { auto: 'Automatic', thesis: 'Thesis §6.2', 'map-only': 'Map-only baseline' };

/**
 * Fills `host` with the summary of `data`:
 * {scenario, link, when: Date, run: {time_s, finished, steps},
 *  robots: [{name, follow, distance, frames, bumps, figures}],
 *  worldImage, plots: [{name, src}],
 *  merge: null | {report, view, tableImage, mergedImage, chartImage, results,
 *                 groups?: [{group, robots, reason?, errors}], groupImages?: [{group, robots, src}]}}
 */
export function buildSummary(host, data, { onPrint, onClose }) {
  const s = data.scenario;
  const head = el('div', { class: 'summary-head' },
    el('h1', { id: 'summary-title', text: `Run summary: “${s.name}”` }),
    el('div', { class: 'summary-buttons no-print' },
      (() => {
        const b = el('button', { type: 'button', class: 'primary', id: 'summary-print', text: 'Print…' });
        b.addEventListener('click', onPrint);
        return b;
      })(),
      (() => {
        const b = el('button', { type: 'button', id: 'summary-close', text: 'Close', 'aria-label': 'Close the summary (Esc)' });
        b.addEventListener('click', onClose);
        return b;
      })()));
  const run = data.run;
  const meta = el('p', { class: 'summary-meta' },
    `Seed ${s.seed} · ${fmt(run.time_s, 1)} s simulated of ${fmt(s.duration_s, 0)} s` +
      `${run.finished ? '' : run.steps ? ' (run not finished)' : ' (not run yet)'} · ${s.walls.length} walls · ` +
      `${s.robots.length} robots · ${data.when.toLocaleString('en-GB')}`,
    el('br'), 'Link to this scenario and seed: ', el('a', { href: data.link, text: data.link, class: 'summary-link' }));

  const parts = [head, meta];
  parts.push(el('div', { class: 'summary-figures' },
    figure(data.worldImage, 'The world with the robots\u2019 true and odometry paths',
      'The world: walls, each robot\u2019s true path (solid) and odometry path (dashed).', 'wide')));

  const robotRows = data.robots.map((r) => [
    r.name, `${r.follow} wall, ${fmt(r.distance, 2)} m`, r.frames, r.bumps,
    r.figures ? `${fmt(r.figures.ate_m)} m` : '–', r.figures ? `${fmt(r.figures.odometry_ate_m)} m` : '–',
    r.figures ? pct(r.figures.occupied_precision) : '–', r.figures ? pct(r.figures.wall_coverage) : '–',
  ]);
  parts.push(table('Robots: position error (ATE, RMS against the ground truth) of SLAM and of odometry alone',
    ['robot', 'follows', 'frames', 'bumps', 'ATE SLAM', 'ATE odometry', 'map cells on a wall', 'walls mapped (SLAM)'], robotRows));
  if (data.plots.length) {
    parts.push(el('div', { class: 'summary-figures' },
      ...data.plots.map((p) => figure(p.src, `${p.name}'s position error over time`,
        `${p.name}: position error over time (red: SLAM, dashed: odometry).`))));
  }

  const m = data.merge;
  if (!m?.report) {
    parts.push(el('p', { class: 'summary-note', text: 'The maps have not been merged on this run.' }));
  } else {
    const r = m.report;
    const merged = r.status === 'merged';
    parts.push(el('h2', { text: `Merge (${METHOD_NAMES[r.method] ?? r.method})` }));
    const wrong = wrongMerge(r);
    parts.push(el('p', { class: `summary-verdict ${wrong ? 'wrong' : merged ? 'ok' : 'no'}`,
      text: wrong ? `${verdictTitle(r, fmt)}, against the ground truth. The method’s reason: ${plainReason(r.reason)}.`
        : merged ? `${verdictTitle(r, fmt)}: ${plainReason(r.reason)}.` : `No merge, because ${plainReason(r.reason)}.` }));
    if (r.transforms.length) {
      parts.push(table('Each robot\u2019s map frame in the merged frame, and its error against the ground truth',
        ['robot', 'x (m)', 'y (m)', 'θ (°)', 'error (m)', 'error (°)'],
        r.transforms.map((t) => {
          const e = r.errors.find((x) => x.robot === t.robot);
          return [t.robot, fmt(t.pose[0]), fmt(t.pose[1]), fmt(deg(t.pose[2]), 1), e ? fmt(e.error_m, 3) : '–', e ? fmt(e.error_deg, 2) : '–'];
        })));
    }
    const d = r.pairs.find((p) => p.distance)?.distance;
    if (d) {
      parts.push(el('p', { class: 'summary-formula',
        text: `§6.2.4: θ = ${fmt(deg(d.hfov_rad), 1)}°, B\u2032C\u2032 = ${fmt(d.bc_px, 0)} px, FJ = ${fmt(d.fj_px, 1)} px, ` +
          `GH = ${fmt(d.gh_px, 1)} px, DE = ${fmt(d.de_m, 3)} m ⇒ K = ${fmt(d.k_m_per_px * 1000, 2)} mm/px, ` +
          `AD = ${fmt(d.ad_m, 3)} m, AA\u2032 = ${fmt(d.aa_m, 3)} m.` }));
    }
    parts.push(el('div', { class: 'summary-figures' },
      figure(m.tableImage, 'The matched-pair table', 'Matched-pair table: inliers per frame pair (orange: the best pair).'),
      figure(m.mergedImage, 'The merged map', 'The merged map with every joined robot\u2019s path.')));
    if (m.groups) parts.push(...groupParts(m));
  }
  const results = m?.results ?? {};
  const ran = Object.keys(METHOD_NAMES).filter((k) => results[k]);
  if (ran.length) {
    parts.push(table('Transform error of each method merged on this run (worst joined robot)',
      ['method', 'verdict', 'position error', 'heading error'],
      ran.map((k) => {
        const x = results[k];
        return x.status === 'merged'
          ? [METHOD_NAMES[k], isWrong(x) ? 'Wrong merge' : 'Merged', `${fmt(x.error_m, 3)} m`, `${fmt(Math.abs(x.error_deg), 2)}°`]
          : [METHOD_NAMES[k], 'No merge', '–', '–'];
      })));
  }
  host.replaceChildren(...parts);
}

/** The summary view: opens over the page, gathers its data, keeps the focus while open. */
export class Summary {
  /**
   * @param {HTMLElement} box     the summary's element (hidden while closed)
   * @param {HTMLElement} opener  the button that opens it (focus returns there)
   * @param {{lab: () => any, scenario: () => any, state: () => any, link: () => string,
   *          shareLink: () => Promise<string>, pause: () => void, world: (w: number, h: number) => string,
   *          maps: {plots: () => any[]}, merge: {summary: () => any}}} hooks
   */
  constructor(box, opener, hooks) {
    this.box = box;
    this.opener = opener;
    this.hooks = hooks;
    opener.addEventListener('click', () =>
      this.open().catch((e) => setStatus(`Could not build the summary: ${message(e)}`, 'error')));
    // Ctrl+P anywhere prints the summary (the print stylesheet shows only it).
    window.addEventListener('beforeprint', () => {
      if (!this.hooks.lab() || !this.box.hidden) return;
      try {
        this.build();
      } catch (e) {
        setStatus(`Could not build the summary: ${message(e)}`, 'error');
      }
    });
  }

  get isOpen() {
    return !this.box.hidden;
  }

  /** Builds the summary from what the page shows now; `link` restores the scenario. */
  build(link = this.hooks.link() || location.href) {
    const h = this.hooks;
    const lab = h.lab();
    const scenario = h.scenario();
    const st = h.state();
    const started = st.steps > 0;
    const robots = scenario.robots.map((r, i) => ({
      name: r.name,
      follow: r.follow,
      distance: r.distance ?? 0.6,
      frames: started ? lab.frameCount(i) : 0,
      bumps: st.robots[i]?.bumps ?? 0,
      figures: started ? lab.slamFigures(i) : null,
    }));
    const plots = started ? h.maps.plots() : [];
    const merge = h.merge.summary();
    buildSummary(
      this.box,
      {
        scenario,
        link,
        when: new Date(),
        run: { time_s: st.time_s, finished: st.finished, steps: st.steps },
        robots,
        worldImage: h.world(720, 540),
        plots,
        merge,
      },
      { onPrint: () => window.print(), onClose: () => this.close() },
    );
  }

  async open() {
    this.hooks.pause();
    this.build(await this.hooks.shareLink());
    this.box.hidden = false;
    this.box.querySelector('#summary-print').focus();
  }

  close() {
    this.box.hidden = true;
    this.opener.focus({ preventScroll: true });
  }

  /** A key while open: Escape closes, Tab stays inside (the summary is modal). */
  key(e) {
    if (e.key === 'Escape') this.close();
    else if (e.key === 'Tab') this.trapFocus(e);
  }

  trapFocus(e) {
    const items = [...this.box.querySelectorAll('button, a[href]')].filter((x) => !x.hidden);
    if (!items.length) return;
    const first = items[0];
    const last = items[items.length - 1];
    if (e.shiftKey && document.activeElement === first) {
      e.preventDefault();
      last.focus();
    } else if (!e.shiftKey && document.activeElement === last) {
      e.preventDefault();
      first.focus();
    }
  }
}
