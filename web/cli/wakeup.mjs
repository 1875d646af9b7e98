// One waiter for "the next message from any worker": a pool's loop awaits
// next(), and each worker's message or error handler calls wake(). A wake
// with nobody waiting is dropped, so a loop re-checks its condition before
// it waits again (the pools' loops do).
export class Wakeup {
  constructor() {
    this.resolve = null;
  }

  /** Resolves at the next wake(). */
  next() {
    return new Promise((resolve) => {
      this.resolve = resolve;
    });
  }

  wake() {
    const resolve = this.resolve;
    this.resolve = null;
    if (resolve) resolve();
  }
}
