// Guided mode: "reproduce the thesis" step by step (thesis §6.2.1–6.2.5).
//
// A panel under the world map walks a student through the thesis's
// experiment on the live lab, one section per step, with Back and Next:
//
//   6.2.1 data collection   load the thesis preset and run the two robots;
//   6.2.2 image selection   start a thesis merge, held before matching:
//                           its selected frames are marked on the map;
//   6.2.3 image matching    let the matched-pair table fill in (the merge
//                           panel) and open the best pair's matches;
//   6.2.4 distance          the two tan(θ/2) equations with the measured
//                           numbers, solved for K and AD; A', D and E on
//                           the map;
//   6.2.5 merge             the merged map, the transform and its error
//                           against the ground truth.
//
// Each step pairs a short explanation (after the thesis's text) and the
// formula it uses with the live result, which is read from the Lab every
// quarter second. The guide drives the existing panels (web/merge-panel.js)
// rather than duplicating them, and never reads anything the page could not
// show anyway. While it is open the status line speaks for the guide ("Guide,
// step 3 of 5 (§6.2.3 Image matching): …"): the merge panel keeps its news
// until the guide closes, so the line never runs ahead to a step the guide
// has not reached. Keyboard: every control is a button; Escape closes (app.js).
import { deg, el, fmt } from './dom.js';
import { plainReason, wrongMerge, wrongWords } from './merge-words.js';

const REFRESH_MS = 100; // the live text follows the clock closely

const int = (n) => Number(n).toLocaleString('en-US');

/**
 * The steps: the section, a title, the explanation (constant HTML, after
 * the thesis's §6.2 text) and the formula it uses (one line each).
 */
const STEPS = [
  {
    section: '6.2.1',
    title: 'Data collection',
    text:
      'Two robots explore the thesis\u2019s map (Figure 17) by following walls: <b>robot1</b> keeps 0.6 m from the ' +
      'wall on its left, <b>robot2</b> 0.6 m from the wall on its right, steering on its side sonar. Every 0.1 s each ' +
      'robot logs its odometry pose, its eight sonars and 181 laser ranges and builds its own map, in its own frame; ' +
      'once a second its camera takes a frame (the thesis used Fraps screenshots). Those frames are what the ' +
      'merge will compare.',
    formula: [
      'steer so that  e = s₁ − 0.6 m → 0   (robot1; s₈ for robot2)',
      'one frame per simulated second:  147 s → 148 frames per robot (the thesis: 134 and 147)',
    ],
  },
  {
    section: '6.2.2',
    title: 'Image selection',
    text:
      'Matching every frame of one robot with every frame of the other is too much work, and most pairs could ' +
      'not be used anyway. The thesis keeps only frames taken while the robot faced a wall <b>squarely</b>: then ' +
      'moving the camera only shrinks and shifts the view of the wall, without turning it (§5.6). A robot faces a ' +
      'wall squarely when its two forward sonars, 4 and 5 (10° either side of straight ahead), read the same range. ' +
      'Many such positions lie close together, so only one of each close group is kept.',
    formula: ['keep a frame if  |s₄ − s₅| ≤ tol  (and the robot is not turning)', 'then drop frames taken < d from one already kept'],
  },
  {
    section: '6.2.3',
    title: 'Image matching',
    text:
      'Every kept frame of robot1 is matched with every kept frame of robot2 (the thesis: 5 × 19 matchings, its ' +
      'Table 1). For each pair, SURF finds and describes interest points in both frames; a point is paired with its ' +
      'nearest neighbour in the other frame when that one is clearly nearer than the second nearest; MSAC then fits ' +
      'a homography and throws out the pairs that disagree with it. The inliers left fill the table\u2019s cell: many ' +
      'inliers mean the two robots saw the same piece of wall from nearly the same place.',
    formula: ['match if  d₁ < 0.8 · d₂   (nearest vs second-nearest descriptor)', 'x₂ ≃ H · x₁  (MSAC);  cell = number of inliers'],
  },
  {
    section: '6.2.4',
    title: 'Distance between the robots',
    text:
      'Two pairs share one frame of one robot: that robot stood at <b>A\u2032</b>, the other at <b>D</b> and, ' +
      'later, at <b>E</b>, all facing the same wall (Figure 18). B\u2032C\u2032 is A\u2032\u2019s view in pixels (the ' +
      'image width); the homographies give the views at D and E in the same pixels, FJ and GH; DE comes from the ' +
      'second robot\u2019s own odometry; θ is the camera\u2019s horizontal view angle. The two equations below then ' +
      'give K, the metres of wall per pixel, and AD, how much nearer the wall D is than A\u2032.',
    formula: [
      'tan(θ/2) = (B\u2032C\u2032/2 − FJ/2) · K / AD',
      'tan(θ/2) = (B\u2032C\u2032/2 − GH/2) · K / (AD + DE)',
      '⇒  K = 2 · DE · tan(θ/2) / (FJ − GH),   AD = DE · (B\u2032C\u2032 − FJ) / (FJ − GH)',
    ],
  },
  {
    section: '6.2.5',
    title: 'Merge the maps',
    text:
      'Both robots faced the same wall, so the difference of the headings each believed it had, θ₂ − θ₁, is how much ' +
      'one map is turned against the other: rotate robot2\u2019s map (and its path) by it. Then translate it by the ' +
      'difference of the two reference positions plus the distance just computed (AD ahead, AA\u2032 sideways). The ' +
      'two maps are now one, in robot1\u2019s frame. The simulator knows where each robot really started, so the lab ' +
      'can score the transform, which the thesis could only judge by eye (Figure 19).',
    formula: [
      'T = P_A\u2032 ⊕ (AD, AA\u2032, 0) ⊕ P_D⁻¹   (P: a robot\u2019s own pose at its frame; ⊕: pose composition)',
      'x₁ = R(θ_T) · x₂ + t_T,   θ_T = θ_A\u2032 − θ_D  (the thesis\u2019s θ₂ − θ₁)',
      'error = ‖t_T − t_true‖ and |θ_T − θ_true|',
    ],
  },
];

export class GuidedTour {
  /**
   * @param {HTMLElement} host the (hidden) panel element of index.html
   * @param {HTMLElement} opener the button that opens the guide
   * @param {{lab: () => any,
   *          run: () => {steps: number, time_s: number, finished: boolean, running: boolean,
   *                       duration_s: number, robots: string[], thesis: boolean, name: string, seed: number},
   *          loadThesisAndRun: () => Promise<void>,
   *          merge: import('./merge-panel.js').MergePanel,
   *          setMarkers: (m: Array<{robot: number, pose: number[], label?: string}> | null) => void,
   *          reveal: (id: string, block?: string) => void,
   *          zoomTo: (points: number[][] | null) => void,
   *          onError: (e: unknown) => void,
   *          setStatus: (text: string, kind: string) => void,
   *          onToggle: (open: boolean) => void}} hooks
   */
  constructor(host, opener, hooks) {
    this.host = host;
    this.opener = opener;
    this.hooks = hooks;
    this.step = 0;
    this.isOpen = false;
    this.lastMs = 0;
    this.frameCache = new Map(); // robot index → Map(frame index → truth pose), per run
    this.cacheKey = '';
    this.build();
  }

  build() {
    this.counter = el('span', { class: 'guide-counter' });
    this.title = el('h2', { id: 'guide-title', tabindex: '-1' });
    const close = el('button', { type: 'button', class: 'guide-close', text: '×', 'aria-label': 'Close the guide (Esc)', title: 'Close (Esc)' });
    close.addEventListener('click', () => this.close());
    this.text = el('p', { class: 'guide-explain' });
    this.formula = el('div', { class: 'formula', role: 'math', 'aria-label': 'Formula' });
    this.live = el('div', { class: 'guide-live-body' });
    this.actions = el('div', { class: 'guide-actions' });
    this.verdict = el('p', { class: 'guide-ready', role: 'status', 'aria-live': 'polite' });
    this.back = el('button', { type: 'button', id: 'guide-back', text: '← Back' });
    this.next = el('button', { type: 'button', id: 'guide-next', class: 'primary', text: 'Next →' });
    this.back.addEventListener('click', () => this.go(this.step - 1));
    this.next.addEventListener('click', () => (this.step === STEPS.length - 1 ? this.close() : this.go(this.step + 1)));
    this.dots = el('ol', { class: 'guide-dots', 'aria-label': 'Steps' });
    STEPS.forEach((s, k) => this.dots.append(el('li', { text: s.section, 'data-step': String(k) })));
    this.host.replaceChildren(
      el('div', { class: 'guide-head' }, this.counter, this.title, close),
      el('div', { class: 'guide-body' },
        el('div', { class: 'guide-text' }, this.text, this.formula),
        el('div', { class: 'guide-live', 'aria-label': 'Live result' }, this.live, this.actions)),
      el('div', { class: 'guide-foot' }, this.back, this.verdict, this.dots, this.next),
    );
  }

  lab() {
    return this.hooks.lab();
  }

  open() {
    if (this.isOpen) return;
    this.isOpen = true;
    this.host.hidden = false;
    this.opener.setAttribute('aria-expanded', 'true');
    this.hooks.onToggle(true);
    // Reopened on a later step without the run it needs: start over.
    const run = this.hooks.run();
    this.go(run.finished ? this.step : 0);
    this.title.focus({ preventScroll: true });
  }

  close() {
    if (!this.isOpen) return;
    this.isOpen = false;
    this.said = '';
    this.host.hidden = true;
    this.opener.setAttribute('aria-expanded', 'false');
    this.hooks.merge.release();
    this.hooks.setMarkers(null);
    if (this.zoomed) {
      this.zoomed = false;
      this.hooks.zoomTo(null);
    }
    this.hooks.onToggle(false);
    this.opener.focus({ preventScroll: true });
  }

  toggle() {
    if (this.isOpen) this.close();
    else this.open();
  }

  /** Shows step `k` and does what entering it does. */
  go(k) {
    this.step = Math.max(0, Math.min(STEPS.length - 1, k));
    const s = STEPS[this.step];
    this.counter.textContent = `Step ${this.step + 1} of ${STEPS.length} · §${s.section}`;
    this.title.textContent = s.title;
    this.text.innerHTML = s.html ?? s.text;
    this.formula.replaceChildren(...s.formula.map((line) => el('div', { text: line })));
    this.back.disabled = this.step === 0;
    this.next.textContent = this.step === STEPS.length - 1 ? 'Finish' : 'Next →';
    for (const li of this.dots.children) {
      const n = Number(li.dataset.step);
      li.className = n === this.step ? 'current' : n < this.step ? 'done' : '';
      if (n === this.step) li.setAttribute('aria-current', 'step');
      else li.removeAttribute('aria-current');
    }
    this.actions.replaceChildren();
    this.live.replaceChildren();
    this.verdict.textContent = '';
    this.liveKey = '';
    try {
      this.enter();
    } catch (e) {
      this.hooks.onError(e);
    }
    this.update(performance.now(), true);
  }

  /** Side effects of entering the current step. */
  enter() {
    const run = this.hooks.run();
    this.hooks.setMarkers(null);
    if (this.zoomed) {
      this.zoomed = false;
      this.hooks.zoomTo(null);
    }
    this.revealed = false;
    switch (this.step) {
      case 0: {
        const b = this.button('Load the thesis map and run', 'guide-load', async () => {
          b.disabled = true;
          try {
            await this.hooks.loadThesisAndRun();
          } catch (e) {
            this.hooks.onError(e);
          }
          b.disabled = false;
        });
        if (!run.thesis || !run.steps) b.classList.add('primary');
        this.hooks.reveal('maps-title');
        break;
      }
      case 1:
        if (!run.finished) return;
        if (!this.thesisMerge()) this.hooks.merge.startMethod('thesis', { hold: true });
        this.markSelection();
        break;
      case 2: {
        if (!run.finished) return;
        if (!this.thesisMerge()) this.hooks.merge.startMethod('thesis');
        this.hooks.merge.release();
        this.markSelection();
        this.pairButton = this.button('Show the best pair\u2019s matches', 'guide-best-pair', () => {
          const t = this.view()?.tables?.[0];
          if (t?.best) this.hooks.merge.openPair(t.best[0], t.best[1]);
        });
        this.pairButton.disabled = true;
        this.hooks.reveal('merge-title');
        break;
      }
      case 3:
      case 4:
        if (!run.finished) return;
        if (!this.thesisMerge()) this.hooks.merge.startMethod('thesis');
        this.hooks.merge.release();
        this.markSelection();
        this.hooks.reveal('merge-title');
        break;
      default:
        break;
    }
  }

  button(text, id, fn) {
    const b = el('button', { type: 'button', id, text });
    b.addEventListener('click', fn);
    this.actions.append(b);
    return b;
  }

  view() {
    const lab = this.lab();
    return lab?.hasMerge() ? lab.mergeView() : null;
  }

  /** The lab's merge, when it is one with the thesis method. */
  thesisMerge() {
    const v = this.view();
    return v && v.method === 'thesis' ? v : null;
  }

  /** True poses of a robot's frames (display only), cached per run. */
  framePoses(robot) {
    const lab = this.lab();
    const key = `${lab.timeS()}|${JSON.stringify(this.hooks.run().robots)}`;
    if (key !== this.cacheKey) {
      this.cacheKey = key;
      this.frameCache.clear();
    }
    if (!this.frameCache.has(robot)) {
      const m = new Map();
      for (const f of lab.frames(robot)) m.set(f.index, f.truth);
      this.frameCache.set(robot, m);
    }
    return this.frameCache.get(robot);
  }

  /** Marks the selected frames on the map; `letters` labels some of them. */
  markSelection(letters = []) {
    const lab = this.lab();
    if (!lab?.hasMerge()) return;
    const sel = lab.mergeSelection();
    const marks = [];
    sel.robots.forEach((r, i) => {
      const poses = this.framePoses(i);
      r.selected.forEach((f, k) => {
        const pose = poses.get(f.frame);
        if (!pose) return;
        const letter = letters.find((l) => l.robot === i && l.pos === k);
        marks.push({ robot: i, pose, label: letter?.label });
      });
    });
    const lettered = marks.filter((m) => m.label);
    if (lettered.length) {
      // Each label points away from the group's middle (screen: y down).
      const cx = lettered.reduce((a, m) => a + m.pose[0], 0) / lettered.length;
      const cy = lettered.reduce((a, m) => a + m.pose[1], 0) / lettered.length;
      for (const m of lettered) {
        const [dx, dy] = [m.pose[0] - cx, m.pose[1] - cy];
        const n = Math.hypot(dx, dy);
        m.labelDir = n > 1e-6 ? [dx / n, dy / n] : [0.7, 0.7];
      }
      // Draw them last, on top of the others.
      marks.sort((a, b) => Number(Boolean(a.label)) - Number(Boolean(b.label)));
    }
    this.hooks.setMarkers(marks);
    this.marked = true;
    this.lettered = lettered.map((m) => m.pose);
    this.selection = sel;
  }

  /** Called every animation frame. */
  update(nowMs, force = false) {
    if (!this.isOpen || (!force && nowMs - this.lastMs < REFRESH_MS)) return;
    this.lastMs = nowMs;
    try {
      this.refresh();
    } catch (e) {
      this.hooks.onError(e);
    }
  }

  /** Replaces the live lines when they changed (so focus and selection survive). */
  setLive(lines, ready, verdict, kind) {
    const key = JSON.stringify(lines);
    if (key !== this.liveKey) {
      this.liveKey = key;
      this.live.replaceChildren(
        ...lines.map((l) => (typeof l === 'string' ? el('p', { text: l }) : l.formula
          ? el('div', { class: 'formula filled' }, ...l.formula.map((f) => el('div', { text: f })))
          : el('p', { class: l.class ?? '', text: l.text }))),
      );
    }
    if (this.verdict.textContent !== verdict) this.verdict.textContent = verdict;
    this.next.disabled = !ready;
    this.announce(false, verdict, kind ?? (ready ? 'ok' : 'info'));
  }

  /**
   * Puts the guide's step and verdict in the status line (the merge panel
   * keeps quiet while the guide is open, so the line never tells of a step
   * the guide has not reached); only when it changed, unless `force`.
   */
  announce(force = true, verdict = this.verdict.textContent, kind = this.next.disabled ? 'info' : 'ok') {
    if (!this.isOpen) return;
    const s = STEPS[this.step];
    const text = `Guide, step ${this.step + 1} of ${STEPS.length} (§${s.section} ${s.title})${verdict ? `: ${verdict}` : '.'}`;
    if (!force && text === this.said) return;
    this.said = text;
    this.hooks.setStatus(text, kind);
  }

  refresh() {
    const run = this.hooks.run();
    if (this.step > 0 && !run.finished) {
      if (this.marked) {
        // The frames marked belonged to the run that is gone.
        this.marked = false;
        this.hooks.setMarkers(null);
      }
      this.setLive(
        [{ class: 'warn', text: 'This step needs a finished run, and the run was reset or changed.' },
          'Go back to step 1 (§6.2.1) to run the robots again.'],
        false, 'Waiting for a finished run.');
      return;
    }
    switch (this.step) {
      case 0:
        return this.refreshCollect(run);
      case 1:
        return this.refreshSelection();
      case 2:
        return this.refreshMatching();
      case 3:
        return this.refreshDistance();
      default:
        return this.refreshMerge();
    }
  }

  refreshCollect(run) {
    const lab = this.lab();
    const lines = [];
    if (!run.thesis) {
      lines.push(run.steps
        ? `The lab holds your scenario “${run.name}”, not the thesis preset. The steps work on it too, ` +
          'or load the thesis map to reproduce the thesis.'
        : `The lab holds “${run.name}”, not the thesis preset: load the thesis map to reproduce the thesis.`);
    }
    if (!run.steps) {
      lines.push(run.thesis
        ? `Press Run (Space) to run the thesis preset as it is (seed ${run.seed}), or the button to load it as ` +
          'shipped and run it at 50× real time.'
        : 'Press the button: the thesis preset loads and both robots start at 50× real time.');
      return this.setLive(lines, false, '');
    }
    const frames = run.robots.map((name, i) => `${name} ${int(lab.frameCount(i))}`).join(', ');
    if (!run.finished) {
      lines.push(`${run.running ? 'Running' : 'Paused'}: t = ${fmt(run.time_s, 1)} s of ${fmt(run.duration_s, 0)} s.`);
      lines.push(`Frames taken so far: ${frames}.`);
      lines.push(run.running
        ? 'Watch the robots follow their walls; the Speed slider above fast-forwards (up to 50×).'
        : 'Press Run (Space) to let the robots finish their run.');
      return this.setLive(lines, false, '');
    }
    const period = Number(lab.camera().period_s.toFixed(2));
    lines.push(`Run finished at t = ${fmt(run.time_s, 1)} s. Frames: ${frames}: one every ${period} s of simulated time, ` +
      `from t = 0 s to ${fmt(run.time_s, 0)} s. The merge will not compare them all: step 2 keeps a few of each robot\u2019s.`);
    const ate = run.robots.map((name, i) => {
      const f = lab.slamFigures(i);
      return `${name} ${fmt(f.ate_m)} m (odometry alone ${fmt(f.odometry_ate_m)} m)`;
    });
    lines.push(`How far each robot\u2019s own position estimate was from the truth (RMS): ${ate.join('; ')}. ` +
      'The Maps panel plots it over time.');
    lines.push({ class: 'thesis-note', text: 'Thesis: robot1 logged 1,079 groups of data and 134 frames, robot2 1,020 and 147.' });
    this.setLive(lines, run.robots.length >= 2, run.robots.length >= 2
      ? 'Data collected: press Next.'
      : 'The merge needs at least two robots.');
  }

  refreshSelection() {
    const sel = this.selection;
    if (!sel) {
      return this.setLive(['Starting the thesis merge…'], false, '');
    }
    if (!this.thesisMerge()) {
      return this.setLive(['The Merge panel now holds another method\u2019s merge: press Back, then Next, to start ' +
        'the thesis merge again.'], false, '');
    }
    const lines = [
      { formula: [`tol = ${fmt(sel.sonar_tolerance_m, 2)} m,  ${fmt(sel.min_front_range_m, 1)} m ≤ s₄, s₅ ≤ ${fmt(sel.max_front_range_m, 1)} m,  ` +
        `turn ≤ ${fmt(sel.max_turn_per_step_rad, 2)} rad per step,  d = ${fmt(sel.min_separation_m, 2)} m`] },
    ];
    for (const r of sel.robots) {
      const ex = r.selected[0];
      lines.push(`${r.name}: ${int(r.captured)} frames → ${int(r.square)} facing a wall squarely → ${int(r.selected.length)} kept` +
        (ex ? ` (e.g. frame ${ex.frame}, t = ${fmt(ex.step / 10, 0)} s: s₄ = ${fmt(ex.sonar4_m, 3)} m, s₅ = ${fmt(ex.sonar5_m, 3)} m).` : '.'));
    }
    const [a, b] = sel.robots;
    const ok = a && b && a.selected.length > 0 && b.selected.length > 0;
    if (ok) lines.push(`Pairs to match: ${int(a.selected.length)} × ${int(b.selected.length)} = ${int(a.selected.length * b.selected.length)}.`);
    lines.push('On the map: a small triangle where each kept frame was taken, in the robot\u2019s colour, pointing the way the camera looked.');
    lines.push({ class: 'thesis-note', text: 'Thesis: 21 → 5 positions for robot1 and 148 → 19 for robot2; 5 × 19 = 95 pairs.' });
    this.setLive(lines, ok, ok ? 'Frames selected: press Next to match them.'
      : 'A robot kept no frame: it never faced a wall squarely, so this method cannot go on.');
  }

  refreshMatching() {
    const v = this.thesisMerge();
    if (!v) return this.setLive(['The Merge panel now holds another method\u2019s merge: press Back, then Next, to start the thesis merge again.'], false, '');
    const t = v.tables[0];
    const p = v.progress;
    const lines = [];
    if (p.stage === 'features') lines.push(`Describing the kept frames with SURF: ${int(p.done)} of ${int(p.total)}.`);
    else if (t) lines.push(`Pairs checked: ${int(t.cells.length)} of ${int(t.planned)}.`);
    const best = t?.best ? t.cells.find((c) => c[0] === t.best[0] && c[1] === t.best[1]) : null;
    if (best) {
      const fa = v.robots[t.a].frames[best[0]];
      const fb = v.robots[t.b].frames[best[1]];
      lines.push(`Best pair so far: row ${best[0] + 1} × column ${best[1] + 1} (${v.robots[t.a].name}\u2019s frame ${fa}, ` +
        `${v.robots[t.b].name}\u2019s frame ${fb}): ${int(best[2])} inliers of ${int(best[3])} matches. ` +
        'The orange box marks it in the table; click any cell to see its matches.');
    }
    if (this.pairButton) this.pairButton.disabled = !best;
    if (!this.revealed && t?.cells.length) {
      this.revealed = true;
      this.hooks.reveal('merge-table', 'center');
    }
    lines.push({ class: 'thesis-note', text: 'Thesis: the best pair was (3, 10) with 1,335 matched points, then (3, 11) and (3, 12).' });
    const done = p.finished;
    this.setLive(lines, done, done ? 'Every pair is checked: press Next.' : '');
  }

  /** The §6.2.4 numbers of the first robot pair, with who played A', D, E. */
  distance() {
    const v = this.thesisMerge();
    const pair = v?.report?.pairs?.[0];
    if (!pair) return { v, pair };
    const d = pair.distance;
    let roles = null;
    if (pair.best && pair.second) {
      const [ia, ib] = [v.tables[0].a, v.tables[0].b];
      roles = pair.best[0] === pair.second[0]
        ? { one: ia, two: ib, a: [ia, pair.best[0]], d: [ib, pair.best[1]], e: [ib, pair.second[1]] }
        : { one: ib, two: ia, a: [ib, pair.best[1]], d: [ia, pair.best[0]], e: [ia, pair.second[0]] };
    }
    return { v, pair, d, roles };
  }

  refreshDistance() {
    const { v, pair, d, roles } = this.distance();
    if (!v) return this.setLive(['The Merge panel now holds another method\u2019s merge: press Back, then Next, to start the thesis merge again.'], false, '');
    if (!pair) return this.setLive(['Waiting for the merge to finish…'], false, '');
    if (roles && !this.zoomed) {
      this.zoomed = true;
      this.markSelection([
        { robot: roles.a[0], pos: roles.a[1], label: 'A\u2032' },
        { robot: roles.d[0], pos: roles.d[1], label: 'D' },
        { robot: roles.e[0], pos: roles.e[1], label: 'E' },
      ]);
      if (this.lettered.length) this.hooks.zoomTo(this.lettered);
    }
    if (!d) {
      return this.setLive([{ class: 'warn', text: `No distance: ${pair.reason}.` },
        'The method needs both robots to face the same wall squarely, with overlapping views, and the second robot to ' +
        'move towards it between two kept frames.'], true, 'No merge with this method on this run.');
    }
    const names = v.robots.map((r) => r.name);
    const frame = ([r, k]) => `${names[r]}\u2019s frame ${v.robots[r].frames[k]}`;
    const th = fmt(d.tan_half_fov, 4);
    const half = (x) => fmt(x / 2, 1);
    const lines = [
      `A\u2032 = ${frame(roles.a)}; D = ${frame(roles.d)}; E = ${frame(roles.e)} (labelled on the map).`,
      `θ = ${fmt(deg(d.hfov_rad), 1)}°, B\u2032C\u2032 = ${fmt(d.bc_px, 0)} px, FJ = ${fmt(d.fj_px, 1)} px, ` +
        `GH = ${fmt(d.gh_px, 1)} px, DE = ${fmt(d.de_m, 3)} m`,
      { formula: [
        `${th} = (${half(d.bc_px)} − ${half(d.fj_px)}) · K / AD`,
        `${th} = (${half(d.bc_px)} − ${half(d.gh_px)}) · K / (AD + ${fmt(d.de_m, 3)})`,
        `⇒  K = 2 · ${fmt(d.de_m, 3)} · ${th} / (${fmt(d.fj_px, 1)} − ${fmt(d.gh_px, 1)}) = ${fmt(d.k_m_per_px * 1000, 2)} mm/px`,
        `⇒  AD = ${fmt(d.de_m, 3)} · (${fmt(d.bc_px, 0)} − ${fmt(d.fj_px, 1)}) / (${fmt(d.fj_px, 1)} − ${fmt(d.gh_px, 1)}) = ${fmt(d.ad_m, 3)} m`,
      ] },
      `Check: K · f puts ${names[roles.one]} ${fmt(d.depth_a_m, 2)} m from the wall` +
        (d.laser_depth_a_m != null ? `; its laser measured ${fmt(d.laser_depth_a_m, 2)} m.` : '; its laser saw no straight wall.'),
      `Sideways, D\u2019s view centre lands ${fmt(Math.abs(d.shift_px), 1)} px ${d.shift_px >= 0 ? 'right' : 'left'} of ` +
        `A\u2032\u2019s image centre: AA\u2032 = ${fmt(Math.abs(d.aa_m), 3)} m to ${names[roles.one]}\u2019s ` +
        `${d.aa_m >= 0 ? 'left' : 'right'}.`,
    ];
    this.setLive(lines, true, `K = ${fmt(d.k_m_per_px * 1000, 2)} mm/px and AD = ${fmt(d.ad_m, 3)} m: press Next to merge.`);
  }

  refreshMerge() {
    const v = this.thesisMerge();
    if (!v) return this.setLive(['The Merge panel now holds another method\u2019s merge: press Back, then Next, to start the thesis merge again.'], false, '');
    const r = v.report;
    if (!r) return this.setLive(['Waiting for the merge to finish…'], false, '');
    const lines = [];
    const merged = r.status === 'merged';
    const wrong = wrongMerge(r);
    lines.push({ class: merged && !wrong ? 'ok' : 'warn', text: wrong
      ? `Wrong merge: ${wrongWords(wrong)} (against the ground truth), though the method reports success.`
      : merged
        ? `Merged (confidence ${fmt(r.confidence)}): the merged map is in the Merge panel, right.`
        : `No merge, because ${plainReason(r.reason)}.` });
    for (const t of r.transforms.slice(1)) {
      const e = r.errors.find((x) => x.robot === t.robot);
      lines.push({ formula: [
        `${t.robot}\u2019s map in ${r.transforms[0].robot}\u2019s: rotate ${fmt(deg(t.pose[2]), 2)}°, translate (${fmt(t.pose[0])}, ${fmt(t.pose[1])}) m`,
        e ? `truth: rotate ${fmt(deg(e.truth[2]), 2)}°, translate (${fmt(e.truth[0])}, ${fmt(e.truth[1])}) m` : '',
      ].filter(Boolean) });
      if (e) lines.push({ class: 'ok', text: `Error against the ground truth: ${fmt(e.error_m, 3)} m and ${fmt(Math.abs(e.error_deg), 2)}°.` });
    }
    if (merged && !this.revealed) {
      this.revealed = true;
      this.hooks.reveal('merge-map', 'center');
    }
    lines.push('Now change one thing (the seed, a robot\u2019s follow distance, a wall\u2019s texture set to “plain”), run ' +
      'again and step through once more; the Merge panel\u2019s chart compares the methods on each run.');
    if (wrong) return this.setLive(lines, true, `Wrong merge: ${wrongWords(wrong)}.`, 'error');
    this.setLive(lines, true, merged ? 'The thesis\u2019s experiment is reproduced.' : 'This run gives no merge.', merged ? 'ok' : 'warn');
  }
}
