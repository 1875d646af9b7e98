// Groups of maps in "Your maps" (web/page/real/panel.js) and of the
// robots' maps in "Your log" (web/page/real/log-merge-view.js).
//
// Maps of two buildings opened together cannot all be joined: the merge
// then finds groups of maps that share walls among themselves and with no
// map outside (the report's `merge.groups`, crate/src/merge/saved/mod.rs),
// each joined in the frame of its first map. This view lists them in
// plain words, as the lab's Merge panel does for robots
// (web/page/merge-groups.js): "Group 1: a, b — merged map", "c alone: why",
// and with two or more groups of two or more maps shows a tab per group;
// the tab picks which group's transforms, overlay and downloads the view
// shows. With one group (every map joined) nothing here shows.

import { joinedGroups } from './report.js';

/** Does the view list the groups? Two or more groups, one of them of two or more maps. */
export function showsGroups(merge) {
  return (merge.groups?.length ?? 0) > 1 && joinedGroups(merge).length > 0;
}

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v);
  }
  e.append(...children);
  return e;
}

export class MapGroupsView {
  /**
   * `box`: the `#real-groups` (or `#log-groups`) element; `select(k)`:
   * shows group `k`; `colour(map)`: a map's colour; `label(map)`: how a
   * map is called (a robot's name in "Your log").
   */
  constructor(box, { select, colour, label = (m) => m }) {
    Object.assign(this, { box, select, colour, label });
    this.selected = -1;
    this.box.addEventListener('keydown', (e) => this.key(e));
  }

  hide() {
    this.box.hidden = true;
    this.box.replaceChildren();
    this.selected = -1;
  }

  /** A map's name in its colour. */
  name(n) {
    const b = el('b', { class: 'real-group-map', text: this.label(n) });
    b.style.color = this.colour(n);
    return b;
  }

  /** Lists the groups of `merge`; returns the group shown first (the first of two or more maps), -1 if none. */
  show(merge) {
    if (!showsGroups(merge)) {
      this.hide();
      return joinedGroups(merge)[0]?.k ?? -1;
    }
    const joined = joinedGroups(merge);
    this.box.hidden = false;
    const intro = el('p', {
      class: 'real-groups-intro',
      text: `Each group of two or more maps has its own merged map, transforms and downloads, in the frame of its first map` +
        (joined.length > 1 ? ': pick a group with its tab.' : '.'),
    });
    const list = el('ul', { class: 'real-group-list' }, ...merge.groups.map((g, k) => {
      if (g.maps.length === 1) {
        return el('li', { class: 'real-group-alone', 'data-group': String(k) }, this.name(g.maps[0]),
          ` joins no other map: ${g.reason ?? 'no pair with it merged'}`);
      }
      const n = joined.findIndex((j) => j.k === k) + 1;
      const names = g.maps.flatMap((m, i) => (i ? [' + ', this.name(m)] : [this.name(m)]));
      return el('li', { 'data-group': String(k) }, el('span', { text: `Group ${n}: ` }), ...names,
        ` (confidence ${g.confidence.toFixed(2)})`);
    }));
    const tabs = el('div', { class: 'real-group-tabs', role: 'tablist', 'aria-label': 'Which group of maps to show' },
      ...joined.map((g, i) => {
        const b = el('button', { type: 'button', role: 'tab', class: 'real-group-tab', 'data-group': String(g.k),
          'aria-selected': 'false', tabindex: '-1', text: `Group ${i + 1}: ${g.maps.length} maps` });
        b.addEventListener('click', () => this.pick(g.k));
        return b;
      }));
    tabs.hidden = joined.length < 2;
    this.box.replaceChildren(intro, list, tabs);
    this.selected = joined[0].k;
    this.mark();
    return this.selected;
  }

  /** Shows group `k` (called by a tab). */
  pick(k) {
    if (k === this.selected) return;
    this.selected = k;
    this.mark();
    this.select(k);
  }

  mark() {
    for (const b of this.box.querySelectorAll('[role="tab"]')) {
      const on = Number(b.dataset.group) === this.selected;
      b.setAttribute('aria-selected', String(on));
      b.tabIndex = on ? 0 : -1;
    }
  }

  /** Arrow keys, Home and End move between the tabs (the ARIA tabs pattern). */
  key(e) {
    const tabs = [...this.box.querySelectorAll('[role="tab"]')];
    const at = tabs.findIndex((b) => Number(b.dataset.group) === this.selected);
    const to = { ArrowRight: at + 1, ArrowLeft: at - 1, Home: 0, End: tabs.length - 1 }[e.key];
    if (to === undefined || !tabs.length || at < 0) return;
    e.preventDefault();
    const b = tabs[(to + tabs.length) % tabs.length];
    this.pick(Number(b.dataset.group));
    b.focus();
  }
}
