// The side panel's robot cards: one per robot, in the robot's colour.
//
// Each card has the robot's settings (name, follow side, wall distance; only
// editable at t = 0) and its live readouts from `lab.state()` (web/lab.js): mode,
// true pose (world frame), odometry pose (the robot's own frame, origin at
// its start), odometry error, bumps, the 8 sonars (numbered 1..8 from the
// robot's left to its right, as in the thesis), the nearest laser return,
// and a link to download its log as CSV.
//
// The cards are rebuilt only when the set of robots or the editing state
// changes; live values are written in place, so typing in a field is never
// interrupted by the running simulation.

import { deg, el, fmt } from './dom.js';
import { robotColour } from './palette.js';

const SONAR_COUNT = 8;

/** What each of the wall follower's modes means (crate/src/follower.rs). */
const MODE_WORDS = {
  seek: 'no wall in reach: driving straight to find one',
  follow: 'following its wall',
  turn: 'turning in place at a corner',
  recover: 'backing off after a bump',
  yield: 'waiting while an oncoming robot goes around',
  pass: 'going around an oncoming robot',
};

export class RobotsPanel {
  /**
   * @param {HTMLElement} root    container for the cards
   * @param {object} actions      callbacks: select(i), rename(i, name),
   *                              setFollow(i, side), setDistance(i, m),
   *                              remove(i), downloadLog(i)
   */
  constructor(root, actions) {
    this.root = root;
    this.actions = actions;
    this.key = '';
    this.cards = [];
    /** The state last written (`update`), for cards that scroll into view. */
    this.state = null;
    // With many robots most cards are scrolled out of view; while running
    // only those on screen are written (issue 22: 16 cards' readouts ten
    // times a second made the page lay itself out again every frame). A card
    // that scrolls into view is written at once.
    this.seen = typeof IntersectionObserver === 'undefined' ? null : new IntersectionObserver((entries) => {
      for (const e of entries) {
        const i = this.cards.findIndex((c) => c.root === e.target);
        if (i < 0) continue;
        this.cards[i].visible = e.isIntersecting;
        if (e.isIntersecting) this.write(i, this.state);
      }
    });
  }

  /** Rebuilds the cards if the robots or the editing state changed. */
  sync(scenario, { editable, selected, problems }) {
    const key = JSON.stringify([
      editable,
      selected,
      [...problems],
      scenario.robots.map((r) => [r.name, r.follow, r.distance]),
    ]);
    if (key === this.key) return;
    // Keep focus on a field the user is in while we rebuild.
    const active = document.activeElement;
    const focusId = active && this.root.contains(active) ? active.id : null;
    this.key = key;
    this.root.replaceChildren();
    this.cards = scenario.robots.map((r, i) => this.card(r, i, editable, selected === i, problems.has(i)));
    this.root.append(...this.cards.map((c) => c.root));
    this.seen?.disconnect();
    for (const c of this.cards) this.seen?.observe(c.root);
    if (focusId) document.getElementById(focusId)?.focus();
  }

  card(robot, i, editable, isSelected, hasProblem) {
    const a = this.actions;
    const id = (what) => `robot-${i}-${what}`;
    const name = el('input', {
      class: 'name',
      id: id('name'),
      type: 'text',
      value: robot.name,
      maxlength: '64',
      'aria-label': `Name of robot ${i + 1}`,
      disabled: !editable,
      onchange: (e) => a.rename(i, e.target.value),
    });
    const follow = el(
      'select',
      {
        id: id('follow'),
        'aria-label': `Wall side robot ${robot.name} follows`,
        disabled: !editable,
        onchange: (e) => a.setFollow(i, e.target.value),
      },
      el('option', { value: 'left', selected: robot.follow === 'left' }, 'left wall'),
      el('option', { value: 'right', selected: robot.follow === 'right' }, 'right wall'),
    );
    const dist = el('input', {
      class: 'dist',
      id: id('distance'),
      type: 'number',
      min: '0.3',
      max: '1.5',
      step: '0.05',
      value: String(robot.distance ?? 0.6),
      'aria-label': `Distance robot ${robot.name} keeps to the wall, metres`,
      disabled: !editable,
      onchange: (e) => a.setDistance(i, Number(e.target.value)),
    });
    const remove = el(
      'button',
      {
        type: 'button',
        class: 'remove',
        'aria-label': `Remove robot ${robot.name}`,
        title: 'Remove this robot',
        disabled: !editable,
        onclick: () => a.remove(i),
      },
      '×',
    );
    const head = el(
      'div',
      { class: 'robot-head' },
      name,
      follow,
      el('span', { class: 'small' }, 'at'),
      dist,
      el('span', { class: 'small' }, 'm'),
      remove,
    );

    // Live readouts: a compact label/value grid.
    const v = {};
    const value = (key) => (v[key] = el('span', { class: key }, '–'));
    const log = el(
      'a',
      {
        href: '#',
        class: 'log',
        'aria-disabled': 'true',
        title: 'Time, odometry pose, 8 sonars, 181 laser ranges and the true pose, one row per 0.1 s step',
        onclick: (e) => {
          e.preventDefault();
          a.downloadLog(i);
        },
      },
      'Download log (CSV)',
    );
    const bumps = el('span', {}, '');
    const sonarCells = [];
    const sonar = el('div', { class: 'sonar', role: 'group', 'aria-label': `Sonar ranges of ${robot.name} in metres, 1 left to 8 right` });
    for (let k = 0; k < SONAR_COUNT; k++) {
      const bar = el('span', { class: 'bar', style: 'height:0%' });
      const val = el('span', { class: 'v' }, '–');
      const cell = el('div', { class: 'sonar-cell', title: `sonar ${k + 1}` }, bar, val, el('span', { class: 'k' }, String(k + 1)));
      sonarCells.push({ cell, bar, val });
      sonar.append(cell);
    }
    const readout = el(
      'dl',
      { class: 'readout' },
      el('dt', {}, 'mode'),
      el('dd', { class: 'split' }, el('span', {}, value('mode'), bumps, (v.modeWords = el('span', { class: 'mode-words' }))), log),
      el('dt', {}, 'true pose'),
      el('dd', {}, value('truth')),
      el('dt', {}, 'odometry'),
      el('dd', {}, value('odometry')),
      el('dt', {}, 'odo. error'),
      el('dd', {}, value('error')),
      el('dt', {}, 'laser'),
      el('dd', {}, value('laser')),
      el('dt', { title: 'Sonars 1 (left, +90°) to 8 (right, -90°), metres' }, 'sonar L→R'),
      el('dd', {}, sonar),
    );
    const root = el(
      'div',
      {
        class: `robot-card${isSelected ? ' selected' : ''}${hasProblem ? ' problem' : ''}`,
        style: `--robot:${robotColour(i)}`,
        'data-robot': String(i),
        onpointerdown: (e) => {
          if (!e.target.closest('input, select, button, a')) a.select(i);
        },
      },
      head,
      readout,
    );
    return { root, v, sonarCells, log, bumps };
  }

  /** Writes the live state (or clears it at t = 0): into every card when
   *  `all`, else only into those on screen. */
  update(state, all = true) {
    this.state = state;
    this.cards.forEach((c, i) => {
      if (all || c.visible !== false) this.write(i, state);
    });
  }

  /** Writes card `i`'s readouts from `state`. */
  write(i, state) {
    const c = this.cards[i];
    const live = state && state.robots.length === this.cards.length ? state.robots : null;
    const r = live ? live[i] : null;
    if (!r) {
      c.v.mode.textContent = 'not started';
      c.v.modeWords.textContent = '';
      c.v.truth.textContent = '–';
      c.v.odometry.textContent = '–';
      c.v.error.textContent = '–';
      c.v.laser.textContent = '–';
      c.bumps.textContent = '';
      c.log.setAttribute('aria-disabled', 'true');
      c.sonarCells.forEach((s) => {
        s.val.textContent = '–';
        s.bar.style.height = '0%';
        s.cell.classList.remove('no-echo');
      });
      return;
    }
    c.v.mode.textContent = r.mode.replace(/_/g, ' ');
    c.v.mode.title = MODE_WORDS[r.mode] ?? '';
    c.v.mode.dataset.words = MODE_WORDS[r.mode] ?? '';
    // The rare modes are said in words on the card; every mode has its words as a tooltip.
    c.v.modeWords.textContent = ['yield', 'pass', 'recover'].includes(r.mode) ? ` (${MODE_WORDS[r.mode]})` : '';
    c.v.truth.textContent = pose(r.truth);
    c.v.odometry.textContent = pose(r.odometry);
    c.v.error.textContent = `${fmt(r.odometry_error_m)} m`;
    c.v.laser.textContent = r.laser_min
      ? `nearest ${fmt(r.laser_min[0])} m at ${fmt(r.laser_min[1], 0)}° · ${r.laser_returns}/181 hit`
      : 'no return';
    c.bumps.textContent = ` · ${r.bumps} bump${r.bumps === 1 ? '' : 's'}`;
    c.log.setAttribute('aria-disabled', 'false');
    r.sonar_m.forEach((m, k) => {
      const s = c.sonarCells[k];
      s.val.textContent = fmt(m, 2);
      s.bar.style.height = `${Math.min(100, (m / (this.sonarRange ?? 2)) * 100).toFixed(0)}%`;
      s.cell.classList.toggle('no-echo', !!r.sonar_no_echo[k]);
      s.cell.title = `sonar ${k + 1}: ${fmt(m, 2)} m${r.sonar_no_echo[k] ? ' (no echo)' : ''}`;
    });
  }
}

function pose([x, y, th]) {
  return `x ${fmt(x)}  y ${fmt(y)}  θ ${fmt(deg(th), 0)}°`;
}
