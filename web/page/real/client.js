// The page's side of its workers (merge-worker.js, log-worker.js):
// requests as promises, progress lines to a callback. A worker is started
// on first use, so a page that never opens saved maps or logs never
// loads a second wasm.

export class WorkerClient {
  /** `url`: the module worker; `onProgress(text, message)`: its progress lines (and the whole message). */
  constructor(url, onProgress = () => {}) {
    this.url = url;
    this.onProgress = onProgress;
    this.worker = null;
    this.next = 1;
    this.waiting = new Map();
  }

  start() {
    if (this.worker) return;
    this.worker = new Worker(this.url, { type: 'module' });
    this.worker.onmessage = ({ data }) => {
      if (data.type === 'progress') {
        this.onProgress(data.text, data);
        return;
      }
      const w = this.waiting.get(data.id);
      if (!w) return;
      this.waiting.delete(data.id);
      if (data.ok) w.resolve(data);
      else w.reject(new Error(data.error));
    };
    this.worker.onerror = (e) => {
      const error = new Error(`the page's worker failed: ${e.message || 'could not load it (is web/pkg built?)'}`);
      for (const w of this.waiting.values()) w.reject(error);
      this.waiting.clear();
      this.worker?.terminate();
      this.worker = null;
    };
  }

  request(message, transfer = []) {
    this.start();
    const id = this.next++;
    return new Promise((resolve, reject) => {
      this.waiting.set(id, { resolve, reject });
      this.worker.postMessage({ ...message, id }, transfer);
    });
  }

}

/** The saved-maps merge worker's requests (merge-worker.js). */
export class SavedMapsClient extends WorkerClient {
  constructor(onProgress) {
    super(new URL('./merge-worker.js', import.meta.url), onProgress);
  }

  /** Reads `files` ([{name, bytes: ArrayBuffer}]) into maps: `{added, errors}`. */
  add(files, resolution, colours) {
    return this.request({ type: 'add', files, resolution, colours }, files.map((f) => f.bytes));
  }

  /** Reads image-only map `name` again at `resolution`: `{map}` (its card's facts, as `add` gives them). */
  reread(name, resolution) {
    return this.request({ type: 'reread', name, resolution });
  }

  /** Images at an assumed resolution the last merge left alone, that merge at another: `{hints}` (scale-probe.js). */
  scales() {
    return this.request({ type: 'scales' });
  }

  /** Merges the maps read so far: `{report, files, groupFiles}` (each group's files, null for a map alone). */
  merge() {
    return this.request({ type: 'merge' });
  }

  /**
   * Shows map `b` (index) with its frame at `pose` in map `a`'s; `fit` fits
   * the view anew; `judged` (a pose) outlines where a refused refine put
   * it: `{view}`.
   */
  adjust(a, b, pose, fit = false, judged = null) {
    return this.request({ type: 'adjust', a, b, pose, fit, judged });
  }

  /** Joins map `b` to map `a` at `pose` as placed, not verified: `{pair, report, files}`. */
  keep(a, b, pose) {
    return this.request({ type: 'keep', a, b, pose });
  }

  /** Back to the merge's overlay: `{view}`. */
  endAdjust() {
    return this.request({ type: 'endAdjust' });
  }

  /** Aligns map `b` on map `a` from `pose`: `{pair, report, files}`. */
  refine(a, b, pose) {
    return this.request({ type: 'refine', a, b, pose });
  }

  /** Shows group `group` of the last report in the overlay: `{view}`. */
  showGroup(group) {
    return this.request({ type: 'group', group });
  }

  /** Forgets every map. */
  clear() {
    return this.worker ? this.request({ type: 'clear' }) : Promise.resolve();
  }
}
