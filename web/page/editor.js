// The editor: the tools (Select, Wall) and every edit that is not a drag:
// deleting the selection, adding and removing robots, a robot card's
// settings, nudging and turning with the keys, a new empty scenario, undo.
// Each edit copies the scenario, changes the copy and commits it to the
// store (web/page/state.js), which refuses what the Lab refuses. Edits
// happen only at t = 0 (`editable`); otherwise the status line says why not.
// Drags on the map are web/page/pointer.js's.
import { snap, snapAngle } from './geometry.js';
import { fmt } from './dom.js';
import { setStatus } from './status.js';
import { MAX_ROBOTS } from './state.js';


const ROBOT_GAP_M = 1.5; // a new robot's least distance from the others
export class Editor {
  /**
   * @param {import('./state.js').Store} store
   * @param {{guard: Function, editable: () => boolean, validate: (text: string) => string,
   *          center: () => number[], cancelDrag: () => void, refreshPanels: () => void,
   *          refreshControls: () => void, invalidate: () => void, robotsChanged: () => void}} hooks
   */
  constructor(store, hooks) {
    this.store = store;
    this.hooks = hooks;
    this.tool = 'select'; // 'select' | 'wall'
    for (const k of ['deleteSelection', 'addRobot', 'newScenario', 'undo', 'editRobot', 'removeRobot', 'nudge', 'turnSelected']) {
      this[k] = hooks.guard(this[k].bind(this));
    }
  }

  notEditable() {
    setStatus('The scenario can only be edited at t = 0: press Reset (R) first.', 'info');
  }

  /** Says what keeps the scenario from running, if anything. */
  reportProblems() {
    const problems = this.store.problems;
    if (problems.length) setStatus(`${problems[0].text}: move it clear before running.`, 'warn');
  }

  setTool(tool) {
    this.tool = tool;
    this.hooks.cancelDrag();
    if (tool === 'wall' && !this.hooks.editable()) this.notEditable();
    else if (tool === 'wall') setStatus('Wall tool: drag on the map to draw a wall; Alt or Shift for any angle.', 'info');
    this.hooks.refreshControls();
    this.hooks.invalidate();
  }

  undo() {
    if (!this.hooks.editable()) return this.notEditable();
    if (!this.store.undo()) return setStatus('Nothing to undo.', 'info');
    setStatus('Undone.', 'info');
  }

  /** A robot card's setting: `change(robot)` on a copy, committed; `what` for the status line. */
  editRobot(i, change, what) {
    if (!this.hooks.editable()) {
      this.hooks.robotsChanged();
      return this.notEditable();
    }
    const next = this.store.draft();
    change(next.robots[i]);
    try {
      this.store.commit(next);
    } catch (e) {
      this.hooks.robotsChanged(); // show the old values again
      throw e;
    }
    setStatus(`${next.robots[i].name} ${what}.`, 'info');
    this.reportProblems();
  }

  deleteSelection() {
    const sel = this.store.selection;
    if (!sel) return setStatus('Nothing selected: click a wall or robot first.', 'info');
    if (!this.hooks.editable()) return this.notEditable();
    if (sel.kind === 'robot') return this.removeRobot(sel.index);
    const next = this.store.draft();
    next.walls.splice(sel.index, 1);
    this.store.select(null);
    this.store.commit(next);
    setStatus(`Wall deleted (${next.walls.length} left). Ctrl+Z undoes.`, 'info');
  }

  removeRobot(i) {
    if (!this.hooks.editable()) return this.notEditable();
    if (this.store.scenario.robots.length <= 1) {
      setStatus('A scenario needs at least one robot: add another before removing this one.', 'warn');
      return;
    }
    const next = this.store.draft();
    const [gone] = next.robots.splice(i, 1);
    this.store.select(null);
    this.store.commit(next);
    setStatus(`Removed ${gone.name}. Ctrl+Z undoes.`, 'info');
  }

  addRobot() {
    if (!this.hooks.editable()) return this.notEditable();
    const scenario = this.store.scenario;
    if (scenario.robots.length >= MAX_ROBOTS) {
      setStatus(`At most ${MAX_ROBOTS} robots.`, 'warn');
      return;
    }
    const names = new Set(scenario.robots.map((r) => r.name));
    let k = scenario.robots.length + 1;
    while (names.has(`robot${k}`)) k++;
    const robot = {
      name: `robot${k}`,
      start: [0, 0, 0],
      follow: scenario.robots.length % 2 ? 'right' : 'left',
      distance: 0.6,
    };
    const [cx, cy] = this.hooks.center().map((c) => snap(c, 0.5));
    const next = this.freeSpot(robot, cx, cy) ?? (() => {
      const t = this.store.draft();
      t.robots.push({ ...robot, start: [snap(cx), snap(cy), 0] });
      return t;
    })();
    this.store.select({ kind: 'robot', index: next.robots.length - 1 });
    this.store.commit(next);
    const s = next.robots[next.robots.length - 1].start;
    setStatus(`Added ${robot.name} at (${fmt(s[0], 1)}, ${fmt(s[1], 1)}): drag it to place it, drag its yellow handle to turn it.`, 'info');
    this.reportProblems();
  }

  /** The scenario with `robot` on the first free spot of a spiral around
   *  (cx, cy), at least ROBOT_GAP_M from every other robot (so that the
   *  robots and their names stay apart), or null. */
  freeSpot(robot, cx, cy) {
    const others = this.store.scenario.robots.map((r) => r.start);
    for (let ring = 0; ring <= 16; ring++) {
      for (let a = 0; a < Math.max(1, ring * 6); a++) {
        const th = (2 * Math.PI * a) / Math.max(1, ring * 6);
        const p = [snap(cx + 0.5 * ring * Math.cos(th)), snap(cy + 0.5 * ring * Math.sin(th))];
        if (others.some((o) => Math.hypot(o[0] - p[0], o[1] - p[1]) < ROBOT_GAP_M)) continue;
        const trial = this.store.draft();
        trial.robots.push({ ...robot, start: [p[0], p[1], 0] });
        try {
          this.hooks.validate(JSON.stringify(trial));
          return trial;
        } catch {
          // occupied: try the next spot
        }
      }
    }
    return null;
  }

  newScenario() {
    this.store.pushUndo();
    const seed = this.store.scenario?.seed ?? 1;
    const empty = {
      name: 'untitled',
      seed,
      duration_s: 300,
      walls: [],
      robots: [{ name: 'robot1', start: [10, 7.5, 0], follow: 'left', distance: 0.6 }],
    };
    this.store.load(JSON.stringify(empty), { preset: '' });
    this.tool = 'wall';
    this.hooks.refreshControls();
    setStatus('New empty scenario: drag on the map to draw walls (Wall tool), add robots, then Run.', 'info');
  }

  /** Moves the selection by (dx, dy) m, snapped to 0.1 m. */
  nudge(dx, dy) {
    const sel = this.store.selection;
    if (!sel) return;
    if (!this.hooks.editable()) return this.notEditable();
    const next = this.store.draft();
    if (sel.kind === 'robot') {
      const s = next.robots[sel.index].start;
      s[0] = snap(s[0] + dx);
      s[1] = snap(s[1] + dy);
    } else {
      const w = next.walls[sel.index];
      w.from = [snap(w.from[0] + dx), snap(w.from[1] + dy)];
      w.to = [snap(w.to[0] + dx), snap(w.to[1] + dy)];
    }
    this.store.commit(next);
    this.reportProblems();
  }

  /** Turns the selected robot by `dTheta`, snapped to 15°. */
  turnSelected(dTheta) {
    const sel = this.store.selection;
    if (!sel || sel.kind !== 'robot') return;
    if (!this.hooks.editable()) return this.notEditable();
    const next = this.store.draft();
    const s = next.robots[sel.index].start;
    s[2] = snapAngle(s[2] + dTheta);
    this.store.commit(next);
    this.reportProblems();
  }
}
