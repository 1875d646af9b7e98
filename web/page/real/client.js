// The page's side of the merge worker (merge-worker.js): requests as
// promises, progress lines to a callback. The worker is started on first
// use, so a page that never opens its own maps never loads a second wasm.

export class MergeClient {
  /** `onProgress(text)`: a line from the merge as each pair is judged. */
  constructor(onProgress) {
    this.onProgress = onProgress;
    this.worker = null;
    this.next = 1;
    this.waiting = new Map();
  }

  start() {
    if (this.worker) return;
    this.worker = new Worker(new URL('./merge-worker.js', import.meta.url), { type: 'module' });
    this.worker.onmessage = ({ data }) => {
      if (data.type === 'progress') {
        this.onProgress(data.text);
        return;
      }
      const w = this.waiting.get(data.id);
      if (!w) return;
      this.waiting.delete(data.id);
      if (data.ok) w.resolve(data);
      else w.reject(new Error(data.error));
    };
    this.worker.onerror = (e) => {
      const error = new Error(`the merge worker failed: ${e.message || 'could not load it (is web/pkg built?)'}`);
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

  /** Reads `files` ([{name, bytes: ArrayBuffer}]) into maps: `{added, errors}`. */
  add(files, resolution, colours) {
    return this.request({ type: 'add', files, resolution, colours }, files.map((f) => f.bytes));
  }

  /** Merges the maps read so far: `{report, files}` (files null on no_merge). */
  merge() {
    return this.request({ type: 'merge' });
  }

  /** Forgets every map. */
  clear() {
    return this.worker ? this.request({ type: 'clear' }) : Promise.resolve();
  }
}
