// One checked frame pair of the merge, over the page: the two frames side
// by side, every ratio-test match as a line (green: an inlier of the
// method's fit, red: rejected), and, for the thesis method, the first
// frame's outline mapped into the second by the homography (the
// matched-region quad of thesis Figure 8). Opened from the merge panel's
// matched-pair table (web/page/match-table.js) and by the guided mode.
// Beside the pictures, a small map of the world with each frame's camera
// (web/page/pair-map.js), and under them the same in words: where each
// frame was really taken (the truth, which the methods never see), so a
// false match between two look-alike walls shows as two far-apart places. Closing it (Close or Esc) gives the focus
// back to where it was when the view opened.
import { deg, el, fmt } from './dom.js';
import { drawPairMap } from './pair-map.js';

const GAP_PX = 12;

export class PairView {
  /** @param {HTMLElement} host the overlay element (hidden while closed) */
  constructor(host) {
    this.host = host;
  }

  get isOpen() {
    return !this.host.hidden;
  }

  /**
   * Shows cell (row, col) of the match `table` (`{pair, a, b}` of
   * `lab.mergeView().tables`) of a merge with `method`; throws with the
   * Lab's message if the pair cannot be shown.
   */
  open(lab, table, method, row, col) {
    const pv = lab.mergePair(table.pair, row, col);
    if (!this.isOpen) this.returnTo = document.activeElement;
    const { width: w, height: h } = lab.camera();
    const canvas = el('canvas', { width: String(2 * w + GAP_PX), height: String(h), class: 'pair-canvas', role: 'img',
      'aria-label': `Frame ${pv.a_frame} of ${pv.a} and frame ${pv.b_frame} of ${pv.b} with their matches` });
    const ctx = canvas.getContext('2d');
    ctx.fillStyle = '#fff';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    const tmp = document.createElement('canvas');
    tmp.width = w;
    tmp.height = h;
    const tctx = tmp.getContext('2d');
    lab.drawFrame(table.a, pv.a_frame, tctx);
    ctx.drawImage(tmp, 0, 0);
    lab.drawFrame(table.b, pv.b_frame, tctx);
    ctx.drawImage(tmp, w + GAP_PX, 0);
    // matches: grey outliers, green rigid inliers (auto) / homography inliers (thesis)
    const useRigid = method !== 'thesis';
    for (const [x1, y1, x2, y2, hIn, rIn] of pv.matches) {
      const inl = useRigid ? rIn : hIn;
      ctx.strokeStyle = inl ? 'rgba(20,170,60,0.85)' : 'rgba(220,40,40,0.35)';
      ctx.lineWidth = inl ? 1.2 : 0.8;
      ctx.beginPath();
      ctx.moveTo(x1 + 0.5, y1 + 0.5);
      ctx.lineTo(x2 + 0.5 + w + GAP_PX, y2 + 0.5);
      ctx.stroke();
    }
    if (pv.quad) {
      ctx.strokeStyle = '#ffb000';
      ctx.lineWidth = 2;
      ctx.beginPath();
      pv.quad.forEach(([x, y], k) => {
        const px = x + 0.5 + w + GAP_PX;
        const py = y + 0.5;
        if (k === 0) ctx.moveTo(px, py);
        else ctx.lineTo(px, py);
      });
      ctx.closePath();
      ctx.stroke();
    }
    const inliers = useRigid ? pv.rigid_inliers : pv.homography_inliers;
    const cand = pv.candidate
      ? `This pair alone puts ${pv.b}\u2019s map frame at x ${fmt(pv.candidate[0])} m, y ${fmt(pv.candidate[1])} m, ` +
        `θ ${fmt(deg(pv.candidate[2]), 1)}° in ${pv.a}\u2019s.`
      : 'This pair gives no transform on its own.';
    const close = el('button', { type: 'button', text: 'Close', 'aria-label': 'Close the pair view' });
    close.addEventListener('click', () => this.close());
    const where = (robot, index, name) => {
      const t = lab.frame(robot, index).truth;
      return { t, text: `${name} took frame ${index} at x ${fmt(t[0], 1)} m, y ${fmt(t[1], 1)} m, facing ${fmt(deg(t[2]), 0)}°` };
    };
    const wa = where(table.a, pv.a_frame, pv.a);
    const wb = where(table.b, pv.b_frame, pv.b);
    const apart = Math.hypot(wa.t[0] - wb.t[0], wa.t[1] - wb.t[1]);
    const map = el('canvas', { class: 'pair-map', role: 'img',
      'aria-label': `Map of the world: where ${pv.a} took frame ${pv.a_frame} and ${pv.b} took frame ${pv.b_frame}, with what each camera saw` });
    const mapBox = el('figure', { class: 'pair-map-box' },
      map,
      el('figcaption', { text: 'Where each frame was taken (ground truth): the dot is the robot, the shade what its camera saw, the thick line that wall.' }));
    this.host.replaceChildren(
      el('h2', { text: `${pv.a} frame ${pv.a_frame} ↔ ${pv.b} frame ${pv.b_frame}` }),
      el('div', { class: 'pair-row' }, canvas, mapBox),
      el('p', { text: `${pv.matches.length} ratio-test matches, ${inliers} inliers (green; red: rejected). ` +
        (pv.quad ? 'Yellow: the first image\u2019s outline mapped into the second by the homography (thesis Figure 8). ' : '') + cand }),
      el('p', { class: 'pair-where', text: `Where they were taken (ground truth, in the world): ${wa.text}; ${wb.text}; ` +
        `${fmt(apart, 1)} m apart.` }),
      close,
    );
    this.host.hidden = false;
    const marks = [
      { robot: table.a, name: pv.a, frame: pv.a_frame, pose: wa.t },
      { robot: table.b, name: pv.b, frame: pv.b_frame, pose: wb.t },
    ];
    drawPairMap(map, lab.scenario().walls, marks, lab.camera().hfov_deg, map.clientWidth || 260);
    close.focus({ preventScroll: true });
  }

  close() {
    const wasOpen = this.isOpen;
    this.host.hidden = true;
    this.host.replaceChildren();
    const back = this.returnTo;
    this.returnTo = null;
    if (wasOpen && back?.isConnected && back !== document.body) back.focus({ preventScroll: true });
  }
}
