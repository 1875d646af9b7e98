// Several groups of robots in the Merge panel (issue 22).
//
// With many robots, the merge may join them into several groups that saw
// nothing in common with one another: robots 1 and 2 drove through one
// building, 3 and 4 through another. Each group then has a merged map of
// its own, in the frame of its first robot (the report's `merge.groups[]`,
// crate/src/lab/groups.rs); a robot nobody's map or views overlapped stays
// alone, with the merge's reason.
//
// This view lists the groups in plain words ("Group 1: robot1, robot2 —
// merged map", "robot5 alone: …") and, when two or more groups have a
// merged map, shows tabs to pick which one the panel's map, transform table
// and downloads show (web/page/merge-panel.js draws them). With two or
// three robots that the merge joined into one group, or two robots it did
// not join, nothing here shows and the panel is as it always was.

import { robotColour } from './palette.js';
import { el } from './dom.js';
import { plainReason } from './merge-words.js';

/** Does the panel list the groups? More than one group among more than two robots. */
export function showsGroups(report, robotCount) {
  return (report?.groups?.length ?? 0) > 1 && robotCount > 2;
}

/** "robot1, robot3 and robot4". */
export function nameList(names) {
  return names.length < 2 ? names.join('') : `${names.slice(0, -1).join(', ')} and ${names[names.length - 1]}`;
}

/** The status line's words for the groups: "Maps merged in 2 groups (…); robot5 alone." */
export function groupsStatus(report) {
  const joined = report.groups.filter((g) => g.robots.length > 1);
  const alone = report.groups.filter((g) => g.robots.length === 1).map((g) => g.robots[0]);
  const parts = joined.map((g) => g.robots.join(' + '));
  const head = joined.length
    ? `Maps merged in ${joined.length} group${joined.length > 1 ? 's' : ''} (${parts.join('; ')})`
    : 'No two robots\u2019 maps could be merged';
  return alone.length ? `${head}; ${nameList(alone)} ${alone.length > 1 ? 'stay' : 'stays'} alone.` : `${head}.`;
}

/** Why a robot stands alone, without repeating that it does. */
export function aloneReason(g) {
  const text = plainReason(g.reason);
  const said = `${g.robots[0]} joined no other robot: `;
  return text.startsWith(said) ? text.slice(said.length) : text;
}

/**
 * The verdict's reason when the groups are listed below it. The verdict is
 * robot 1's group's: merged, it says who is not joined *to robot 1* (they
 * may be joined to each other); not merged, robot 1's own reason replaces
 * the list of every pair's.
 */
export function groupsReason(report) {
  const first = report.groups[0];
  if (report.status !== 'merged') return `${plainReason(first.reason ?? report.reason)}; the other robots\u2019 groups are below`;
  return plainReason(report.reason).replace(/; not joined: (.*)$/,
    (_, names) => `; not joined to ${first.robots[0]}: ${names} (every group is below)`);
}

export class GroupsView {
  /**
   * @param {{select: (group: number) => void, index: (name: string) => number}} hooks
   *   `select` shows group `group` in the panel; `index` gives a robot's
   *   position (for its colour).
   */
  constructor(hooks) {
    this.hooks = hooks;
    this.intro = el('p', { class: 'merge-groups-intro' });
    this.list = el('ul', { id: 'merge-group-list', class: 'merge-group-list' });
    this.tabs = el('div', { id: 'merge-group-tabs', class: 'merge-group-tabs', role: 'tablist',
      'aria-label': 'Which group\u2019s merged map to show' });
    this.tabs.addEventListener('keydown', (e) => this.key(e));
    this.box = el('section', { id: 'merge-groups', class: 'merge-groups', hidden: '', 'aria-label': 'Groups of robots' },
      this.intro, this.list, this.tabs);
    this.selected = -1;
    this.groups = [];
  }

  hide() {
    this.box.hidden = true;
    this.groups = [];
    this.selected = -1;
  }

  /** A robot's name in its colour. */
  name(n) {
    const b = el('b', { class: 'merge-group-robot', text: n });
    b.style.color = robotColour(this.hooks.index(n));
    return b;
  }

  /**
   * Shows the groups of `report`; returns the group to show first: robot
   * 1's if it joined anyone, else the first group that has a merged map
   * (-1 when none has).
   */
  show(report) {
    const groups = report.groups;
    this.groups = groups;
    this.box.hidden = false;
    const mapped = groups.map((g, k) => [g, k]).filter(([g]) => g.robots.length > 1);
    const alone = groups.length - mapped.length;
    this.intro.textContent = `These robots form ${groups.length} groups that saw nothing in common with each other` +
      (mapped.length ? ': each group of two or more has its own merged map, drawn in its first robot\u2019s frame' : '') +
      (alone ? `; ${alone === 1 ? 'a robot' : 'robots'} nobody overlapped ${alone === 1 ? 'stays' : 'stay'} alone, and the list says why.` : '.');
    this.list.replaceChildren(...groups.map((g, k) => {
      if (g.robots.length === 1) {
        return el('li', { class: 'merge-group-alone', 'data-group': String(k) },
          this.name(g.robots[0]), ` alone: ${aloneReason(g)}`);
      }
      const names = g.robots.flatMap((n, i) => (i ? [', ', this.name(n)] : [this.name(n)]));
      // "merged map" shows that group's map (a link-like button when there is a choice).
      const show = mapped.length > 1
        ? el('button', { type: 'button', class: 'merge-group-show', text: 'merged map', onclick: () => this.select(k, true) })
        : 'merged map';
      return el('li', { 'data-group': String(k) }, el('span', { text: `Group ${k + 1}: ` }), ...names, ' \u2014 ', show);
    }));
    this.tabs.replaceChildren(...mapped.map(([g, k]) => {
      const b = el('button', { type: 'button', role: 'tab', class: 'merge-group-tab', id: `merge-group-tab-${k}`,
        'data-group': String(k), 'aria-controls': 'merge-map', 'aria-selected': 'false', tabindex: '-1',
        text: `Group ${k + 1} (${g.robots.length} robots)` });
      b.addEventListener('click', () => this.select(k));
      return b;
    }));
    // Tabs only when there is a choice.
    this.tabs.hidden = mapped.length < 2;
    this.selected = mapped.length ? mapped[0][1] : -1;
    this.mark();
    return this.selected;
  }

  /** Shows group `k` (a group with a merged map); `focus` moves the focus to its tab. */
  select(k, focus = false) {
    if (!this.groups[k] || this.groups[k].robots.length < 2) return;
    this.selected = k;
    this.mark();
    this.hooks.select(k);
    if (focus) this.tabs.querySelector(`[data-group="${k}"]`)?.focus();
  }

  mark() {
    for (const b of this.tabs.querySelectorAll('[role="tab"]')) {
      const on = Number(b.dataset.group) === this.selected;
      b.setAttribute('aria-selected', String(on));
      b.tabIndex = on ? 0 : -1;
    }
  }

  /** Arrow keys, Home and End move between the tabs (the ARIA tabs pattern). */
  key(e) {
    const tabs = [...this.tabs.querySelectorAll('[role="tab"]')];
    const at = tabs.findIndex((b) => Number(b.dataset.group) === this.selected);
    const to = { ArrowRight: at + 1, ArrowDown: at + 1, ArrowLeft: at - 1, ArrowUp: at - 1, Home: 0, End: tabs.length - 1 }[e.key];
    if (to === undefined || !tabs.length) return;
    e.preventDefault();
    e.stopPropagation(); // the page's own arrow keys (Step, nudge) stay out of the tabs
    const b = tabs[(to + tabs.length) % tabs.length];
    this.select(Number(b.dataset.group));
    b.focus();
  }

  /** The legend under the map: each robot of group `k` in its colour. */
  legend(k) {
    const g = this.groups[k];
    if (!g) return [];
    return g.robots.map((n) => {
      const swatch = el('i', { class: 'merge-swatch' });
      swatch.style.background = robotColour(this.hooks.index(n));
      return el('span', {}, swatch, n);
    });
  }
}
