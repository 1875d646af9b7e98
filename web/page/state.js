// The page's store: the scenario being edited, the source of truth while
// editing (ARCHITECTURE.md, "The page owns the scenario being edited").
//
// Every change goes through here and is pushed to the Lab (web/lab.js) at
// once; an edit the Lab refuses (a bad value) throws and changes nothing.
// `commit` keeps an undo stack of the scenarios before each edit. After a
// change the store tells its listeners what kind of change it was; the
// composition root (web/app.js) then refreshes the views. Data flows one
// way: views and input handlers call the store, the store notifies, the
// views read the store.
//
// Kinds of change: 'load' (a new scenario: preset, import, link, New),
// 'edit' (a commit), 'undo', 'seed' (a new seed: the run starts over) and
// 'duration' (only the run's length changed).
import { Lab } from '../lab.js';

const UNDO_DEPTH = 100;

/** The scenario format's limit (crate/src/scenario.rs, MAX_ROBOTS). */
export const MAX_ROBOTS = 16;

export const clone = (o) => JSON.parse(JSON.stringify(o));

/**
 * The Lab's placement problems (`{field, message, text}`, worded after the
 * scenario format: "robots[1].start: robot 'robot2' starts inside or
 * touching walls[4]") in the words a user reads, with the wall's index to
 * highlight on the map: "robot2 overlaps a wall (marked in red on the map)".
 */
export function problemsInWords(problems) {
  return problems.map((p) => {
    const wall = /^robot '(.+)' starts inside or touching walls\[(\d+)\]$/.exec(p.message);
    if (wall) return { ...p, text: `${wall[1]} overlaps a wall (marked in red on the map)`, wall: Number(wall[2]) };
    const robot = /^robot '(.+)' overlaps robot '(.+)'$/.exec(p.message);
    if (robot) return { ...p, text: `${robot[1]} overlaps ${robot[2]}` };
    return p;
  });
}

export class Store {
  /** `wasm`: the loaded wasm-bindgen module; `preset`: the preset the page starts from. */
  constructor(wasm, preset) {
    this.wasm = wasm;
    /** The Lab (web/lab.js); null until the first scenario loads. */
    this.lab = null;
    this.scenario = null;
    /** The preset the scenario is (seed and duration aside); '' once edited. */
    this.preset = preset;
    /** The preset it was loaded from, kept through edits ('' for New / Import). */
    this.origin = preset;
    /** Preset name → its own duration_s, as fetched. */
    this.presetDurations = {};
    /** What keeps the scenario from running: `[{field, text}]`. */
    this.problems = [];
    /** `{kind: 'wall' | 'robot', index}` or null. */
    this.selection = null;
    this.undoStack = [];
    this.listeners = [];
    /** Counts every change; a load that waited on the network checks it did not miss one. */
    this.changes = 0;
  }

  /** Calls `fn(kind)` after every change. */
  subscribe(fn) {
    this.listeners.push(fn);
  }

  changed(kind) {
    this.changes += 1;
    this.problems = problemsInWords(this.lab.problems());
    const sel = this.selection;
    if (sel) {
      const list = sel.kind === 'wall' ? this.scenario.walls : this.scenario.robots;
      if (sel.index >= list.length) this.selection = null;
    }
    for (const fn of this.listeners) fn(kind);
  }

  /** Replaces the scenario with `text` (throws, keeping the old one, if it is bad). */
  load(text, { preset = '', origin = preset } = {}) {
    if (this.lab) this.lab.setScenario(text);
    else this.lab = Lab.open(this.wasm, text);
    this.scenario = this.lab.scenario();
    this.preset = preset;
    this.origin = origin;
    this.selection = null;
    this.changed('load');
  }

  /** Pushes an edited scenario to the Lab, with undo; on error nothing changes (throws). */
  commit(next, { undoFrom = JSON.stringify(this.scenario) } = {}) {
    this.lab.setScenario(next);
    this.undoStack.push(undoFrom);
    if (this.undoStack.length > UNDO_DEPTH) this.undoStack.shift();
    this.scenario = next;
    this.preset = '';
    this.changed('edit');
  }

  /**
   * Shows `next` in the Lab without committing it (a drag in progress);
   * false if the Lab refuses it (e.g. dragged beyond the ±1000 m the format
   * allows), which keeps the last good one.
   */
  preview(next) {
    try {
      this.lab.setScenario(next);
      this.problems = problemsInWords(this.lab.problems());
      return true;
    } catch {
      return false;
    }
  }

  /** Puts the Lab back on a scenario text shown before a preview (a cancelled drag). */
  revert(text) {
    this.lab.setScenario(text);
    this.problems = problemsInWords(this.lab.problems());
  }

  /** Goes back one commit; false when there is nothing to undo. */
  undo() {
    const text = this.undoStack.pop();
    if (!text) return false;
    this.lab.setScenario(text);
    this.scenario = JSON.parse(text);
    this.preset = '';
    this.selection = null;
    this.changed('undo');
    return true;
  }

  /** Remembers the current scenario (or `text`) for undo before a load replaces it. */
  pushUndo(text = this.scenario ? JSON.stringify(this.scenario) : null) {
    if (text) this.undoStack.push(text);
  }

  clearUndo() {
    this.undoStack = [];
  }

  /** A new seed (throws, keeping the old one, if the Lab refuses it); the run starts over. */
  setSeed(seed) {
    this.lab.setSeed(seed);
    this.scenario.seed = seed;
    this.changed('seed');
  }

  /** A new duration (throws, keeping the old one, if the Lab refuses it). */
  setDuration(seconds) {
    this.lab.setDuration(seconds);
    this.scenario.duration_s = seconds;
    this.changed('duration');
  }

  select(selection) {
    this.selection = selection;
  }

  /** A copy of the scenario to edit and commit. */
  draft() {
    return clone(this.scenario);
  }

  /** Indices of the robots named in a problem. */
  problemRobots() {
    const set = new Set();
    for (const p of this.problems) {
      const m = /^robots\[(\d+)\]/.exec(p.field);
      if (m) set.add(Number(m[1]));
    }
    return set;
  }
}
