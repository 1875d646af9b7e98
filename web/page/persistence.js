// Where the scenario comes from and where it is kept: the presets in
// scenarios/, the autosave in this browser's localStorage, and links that
// carry the scenario and seed in the URL (encoded by web/page/share.js).
//
// On opening, a link wins over the autosave, and the autosave over the
// thesis preset. Once the page was opened from a link or a link was
// copied, the address bar follows every edit (debounced), so a reload or a
// bookmark keeps the current scenario. The current link is kept ready for
// the printed summary.
import { decodeShare, encodeShare } from './share.js';
import { message, setStatus, statusText } from './status.js';

const STORAGE_KEY = 'slamlab.scenario.v1';
const DEFAULT_PRESET = 'thesis';
const SHARE_DEBOUNCE_MS = 250;

/** A load given up because the scenario was edited while it was loading; the edit is kept. */
export class Superseded extends Error {
  constructor(what) {
    super(`the scenario was edited while ${what} was loading, and that edit is kept; ask again to load it`);
    this.name = 'Superseded';
  }
}

export class Persistence {
  /**
   * @param {import('./state.js').Store} store
   * @param {{validate: (text: string) => string}} hooks  the Lab's canonical form of a scenario text
   */
  constructor(store, hooks) {
    this.store = store;
    this.hooks = hooks;
    this.shareHash = ''; // the URL fragment last written
    this.shareInUrl = false; // keep the address bar's fragment in step with the scenario
    this.currentLink = ''; // the link to the current scenario, as last computed
    this.shareTimer = 0;
  }

  /** Follows links pasted into the address bar of the open page. */
  listen() {
    window.addEventListener('hashchange', () => this.openPasted());
  }

  /**
   * Loads preset `name` from scenarios/ (undo goes back to what was there).
   * If the scenario changed while the preset was on its way (the user drew,
   * added a robot, changed the seed), that change is newer than the request:
   * it is kept and the load throws a {@link Superseded}.
   */
  async loadPreset(name) {
    const asked = this.store.changes;
    const res = await fetch(`scenarios/${name}.json`);
    if (!res.ok) throw new Error(`could not fetch scenarios/${name}.json (HTTP ${res.status})`);
    const text = await res.text();
    if (this.store.changes !== asked) throw new Superseded(`the ${name} preset`);
    this.store.pushUndo();
    this.store.load(text, { preset: name });
    this.store.presetDurations[name] = this.store.scenario.duration_s;
    return this.store.scenario;
  }

  autosave() {
    const s = this.store;
    try {
      localStorage.setItem(
        STORAGE_KEY,
        JSON.stringify({ version: 1, preset: s.preset, origin: s.origin, scenario: s.scenario }),
      );
    } catch (e) {
      setStatus(`Could not autosave in this browser: ${message(e)}`, 'warn');
    }
  }

  /** The URL fragment that restores the current scenario and seed. */
  currentShareHash() {
    const s = this.store;
    return encodeShare(s.scenario, { preset: s.preset, presetDuration: s.presetDurations[s.preset], origin: s.origin });
  }

  /** A link that opens this scenario with this seed. */
  async shareLink() {
    return `${location.origin}${location.pathname}#${await this.currentShareHash()}`;
  }

  /** Keeps the current link ready and, when asked to, the address bar in step (debounced). */
  scheduleShareHash() {
    clearTimeout(this.shareTimer);
    this.shareTimer = setTimeout(async () => {
      try {
        const hash = await this.currentShareHash();
        this.currentLink = `${location.origin}${location.pathname}#${hash}`;
        if (!this.shareInUrl) return;
        this.shareHash = hash;
        if (location.hash.slice(1) !== hash || location.search) {
          history.replaceState(history.state, '', `${location.pathname}#${hash}`);
        }
      } catch (e) {
        setStatus(`Could not put the scenario in the address bar: ${message(e)}`, 'warn');
      }
    }, SHARE_DEBOUNCE_MS);
  }

  /** After every change of the scenario: save it, and keep the link in step. */
  saveAndShare() {
    this.autosave();
    this.scheduleShareHash();
  }

  /** Opens what a shared link asks for; throws, keeping the scenario, if it cannot. */
  async openShared(shared) {
    const store = this.store;
    if (shared.kind === 'preset') {
      await this.loadPreset(shared.preset);
      if (shared.seed != null && shared.seed !== store.scenario.seed) store.setSeed(shared.seed);
      if (shared.duration != null && shared.duration !== store.scenario.duration_s) store.setDuration(shared.duration);
    } else {
      const before = store.scenario ? JSON.stringify(store.scenario) : null;
      store.load(shared.text, { preset: '', origin: shared.origin });
      store.pushUndo(before);
    }
  }

  /** Loads the scenario of a shared link, else the autosave, else the thesis preset. */
  async restore() {
    let problem = '';
    try {
      const shared = await decodeShare(location.hash, location.search);
      if (shared) {
        this.shareInUrl = true;
        const saved = this.savedScenarioText(); // before the link replaces the autosave
        await this.openShared(shared);
        this.store.clearUndo();
        const s = this.store.scenario;
        const same = saved !== null && saved === this.hooks.validate(this.store.lab.scenarioText());
        setStatus(same
          ? `Restored your last scenario “${s.name}” (seed ${s.seed}) from the address bar.`
          : `Opened a shared link: “${s.name}” with seed ${s.seed}. Press Run (Space) to run it.`, 'ok');
        return;
      }
    } catch (e) {
      problem = `The link could not be opened (${message(e)}). `;
    }
    await this.restoreSaved();
    if (problem) setStatus(problem + statusText(), 'warn');
  }

  /** The autosaved scenario in the Lab's canonical JSON, or null. */
  savedScenarioText() {
    try {
      const saved = JSON.parse(localStorage.getItem(STORAGE_KEY) ?? 'null');
      return saved?.scenario ? this.hooks.validate(JSON.stringify(saved.scenario)) : null;
    } catch {
      return null;
    }
  }

  /** Restores the autosaved scenario; a corrupt save is reported, never fatal. */
  async restoreSaved() {
    let saved = null;
    try {
      saved = localStorage.getItem(STORAGE_KEY);
    } catch {
      saved = null;
    }
    if (saved == null) {
      await this.loadPreset(DEFAULT_PRESET);
      setStatus('Loaded the thesis preset. Press Run (Space) to start, or edit the map first.', 'info');
      return;
    }
    try {
      let obj;
      try {
        obj = JSON.parse(saved);
      } catch (e) {
        throw new Error(`not valid JSON (${message(e)})`);
      }
      if (!obj || typeof obj !== 'object' || !obj.scenario) throw new Error('it holds no scenario');
      const preset = typeof obj.preset === 'string' ? obj.preset : '';
      this.store.load(JSON.stringify(obj.scenario), { preset, origin: typeof obj.origin === 'string' ? obj.origin : preset });
      this.store.clearUndo();
      setStatus(`Restored your last scenario “${this.store.scenario.name}” from this browser.`, 'ok');
    } catch (e) {
      try {
        localStorage.setItem(`${STORAGE_KEY}.corrupt`, saved);
      } catch {
        // nothing more we can do
      }
      await this.loadPreset(DEFAULT_PRESET);
      this.store.clearUndo();
      setStatus(
        `The scenario saved in this browser could not be restored: ${message(e)}. ` +
          `Loaded the thesis preset instead (the bad save is kept under "${STORAGE_KEY}.corrupt").`,
        'warn',
      );
    }
  }

  /** A link pasted into the address bar of an open page. */
  async openPasted() {
    if (!this.store.lab || location.hash.slice(1) === this.shareHash) return;
    try {
      const shared = await decodeShare(location.hash);
      if (!shared) return;
      this.shareInUrl = true;
      await this.openShared(shared);
      const s = this.store.scenario;
      setStatus(`Opened the link: “${s.name}” with seed ${s.seed} (Ctrl+Z goes back).`, 'ok');
    } catch (e) {
      setStatus(`The link could not be opened: ${message(e)}. The scenario is unchanged.`, 'error');
    }
  }

  async copyLink() {
    let link;
    try {
      link = await this.shareLink();
    } catch (e) {
      setStatus(`Could not make a link: ${message(e)}`, 'error');
      return;
    }
    // From now on the address bar holds the link too, and follows edits.
    this.shareInUrl = true;
    this.scheduleShareHash();
    const s = this.store.scenario;
    try {
      await navigator.clipboard.writeText(link);
      setStatus(`Link copied: it opens “${s.name}” with seed ${s.seed} (${link.length} characters).`, 'ok');
    } catch {
      setStatus('The browser did not let the page use the clipboard: copy the address bar instead, it holds the same link.', 'warn');
    }
  }

  async resetToPreset() {
    const name = this.store.origin || this.store.preset;
    if (!name) {
      setStatus('This scenario did not come from a preset (New or Import): there is no preset to reset to.', 'info');
      return;
    }
    try {
      await this.loadPreset(name);
      setStatus(`Back to the ${name} preset as shipped, seed ${this.store.scenario.seed} (Ctrl+Z goes back to what you had).`, 'ok');
    } catch (e) {
      setStatus(`Could not load the ${name} preset: ${message(e)}`, 'error');
    }
  }
}
