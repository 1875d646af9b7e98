// The full views over the lab (your maps, your log) and the lab's frame
// loop: while one of them covers an idle lab, the loop stops, so the page's
// main thread has nothing to do while a worker merges or replays; when the
// last one closes, the loop starts again.

export class Covers {
  constructor() {
    this.open = new Set();
    this.resume = null;
  }

  /** A view opened (`true`) or closed. */
  set(view, open) {
    if (open) this.open.add(view);
    else this.open.delete(view);
    document.body.classList.toggle('real-open', this.open.size > 0);
    if (!this.open.size && this.resume) {
      const resume = this.resume;
      this.resume = null;
      resume();
    }
  }

  /** Asked by the lab's frame loop each frame; true: skip this frame and stop until `resume`. */
  holdsFrames(labRunning, resume) {
    if (!this.open.size || labRunning) return false;
    this.resume = resume;
    return true;
  }
}
