// The timeline under "Your log"'s map (issue 55): the log's own time, in
// seconds from its first scan, with a slider to look back at any moment of
// what has been replayed, and "Start over".
//
// The slider spans the whole log (for several robots, the longest
// stretch); the part replayed so far is filled in on its track, and the
// label reads "time shown of total". Dragging it shows the replay as it
// was at that moment: the worker (log-worker.js, `seek`) draws each
// robot's map of the scans up to then at the poses its SLAM had then, the
// paths and the loop closures found by then. It cannot look ahead of the
// replay: a drag past the replayed part stops at its end. While the user
// drags, at most one request is under way; the latest position waits for
// it. Play, Step or a new replay return to the live end.

export const TIMELINE_HTML = `
  <style>
    .log-timeline { display: flex; align-items: center; gap: 10px; width: 100%; margin: 0 0 8px; }
    /* The track: dark up to the moment shown, light up to the live end (what was replayed), grey after. */
    #log-time { flex: 1; -webkit-appearance: none; appearance: none; background: transparent; height: 18px; margin: 0; }
    #log-time:disabled { opacity: 0.5; }
    #log-time::-webkit-slider-runnable-track { height: 6px; border-radius: 3px; background: var(--track); }
    #log-time::-moz-range-track { height: 6px; border-radius: 3px; background: var(--track); }
    #log-time::-webkit-slider-thumb { -webkit-appearance: none; width: 16px; height: 16px; margin-top: -5px;
      border-radius: 50%; background: #1f5fa8; border: 2px solid #fff; box-shadow: 0 0 0 1px #1f5fa8; }
    #log-time::-moz-range-thumb { width: 12px; height: 12px; border-radius: 50%; background: #1f5fa8; border: 2px solid #fff; }
    #log-time { --track: linear-gradient(to right, #1f5fa8 var(--shown, 0%), #9cc0e8 var(--shown, 0%),
      #9cc0e8 var(--replayed, 0%), #d9d9d4 var(--replayed, 0%)); }
    .log-timeline output { font-size: 13px; color: var(--muted); min-width: 16em; font-variant-numeric: tabular-nums; }
  </style>
  <div class="log-timeline" role="group" aria-label="Timeline">
    <input id="log-time" type="range" min="0" max="0" step="any" value="0"
      aria-label="The moment of the log shown (seconds from its first scan)" disabled>
    <output id="log-time-value" for="log-time"></output>
    <button type="button" id="log-again" title="Replay the logs from their first scan, without opening them again">Start over</button>
  </div>`;

/** How long a stretch of play Timeline.pace measures (ms). */
const PACE_WINDOW_MS = 2000;

/** A time in seconds as a person reads it: "42.5 s", "3 min 07 s". */
export function clock(t) {
  if (!(t >= 0)) return '0.0 s';
  if (t < 60) return `${t.toFixed(1)} s`;
  const m = Math.floor(t / 60);
  return `${m} min ${String(Math.floor(t - 60 * m)).padStart(2, '0')} s`;
}

export class Timeline {
  /** `root`: the view holding TIMELINE_HTML; `seek(t)`: shows moment `t` (a promise); `again()`: replays anew. */
  constructor(root, { seek, again }) {
    Object.assign(this, { seek, again });
    this.input = root.querySelector('#log-time');
    this.label = root.querySelector('#log-time-value');
    this.button = root.querySelector('#log-again');
    this.live = 0;
    this.duration = 0;
    this.moment = null;
    this.pending = null;
    this.running = false;
    this.input.addEventListener('input', () => this.dragged());
    this.button.addEventListener('click', () => this.again());
  }

  /** The slider moved: show that moment (not past the replayed part). */
  dragged() {
    const t = Math.min(Number(this.input.value), this.live);
    if (Number(this.input.value) > this.live) this.input.value = String(t);
    this.moment = t >= this.live ? null : t;
    this.paint();
    this.pending = t;
    if (!this.running) this.send();
  }

  async send() {
    this.running = true;
    while (this.pending !== null) {
      const t = this.pending;
      this.pending = null;
      await this.seek(t).catch(() => {});
    }
    this.running = false;
  }

  /**
   * The replay's state: `robots` as the worker describes them (each with
   * `time` replayed so far and `duration`, in s from its first scan);
   * `lookingBack`: whether a past moment is still shown; `can`: whether
   * Start over may be pressed.
   */
  show(robots, lookingBack, can) {
    this.duration = Math.max(0, ...robots.map((r) => r.duration));
    this.live = Math.max(0, ...robots.map((r) => r.time));
    // A moment asked for and not yet shown stays (the view refreshes as it pauses for it).
    if (!lookingBack && !this.running) this.moment = null;
    this.input.max = String(this.duration);
    this.input.disabled = !(this.live > 0);
    this.button.disabled = !can;
    if (this.moment === null && !this.running) this.input.value = String(this.live);
    this.paint();
  }

  /** The label and the replayed part of the track. */
  paint() {
    const shown = this.moment ?? this.live;
    const total = this.duration;
    this.label.textContent = !total
      ? ''
      : `${clock(shown)} of ${clock(total)}${this.moment !== null ? ` · looking back (replayed to ${clock(this.live)})` : ''}`;
    const share = (t) => `${(total > 0 ? (100 * t) / total : 0).toFixed(2)}%`;
    this.input.style.setProperty('--replayed', share(this.live));
    this.input.style.setProperty('--shown', share(shown));
  }

  /**
   * How fast the replay's live end has moved against the wall clock over
   * the last PACE_WINDOW_MS while `playing` (× real time), or null (not
   * playing, or not long enough to tell).
   */
  pace(playing) {
    if (!playing) {
      this.samples = [];
      return null;
    }
    const now = performance.now();
    this.samples = [...(this.samples ?? []).filter(([t]) => now - t < PACE_WINDOW_MS), [now, this.live]];
    const [t0, l0] = this.samples[0];
    return now - t0 > PACE_WINDOW_MS / 2 ? (this.live - l0) / ((now - t0) / 1000) : null;
  }

  /** For tests and the console: the moment shown (s) or null at the live end, and the times. */
  snapshot() {
    return { moment: this.moment, live: this.live, duration: this.duration };
  }
}
