// The toolbar and the controls around the map: Run, Pause, Step, Reset,
// the tools, New / presets / Import / Export, seed, duration, speed, the
// layer switches, Copy link, Reset to preset, the help overlay; and what
// they show: which buttons are enabled, the mode badge, the clock and the
// progress bar (refreshed at most every 100 ms while running). The buttons
// call the controllers (web/page/run.js, editor.js, persistence.js); this
// module holds no state of the run or the scenario.
import { fmt } from './dom.js';
import { Superseded } from './persistence.js';
import { MAX_ROBOTS } from './state.js';
import { message, setStatus } from './status.js';

const READOUT_INTERVAL_MS = 100;
const $ = (id) => document.getElementById(id);

/** Offers `data` as a file called `name`. */
export function download(name, data, type) {
  const url = URL.createObjectURL(new Blob([data], { type }));
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

/** A file-name-safe form of a scenario or robot name. */
export function safeName(s) {
  return String(s).replace(/[^\w.-]+/g, '_') || 'scenario';
}

export class Toolbar {
  /**
   * @param {object} page  the collaborators: {guard, store, runner, editor, view, persistence,
   *                       robotsPanel, canvas}
   */
  constructor(page) {
    this.page = page;
    this.lastReadoutMs = 0;
  }

  get helpOpen() {
    return !$('help-overlay').hidden;
  }

  toggleHelp(show) {
    const o = $('help-overlay');
    const open = show ?? o.hidden;
    o.hidden = !open;
    $('help').setAttribute('aria-expanded', String(open));
    if (open) $('help-close').focus();
  }

  setSpeed(v) {
    this.page.runner.speed = v;
    $('speed').value = String(v);
    $('speed-value').textContent = `${v}×`;
  }

  /** The seed, duration and preset fields after the scenario changed. */
  showScenario() {
    const store = this.page.store;
    $('seed').value = String(store.scenario.seed);
    $('duration').value = String(store.scenario.duration_s);
    // not a preset (imported, e.g. an exercise's file, or new): the select names it
    const own = $('preset').querySelector('option[value=""]');
    const name = store.scenario.name?.trim();
    own.textContent = name ? `“${name.length > 22 ? `${name.slice(0, 21)}…` : name}”` : '(your scenario)';
    $('preset').value = store.preset;
  }

  /** Robot cards' readouts, the clock and the progress bar; at most every 100 ms unless `force`. */
  readouts(force = false) {
    const { store, runner } = this.page;
    if (!store.lab) return;
    const now = performance.now();
    if (!force && now - this.lastReadoutMs < READOUT_INTERVAL_MS) return;
    this.lastReadoutMs = now;
    const st = runner.readState();
    this.page.robotsPanel.update(st.steps > 0 ? st : null, force);
    $('clock').textContent = `t = ${fmt(st.time_s, 1)} s / ${Number(store.scenario.duration_s.toFixed(1))} s`;
    $('progress').value = st.total_steps ? st.steps / st.total_steps : 0;
    this.refresh(st);
  }

  /** Which controls are enabled, the mode badge and the pressed tool. */
  refresh(st = this.page.runner.state) {
    const { store, runner, editor } = this.page;
    if (!store.lab || !st) return;
    const ed = runner.editable();
    const started = st.steps > 0;
    const robots = store.scenario.robots.length;
    $('run').disabled = runner.running || st.finished;
    $('pause').disabled = !runner.running;
    $('step').disabled = st.finished;
    $('reset').disabled = !started && !runner.running;
    $('add-robot').disabled = !ed || robots >= MAX_ROBOTS;
    $('add-robot').title = robots >= MAX_ROBOTS ? `At most ${MAX_ROBOTS} robots` : 'Add a robot near the middle of the view';
    $('delete').disabled = !ed || !store.selection;
    $('reset-preset').disabled = !(store.origin || store.preset);
    const badge = $('mode-badge');
    const [cls, text] = runner.running
      ? ['run', 'Running']
      : st.finished
        ? ['done', 'Finished']
        : started
          ? ['pause', 'Paused']
          : ['edit', 'Editing'];
    badge.className = `badge ${cls}`;
    badge.textContent = text;
    for (const b of document.querySelectorAll('button.tool')) b.setAttribute('aria-pressed', String(b.id === `tool-${editor.tool}`));
    this.page.canvas.classList.toggle('tool-wall', editor.tool === 'wall' && ed);
  }

  downloadLog(i) {
    const { store } = this.page;
    const csv = store.lab.logCsv(i);
    const name = `${safeName(store.scenario.name)}-${safeName(store.scenario.robots[i].name)}-log.csv`;
    download(name, csv, 'text/csv');
    setStatus(`Saved ${name} (${csv.split('\n').length - 2} steps).`, 'info');
  }

  wire() {
    const { guard, runner, editor, view, persistence } = this.page;
    // Mouse clicks should not leave focus on a button, so that Space keeps
    // meaning run/pause; keyboard users still tab to and press buttons.
    for (const b of document.querySelectorAll('.toolbar button')) b.addEventListener('mousedown', (e) => e.preventDefault());
    $('run').addEventListener('click', runner.run);
    $('pause').addEventListener('click', runner.pause);
    $('step').addEventListener('click', runner.step);
    $('reset').addEventListener('click', runner.reset);
    $('fit').addEventListener('click', () => view.fit());
    $('help').addEventListener('click', () => this.toggleHelp());
    $('help-close').addEventListener('click', () => this.toggleHelp(false));
    $('tool-select').addEventListener('click', () => editor.setTool('select'));
    $('tool-wall').addEventListener('click', () => editor.setTool('wall'));
    $('add-robot').addEventListener('click', editor.addRobot);
    $('delete').addEventListener('click', editor.deleteSelection);
    $('new').addEventListener('click', editor.newScenario);
    $('preset').addEventListener('change', (e) => this.loadPreset(e.target.value));
    $('export').addEventListener('click', guard(() => this.exportScenario()));
    $('import-label').addEventListener('keydown', (e) => {
      if (e.key === 'Enter' || e.key === ' ') {
        e.preventDefault();
        $('import-file').click();
      }
    });
    $('import-file').addEventListener('change', async (e) => {
      const file = e.target.files?.[0];
      e.target.value = '';
      if (file) await this.importScenario(file);
    });
    const speed = $('speed');
    speed.addEventListener('input', () => this.setSpeed(Number(speed.value)));
    this.setSpeed(Number(speed.value));
    $('reset-preset').addEventListener('click', () => persistence.resetToPreset());
    $('copy-link').addEventListener('click', () => persistence.copyLink());
    $('seed').addEventListener('change', guard((e) => this.setSeed(e.target)));
    $('duration').addEventListener('change', guard((e) => this.setDuration(e.target)));
    for (const k of Object.keys(view.layers)) {
      const box = $(`layer-${k}`);
      box.checked = view.layers[k];
      box.addEventListener('change', () => view.setLayer(k, box.checked));
    }
  }

  async loadPreset(name) {
    if (!name) return;
    try {
      await this.page.persistence.loadPreset(name);
      setStatus(`Loaded the ${name} preset (Ctrl+Z goes back to what you had).`, 'ok');
    } catch (err) {
      $('preset').value = this.page.store.preset;
      if (err instanceof Superseded) {
        setStatus(`Did not load the ${name} preset: you edited meanwhile. Choose it again to load it.`, 'warn');
      } else {
        setStatus(`Could not load the ${name} preset: ${message(err)}`, 'error');
      }
    }
  }

  exportScenario() {
    const { store } = this.page;
    const name = `${safeName(store.scenario.name)}.json`;
    download(name, store.lab.scenarioText(), 'application/json');
    setStatus(`Exported the scenario as ${name}.`, 'info');
  }

  async importScenario(file) {
    const { store, editor } = this.page;
    try {
      const asked = store.changes;
      const text = await file.text();
      if (store.changes !== asked) throw new Superseded(file.name);
      const before = JSON.stringify(store.scenario);
      store.load(text, { preset: '' });
      store.pushUndo(before);
      const s = store.scenario;
      setStatus(`Imported ${file.name}: “${s.name}”, ${s.walls.length} walls, ${s.robots.length} robots.`, 'ok');
      editor.reportProblems();
    } catch (err) {
      setStatus(`Could not import ${file.name}: ${message(err)}. The current scenario is unchanged.`, 'error');
    }
  }

  setSeed(input) {
    const n = Number(input.value);
    try {
      this.page.store.setSeed(n);
    } catch (err) {
      input.value = String(this.page.store.scenario.seed);
      throw err;
    }
    setStatus(`Seed ${n}: the run starts over from t = 0 with new noise.`, 'info');
  }

  setDuration(input) {
    const s = Number(input.value);
    try {
      this.page.store.setDuration(s);
    } catch (err) {
      input.value = String(this.page.store.scenario.duration_s);
      throw err;
    }
    setStatus(`Duration ${s} s.`, 'info');
  }
}
