// Merging the robots' maps (crate/src/merge), step by step in the page.
//
// "Merge maps" starts a merge of the current run with the chosen method.
// The work runs in small slices from the animation loop (a few
// milliseconds per frame), so the page stays responsive while the
// matched-pair table fills in: one row per frame of the first robot, one
// column per frame of the second, each checked pair a cell coloured by its
// inlier count (the thesis's Table 1; web/page/match-table.js draws it, with
// its legend and keyboard cursor). Clicking a cell opens the two frames
// with their matches and the matched-region quad (thesis Figure 8;
// web/page/pair-view.js). At the
// end the verdict appears (scrolled into view) with its reason, the transform of each robot's map
// frame, its error against the ground truth, and the merged map with
// downloads (PNG, ROS map_server PGM + YAML, report JSON). A merge the
// ground truth puts more than 0.5 m or 5° off is called a wrong merge, in
// red, however confident the method was (web/page/merge-words.js).
//
// With several groups of robots (issue 22), a list names them and tabs
// pick the group whose merged map, transforms and downloads the panel
// shows (web/page/merge-groups.js); robot 1's group is the report's own.
//
// The panel remembers each method's result on the current run, and a small
// chart compares their transform errors (position and heading against the
// ground truth) as the user merges with one method after another; a new run
// clears it. The guided mode (web/page/guided.js) drives the same panel: it
// starts a thesis merge and may hold it before the matching starts.

import { robotColour } from './palette.js';
import { deg, el, fmt } from './dom.js';
import { PairView } from './pair-view.js';
import { MatchTable } from './match-table.js';
import { fitCanvas } from './hidpi.js';
import { isWrong, plainReason, verdictTitle, worstError, wrongMerge, wrongWords } from './merge-words.js';
import { GroupsView, groupsReason, groupsStatus, showsGroups } from './merge-groups.js';

const SLICE_MS = 12;
const MAP_W = 330;
const MAP_H = 240;
const CHART_W = 330;
const CHART_H = 104;

const METHODS = [
  ['auto', 'Automatic (verified)'],
  ['thesis', 'Thesis §6.2'],
  ['map-only', 'Map-only baseline'],
];

export class MergePanel {
  /**
   * @param {HTMLElement} host the panel's body
   * @param {HTMLElement} pairHost an overlay element for the pair view
   * @param {{lab: () => any, canMerge: () => boolean, onError: (e: unknown) => void,
   *          setStatus: (text: string, kind: string) => void,
   *          quiet?: () => boolean,
   *          download: (name: string, data: BlobPart, type: string) => void,
   *          report: () => string}} hooks
   */
  constructor(host, pairHost, hooks) {
    this.host = host;
    this.pair = new PairView(pairHost);
    this.hooks = hooks;
    this.method = 'auto';
    this.active = false; // a merge is being computed
    this.view = null; // the last lab.mergeView()
    this.hold = false; // started but not advanced (the guided mode's step 6.2.2)
    /** Per method, the result on the current run: {status, error_m, error_deg, robot, reason}. */
    this.results = {};
    this.build();
  }

  build() {
    const select = el('select', { id: 'merge-method', 'aria-label': 'Merge method',
      title: 'Automatic: any view, several places must agree. Thesis §6.2: square views, the best-matched pair. ' +
        'Map-only: the occupancy grids alone.' });
    for (const [value, text] of METHODS) {
      const o = el('option', { value, text });
      if (value === this.method) o.selected = true;
      select.append(o);
    }
    select.addEventListener('change', () => {
      this.method = select.value;
    });
    this.select = select;
    this.button = el('button', { type: 'button', id: 'merge-run', class: 'primary', text: 'Merge maps' });
    this.button.addEventListener('click', () => this.start());
    this.progress = el('progress', { id: 'merge-progress', max: '1', value: '0', 'aria-label': 'Merge progress' });
    this.stageText = el('span', { class: 'hint', id: 'merge-stage', text: '' });
    this.hint = el('p', { class: 'hint', id: 'merge-hint' });
    this.matchTable = new MatchTable({
      open: (row, col) => this.openPair(row, col),
      say: (text) => this.hooks.setStatus(text, 'info'),
    });
    this.table = this.matchTable.canvas;
    this.verdict = el('div', { id: 'merge-verdict', class: 'merge-verdict', role: 'status', 'aria-live': 'polite' });
    this.transforms = el('table', { id: 'merge-transforms', class: 'merge-transforms' });
    this.distance = el('div', { id: 'merge-distance', class: 'merge-distance', hidden: '' });
    this.map = el('canvas', {
      id: 'merge-map', class: 'map-view', width: String(MAP_W), height: String(MAP_H),
      role: 'img', 'aria-label': 'Merged map',
    });
    // Robots do not know the world frame, so neither does the merge: say
    // why the merged map can look turned against the maze view.
    this.mapNote = el('p', { class: 'hint merge-map-note' });
    this.mapLegend = el('div', { id: 'merge-map-legend', class: 'merge-legend merge-map-legend', hidden: '' });
    this.groups = new GroupsView({
      select: (k) => this.showGroup(k),
      index: (name) => this.view?.robots.findIndex((x) => x.name === name) ?? 0,
    });
    this.group = 0; // the group whose map the panel shows (0: robot 1's, the report's own)
    this.groupList = null; // lab.mergeGroups() when the panel lists the groups
    this.downloads = el('div', { class: 'merge-downloads' });
    for (const [label, fn] of [
      // The picture the panel shows (map and every robot's path), at 4 × its size.
      ['Merged map PNG', () => {
        const c = el('canvas', { width: String(4 * MAP_W), height: String(4 * MAP_H) });
        this.drawGroup(this.group, c.getContext('2d'), c.width, c.height);
        c.toBlob((blob) => this.hooks.download(`${this.fileStem()}.png`, blob, 'image/png'), 'image/png');
      }],
      ['ROS map (PGM + YAML)', () => {
        const [k, stem] = [this.group, this.fileStem()];
        const lab = this.lab();
        this.hooks.download(`${stem}.pgm`, k > 0 ? lab.groupMergedPgm(k) : lab.mergedPgm(), 'image/x-portable-graymap');
        this.hooks.download(`${stem}.yaml`, k > 0 ? lab.groupMergedYaml(k, `${stem}.pgm`) : lab.mergedYaml(`${stem}.pgm`), 'text/yaml');
      }],
      ['Report JSON', () => this.hooks.download('report.json', this.hooks.report(), 'application/json')],
    ]) {
      const b = el('button', { type: 'button', class: 'linkish', text: label });
      b.addEventListener('click', () => {
        try {
          fn();
        } catch (e) {
          this.hooks.onError(e);
        }
      });
      this.downloads.append(b);
    }
    this.result = el('div', { class: 'merge-result', hidden: '' }, this.verdict, this.groups.box, this.distance,
      this.transforms, this.map, this.mapLegend, this.mapNote, this.downloads);
    this.chart = el('canvas', {
      id: 'merge-methods-chart', class: 'merge-chart', width: String(CHART_W), height: String(CHART_H),
      role: 'img', 'aria-label': 'Transform error of each method: no method has merged this run yet',
    });
    this.chartNote = el('p', { class: 'hint', id: 'merge-methods-note' });
    this.chartBox = el('div', { class: 'merge-chart-box', hidden: '' },
      el('div', { class: 'map-title', text: 'Transform error of each method (this run)' }), this.chart, this.chartNote);
    this.tableBox = this.matchTable.box;
    this.host.replaceChildren(
      el('div', { class: 'merge-controls' }, select, this.button),
      el('div', { class: 'merge-progress-row' }, this.progress, this.stageText),
      this.hint,
      this.tableBox,
      this.result,
      this.chartBox,
    );
    this.refreshIdle();
  }

  lab() {
    return this.hooks.lab();
  }

  /** Is a frame pair's view open over the page? */
  get pairOpen() {
    return this.pair.isOpen;
  }

  /**
   * What the run summary (web/page/summary.js) shows of the merge: the
   * report (null before a merge), the matched-pair table and the merged map
   * as PNG data URLs, every method's result on this run, and with several
   * groups the groups (`lab.mergeGroups()`) and the other groups' merged maps.
   */
  summary() {
    const view = this.view;
    if (!view) return { report: null, results: this.results };
    const image = (k) => {
      const c = document.createElement('canvas');
      c.width = 480;
      c.height = 350;
      this.drawGroup(k, c.getContext('2d'), c.width, c.height);
      return c.toDataURL('image/png');
    };
    const others = (this.groupList ?? []).filter((g) => g.group > 0 && g.robots.length > 1);
    return {
      report: view.report,
      tableImage: this.tableBox.hidden ? null : this.table.toDataURL('image/png'),
      mergedImage: view.report?.status === 'merged' ? image(0) : null,
      groups: this.groupList,
      groupImages: others.map((g) => ({ group: g.group, robots: g.robots, src: image(g.group) })),
      results: this.results,
    };
  }

  /** Draws group `k`'s merged map (0: the report's merged map) into `ctx`. */
  drawGroup(k, ctx, width, height) {
    if (k > 0) this.lab().drawGroupMerged(ctx, k, width, height);
    else this.lab().drawMerged(ctx, width, height);
  }

  /** Download names: `merged` for robot 1's group, `merged-group2` for group 2. */
  fileStem() {
    return this.group > 0 ? `merged-group${this.group + 1}` : 'merged';
  }

  /** Called when the run changed: any merge of the old maps is gone. */
  invalidate() {
    this.active = false;
    this.said = null;
    this.hold = false;
    this.view = null;
    this.groupList = null;
    this.group = 0;
    this.results = {};
    this.drawChart();
    this.matchTable.reset();
    this.tableBox.hidden = true;
    this.result.hidden = true;
    this.progress.value = 0;
    this.stageText.textContent = '';
    this.closePair();
    this.refreshIdle();
  }

  refreshIdle() {
    const can = this.hooks.canMerge();
    this.button.disabled = !can || this.active;
    if (!this.view && !this.active) {
      this.hint.textContent = can
        ? 'Merge the robots\u2019 maps now, or let them run longer first: the more they have seen in common, the better.'
        : this.hooks.robotCount() < 2
          ? 'Merging needs at least two robots: Reset (R), then Add robot.'
          : 'Run the robots (or pause them) to merge their maps.';
    }
  }

  /** Chooses `method` in the select and starts merging with it; `hold`
   *  keeps the job from advancing until `release()`. */
  startMethod(method, { hold = false } = {}) {
    this.method = method;
    this.select.value = method;
    this.start();
    this.hold = hold && this.active;
    if (this.hold) {
      this.stageText.textContent = 'waiting: press Next in the guide to match';
      this.say('The thesis method has selected its frames (marked on the map); the matching waits for Next.', 'info');
    }
  }

  /**
   * The merge's news for the status line. While the guided mode is open
   * (`hooks.quiet()`), the guide speaks for its steps and the news waits
   * for `flushStatus()`.
   */
  say(text, kind) {
    this.said = [text, kind];
    if (!this.hooks.quiet?.()) this.hooks.setStatus(text, kind);
  }

  /** Puts the merge's last news in the status line (the guide has closed). */
  flushStatus() {
    if (this.said && (this.active || this.view)) this.hooks.setStatus(...this.said);
  }

  /** Lets a held merge advance. */
  release() {
    this.hold = false;
  }

  start() {
    try {
      this.lab().mergeStart(this.method);
      this.hold = false;
      this.active = true;
      this.view = null;
      this.groupList = null;
      this.group = 0;
      this.result.hidden = true;
      this.matchTable.reset();
      this.tableBox.hidden = this.method === 'map-only';
      this.hint.textContent = '';
      this.closePair();
      this.refreshIdle();
      this.say('Merging the maps…', 'info');
    } catch (e) {
      this.hooks.onError(e);
    }
  }

  /** Called every animation frame. */
  update() {
    if (!this.active) {
      // Stepping, resetting or editing drops the lab's merge: follow it.
      if (this.view && !this.lab().hasMerge()) this.invalidate();
      this.refreshIdle();
      return;
    }
    if (this.hold) return;
    const lab = this.lab();
    let p;
    const t0 = performance.now();
    try {
      do {
        p = lab.mergeAdvance(2);
      } while (!p.finished && performance.now() - t0 < SLICE_MS);
      this.view = lab.mergeView();
      // the rule that chose the table's frames, read once a merge
      if (!this.matchTable.rule && this.view.tables.length) this.matchTable.rule = lab.mergeSelection();
    } catch (e) {
      this.active = false;
      this.hooks.onError(e);
      this.refreshIdle();
      return;
    }
    this.progress.max = Math.max(1, p.total);
    this.progress.value = p.done;
    this.stageText.textContent = p.finished ? 'done' : `${p.stage} ${p.done} / ${p.total}`;
    this.drawTable();
    if (p.finished) {
      this.active = false;
      this.showResult();
      this.refreshIdle();
    }
  }

  table0() {
    return this.view?.tables?.[0] ?? null;
  }

  drawTable() {
    this.matchTable.show(this.view);
  }

  bestCell() {
    return this.matchTable.best();
  }

  /** Scrolls the panel into view and focuses Merge maps: the next step once a run has finished. */
  reveal() {
    this.refreshIdle();
    this.host.closest('.panel')?.scrollIntoView({ block: 'start' });
    if (!this.button.disabled) this.button.focus({ preventScroll: true });
  }

  /** Opens the two frames of a table cell with their matches and the quad (web/page/pair-view.js). */
  openPair(row, col) {
    const t = this.table0();
    try {
      this.pair.open(this.lab(), t, this.view.method, row, col);
    } catch (e) {
      this.hooks.onError(e);
    }
  }

  closePair() {
    this.pair.close();
  }

  /** Thesis §6.2.4: the two equations with the measured numbers. */
  showDistance(r) {
    const d = r.pairs.find((p) => p.distance)?.distance;
    this.distance.hidden = !d;
    if (!d) return;
    const p = r.pairs.find((q) => q.distance);
    const line = (text) => el('div', { text });
    // Table positions counted from 1, as the thesis's Table 1 (and the guide) do.
    const cell = ([row, col]) => `row ${row + 1}, column ${col + 1}`;
    this.distance.replaceChildren(
      el('b', { text: `Distance between the robots (§6.2.4), from the pairs at ${cell(p.best)} and ${cell(p.second)} of the table` }),
      line(`tan(θ/2) = (B'C'/2 − FJ/2)·K / AD`),
      line(`tan(θ/2) = (B'C'/2 − GH/2)·K / (AD + DE)`),
      line(`θ = ${fmt(deg(d.hfov_rad), 1)}°, B'C' = ${fmt(d.bc_px, 0)} px, FJ = ${fmt(d.fj_px, 1)} px, ` +
        `GH = ${fmt(d.gh_px, 1)} px, DE = ${fmt(d.de_m, 3)} m (robot 2's odometry)`),
      line(`⇒ K = ${fmt(d.k_m_per_px * 1000, 3)} mm/px, AD = ${fmt(d.ad_m, 3)} m, AA' = ${fmt(d.aa_m, 3)} m; ` +
        `robot 1 stood ${fmt(d.depth_a_m, 2)} m from the wall` +
        (d.laser_depth_a_m != null ? ` (its laser: ${fmt(d.laser_depth_a_m, 2)} m)` : '')),
    );
  }

  showResult() {
    const r = this.view?.report;
    if (!r) return;
    this.result.hidden = false;
    const merged = r.status === 'merged';
    const wrong = wrongMerge(r);
    const several = showsGroups(r, this.view.robots.length);
    const reason = several ? groupsReason(r) : plainReason(r.reason);
    this.verdict.className = `merge-verdict ${wrong ? 'wrong' : merged ? 'ok' : 'no'}`;
    this.verdict.replaceChildren(
      el('b', { text: verdictTitle(r, fmt) }),
      wrong ? el('span', { text: '. The method trusted what the robots saw; the ground truth, which it never sees, says ' +
        `it joined the wrong places. Its reason: ${reason}` })
        : el('span', { text: merged ? `: ${reason}` : `, because ${reason}` }),
    );
    this.showDistance(r);
    this.groupList = null;
    let first = merged ? 0 : -1;
    if (several) {
      try {
        this.groupList = this.lab().mergeGroups();
        first = this.groups.show(r);
      } catch (e) {
        this.hooks.onError(e);
      }
    } else {
      this.groups.hide();
    }
    this.showGroup(first);
    this.remember(r);
    // The verdict is what the user waited for: into view (the guide, when
    // open, brings the panel into view at its own step).
    if (!this.hooks.quiet?.()) this.verdict.scrollIntoView({ block: 'start', behavior: 'smooth' });
    this.say(
      wrong ? `Wrong merge: ${wrongWords(wrong)} (against the ground truth), though the method reports success.`
        : this.groupList ? groupsStatus(r) : merged ? `Maps merged: ${r.transforms.length} robots joined.` : `No merge: ${plainReason(r.reason)}`,
      wrong ? 'error' : merged || first >= 0 ? 'ok' : 'warn',
    );
  }

  /**
   * Shows group `k`'s transforms, merged map and downloads: 0 is robot 1's
   * group (the report's own transforms and errors), -1 none (no group has a
   * merged map).
   */
  showGroup(k) {
    const r = this.view?.report;
    if (!r) return;
    this.group = Math.max(0, k);
    const has = k >= 0;
    const g = k > 0 ? this.groupList?.[k] : null;
    const transforms = g ? g.transforms : r.transforms;
    const errors = g ? g.errors : r.errors;
    const first = transforms[0]?.robot ?? 'the first robot';
    const head = el('tr', {}, ...['robot', 'x (m)', 'y (m)', 'θ (°)', 'error'].map((t) => el('th', { text: t })));
    const rows = transforms.map((t) => {
      const e = errors.find((x) => x.robot === t.robot);
      const i = this.view.robots.findIndex((x) => x.name === t.robot);
      const name = el('td', { text: t.robot });
      name.style.color = robotColour(i);
      return el('tr', {}, name, el('td', { text: fmt(t.pose[0]) }), el('td', { text: fmt(t.pose[1]) }),
        el('td', { text: fmt(deg(t.pose[2]), 1) }),
        el('td', { class: isWrong(e) && t.robot !== first ? 'bad' : '', text: e ? `${fmt(e.error_m, 3)} m, ${fmt(e.error_deg, 2)}°` : '–' }));
    });
    this.transforms.replaceChildren(
      el('caption', { text: g ? `Group ${k + 1}: each robot’s map frame in the group’s merged frame (${first}’s); error against the ground truth`
        : 'Each robot’s map frame in the merged frame (the first robot’s); error against the ground truth' }),
      head, ...rows);
    this.transforms.hidden = !has;
    this.map.hidden = !has;
    this.mapNote.hidden = !has;
    this.map.setAttribute('aria-label', g ? `Merged map of group ${k + 1}: ${transforms.map((t) => t.robot).join(', ')}` : 'Merged map');
    this.mapNote.textContent = `Drawn in ${first}’s map frame (its start is the origin, its start heading ` +
      'points right), not the world’s: robots never learn the world frame, so the map may look turned ' +
      'against the maze view.';
    this.mapLegend.hidden = !has || !this.groupList;
    this.mapLegend.replaceChildren(...(this.groupList && has ? this.groups.legend(this.group) : []));
    this.downloads.querySelectorAll('button').forEach((b, n) => {
      b.hidden = !has && n < 2;
    });
    const [png, ros] = this.downloads.querySelectorAll('button');
    png.textContent = g ? `Group ${k + 1} map PNG` : 'Merged map PNG';
    ros.textContent = g ? `Group ${k + 1} ROS map (PGM + YAML)` : 'ROS map (PGM + YAML)';
    if (!has) return;
    try {
      fitCanvas(this.map, MAP_W, MAP_H);
      this.drawGroup(this.group, this.map.getContext('2d'), this.map.width, this.map.height);
    } catch (e) {
      this.hooks.onError(e);
    }
  }

  /** Keeps this method's result for the comparison chart. With more than
   *  two robots the worst joined robot's error stands for the method. */
  remember(r) {
    const worst = worstError(r);
    this.results[r.method] = r.status === 'merged' && worst
      ? { status: 'merged', error_m: worst.error_m, error_deg: worst.error_deg, robot: worst.robot, reason: r.reason }
      : { status: 'no_merge', reason: r.reason };
    this.drawChart();
  }

  /**
   * The transform error of each method on this run: one row per method,
   * position error (m) on the left, heading error (degrees, absolute) on
   * the right, each on its own linear scale; "no merge" or "not run yet"
   * where there is no transform to score.
   */
  drawChart() {
    const entries = METHODS.map(([m, text]) => [m, text.split(' (')[0].replace(' baseline', ''), this.results[m]]);
    const any = entries.some(([, , r]) => r);
    this.chartBox.hidden = !any;
    if (!any) return;
    const ctx = fitCanvas(this.chart, CHART_W, CHART_H);
    const W = CHART_W;
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, W, CHART_H);
    const merged = entries.filter(([, , r]) => r?.status === 'merged').map(([, , r]) => r);
    const maxM = Math.max(0.05, ...merged.map((r) => r.error_m)) * 1.05;
    const maxD = Math.max(0.5, ...merged.map((r) => Math.abs(r.error_deg))) * 1.05;
    const x0 = 80;
    const colW = (W - x0 - 6) / 2;
    const rowH = 26;
    const y0 = 18;
    ctx.font = '10.5px system-ui, sans-serif';
    ctx.textBaseline = 'middle';
    ctx.fillStyle = '#333';
    ctx.textAlign = 'left';
    ctx.fillText('position error', x0, 8);
    ctx.fillText('heading error', x0 + colW + 6, 8);
    const spoken = [];
    entries.forEach(([m, label, r], k) => {
      const y = y0 + k * rowH;
      ctx.fillStyle = k % 2 ? '#fafafa' : '#f1f3f6';
      ctx.fillRect(0, y, W, rowH - 2);
      ctx.fillStyle = '#1c1c1c';
      ctx.textAlign = 'left';
      ctx.font = `${m === this.view?.method ? '700 ' : ''}11px system-ui, sans-serif`;
      ctx.fillText(label, 4, y + rowH / 2 - 1);
      ctx.font = '10.5px system-ui, sans-serif';
      if (!r || r.status !== 'merged') {
        ctx.fillStyle = '#666';
        ctx.fillText(r ? 'no merge' : 'not run yet', x0, y + rowH / 2 - 1);
        spoken.push(`${label}: ${r ? 'no merge' : 'not run yet'}`);
        return;
      }
      const bars = [
        [x0, (colW - 44) * (r.error_m / maxM), `${fmt(r.error_m, 3)} m`, '#1f5fbf'],
        [x0 + colW + 6, (colW - 44) * (Math.abs(r.error_deg) / maxD), `${fmt(Math.abs(r.error_deg), 2)}°`, '#0f7d6e'],
      ];
      for (const [bx, bw, text, colour] of bars) {
        ctx.fillStyle = colour;
        ctx.fillRect(bx, y + 5, Math.max(1.5, bw), rowH - 12);
        ctx.fillStyle = '#1c1c1c';
        ctx.fillText(text, bx + Math.max(1.5, bw) + 4, y + rowH / 2 - 1);
      }
      spoken.push(`${label}: ${fmt(r.error_m, 3)} m, ${fmt(Math.abs(r.error_deg), 2)} degrees`);
    });
    this.chart.setAttribute('aria-label', `Transform error of each method on this run. ${spoken.join('; ')}.`);
    const several = this.view?.robots?.length > 2 ? ' With more than two robots, the worst joined robot counts.' : '';
    this.chartNote.textContent =
      'Error of the estimated map transform against the ground truth, for each method you merged with on this run; ' +
      `pick another method above and merge to fill a row.${several}`;
  }
}
