// A ROS bag as "Your log" shows it (log-panel.js, issue 53): one card a
// bag, with what the bag holds (container, compression, size, messages,
// duration), its topics (name, type, messages, and what the replay uses
// each for), what was lost when the bag could be read only in part, and
// what the replay picked and why — the LaserScan topic, the odometry, the
// ground truth, the laser's place on the robot — with a select for each
// pick. A bag picks by itself as `run-log` does (crate/src/formats/bag/
// recording.rs): the only LaserScan topic or the busiest; an Odometry
// topic, else the moving tf transform to the laser's base, else none
// (scan matching alone, from a constant-velocity prediction); a pose topic
// named as ground truth. Changing a select asks the log worker to make
// that bag's replays anew with the new picks, from the bag it keeps (the
// file is not read again).

import { deg, el, fmt } from '../dom.js';

/** What a pick the user made is called (the reader's reasons are worded for the command line). */
const BY_YOU = 'picked by you';

const mb = (bytes) => `${(bytes / 1e6).toFixed(bytes < 1e7 ? 2 : 1)} MB`;
/** A count as a person reads it: 71,280. */
const count = (n) => n.toLocaleString('en');

/** The value of a topic option. */
const topicValue = (t) => `topic:${t}`;

/** The odometry select's options and the one the replay uses: `{options: [[value, label]], value}`. */
function odometryChoice({ auto, picked, picks }) {
  const options = auto.odometry_topics.map((t) => [topicValue(t), t]);
  if (auto.odometry?.startsWith('tf ')) options.unshift(['auto', auto.odometry]);
  options.push(['none', 'none: scan matching alone']);
  let value = 'none';
  if (picks.odom_none) value = 'none';
  else if (picks.odom_topic) value = topicValue(picks.odom_topic);
  else if (picked.odometry?.startsWith('tf ')) value = 'auto';
  else if (picked.odometry) value = topicValue(picked.odometry);
  return { options, value };
}

/** The ground-truth select's options and the one shown. */
function truthChoice({ auto, picked, truthHidden }) {
  const options = auto.truth_topics.map((t) => [topicValue(t), t]);
  options.push(['none', 'none']);
  const value = !truthHidden && picked.truth_topic ? topicValue(picked.truth_topic) : 'none';
  return { options, value };
}

/** The picks the selects of `card` ask for, against what the bag picks by itself: `{picks, truthHidden}`. */
function picksOf(card, auto) {
  const v = (k) => card.querySelector(`select[data-pick="${k}"]`).value;
  const picks = {};
  if (v('scan') !== auto.scan_topic) picks.scan_topic = v('scan');
  const odom = v('odom');
  if (odom === 'none' && auto.odometry) picks.odom_none = true;
  if (odom.startsWith('topic:') && odom !== topicValue(auto.odometry)) picks.odom_topic = odom.slice(6);
  const truth = v('truth');
  if (truth.startsWith('topic:') && truth !== topicValue(auto.truth_topic)) picks.truth_topic = truth.slice(6);
  const truthHidden = truth === 'none' && !!auto.truth_topic;
  if (truthHidden) picks.truth_none = true;
  return { picks, truthHidden };
}

function select(key, label, { options, value }) {
  const s = el('select', { 'data-pick': key, 'aria-label': label });
  for (const [v, text] of options) s.append(new Option(text, v, v === value, v === value));
  if (!options.some(([v]) => v === value)) s.append(new Option(value.replace(/^topic:/, ''), value, true, true));
  return s;
}

/** One row of the picks: a label, then its control with the reason beside it (or under it, when narrow). */
function row(label, control, reason) {
  return [el('span', { class: 'bag-pick-label', text: label }), el('div', { class: 'bag-pick' }, control, el('span', { class: 'bag-why', text: reason }))];
}

/** The card of one bag (`bag` as the worker describes it; `colour` its first robot's). */
function card(bag, colour) {
  const { info, picked, picks, auto, truthHidden, lost } = bag;
  const used = new Map([[picked.scan_topic, 'scans'], [picked.odometry, 'odometry']]);
  if (picked.truth_topic && !truthHidden) used.set(picked.truth_topic, 'ground truth');
  const packed = info.compression.filter((c) => c && c !== 'none');
  const compression = packed.length ? packed.join(', ') : 'uncompressed';
  const topics = el(
    'table',
    { class: 'bag-topics' },
    el('caption', { text: `${info.topics.length} topic${info.topics.length === 1 ? '' : 's'}` }),
    el('thead', {}, el('tr', {}, el('th', { text: 'Topic' }), el('th', { text: 'Type' }), el('th', { class: 'num', text: 'Messages' }), el('th', { text: 'Used for' }))),
    el(
      'tbody',
      {},
      ...info.topics.map((t) =>
        el('tr', { class: used.has(t.name) ? 'used' : null }, el('td', { text: t.name }), el('td', { text: t.type }), el('td', { class: 'num', text: count(t.count) }), el('td', { text: used.get(t.name) ?? '' })),
      ),
    ),
  );
  const scanWhy = picks.scan_topic ? BY_YOU : picked.scan_reason;
  const odomWhy = picks.odom_none ? `${BY_YOU}: scan matching alone, from a constant-velocity prediction` : picks.odom_topic ? BY_YOU : picked.odometry_reason;
  const truthWhy = truthHidden ? `${BY_YOU}: the ground truth is not drawn` : picks.truth_topic ? `${BY_YOU}: drawn beside SLAM's path, not fed to SLAM` : picked.truth_reason;
  const [x, y, th] = picked.laser_offset;
  const frames = picked.laser_frame === picked.base_frame ? picked.laser_frame : `${picked.laser_frame} on ${picked.base_frame}`;
  const offset = el('span', { class: 'bag-offset', text: `${frames}: x ${fmt(x, 3)} m, y ${fmt(y, 3)} m, θ ${fmt(deg(th), 1)}°` });
  const picksBox = el(
    'div',
    { class: 'bag-picks', role: 'group', 'aria-label': `What the replay of ${bag.name} uses` },
    ...row('Scans', select('scan', 'Scan topic', { options: auto.scan_topics.map((t) => [t, t]), value: picked.scan_topic }), scanWhy),
    ...row('Odometry', select('odom', 'Odometry', odometryChoice(bag)), odomWhy),
    ...row('Ground truth', select('truth', 'Ground truth', truthChoice(bag)), truthWhy),
    ...row('Laser on the robot', offset, picked.offset_reason),
  );
  const duration = info.duration_s > 0 ? ` over ${fmt(info.duration_s, 1)} s` : '';
  return el(
    'section',
    { class: 'bag-card', style: `--c:${colour ?? '#888'}`, 'data-bag': String(bag.id), 'aria-label': `Bag ${bag.name}` },
    el('h2', { class: 'real-swatch', style: `--c:${colour ?? '#888'}`, text: bag.name }),
    el('p', { class: 'real-stage', text: `${info.container}, ${compression}, ${mb(info.bytes)}: ${count(info.messages)} messages${duration}; ${count(bag.records)} scans to replay` }),
    lost.length ? el('p', { class: 'real-message warn bag-lost', text: `Read only in part: what was complete is replayed. Lost: ${lost.join(' · ')}` }) : null,
    picksBox,
    topics,
  );
}

export class BagPicks {
  /** `box`: where the cards go; `onPick(bagId, picks, truthHidden)`: a promise, settled when the replays are made anew. */
  constructor(box, onPick) {
    this.box = box;
    this.onPick = onPick;
    this.shown = new Map(); // bag id → {key, node}
    this.pending = false;
  }

  /** Shows `bags` (the worker's description), each card redrawn only when it changed; `robots` give the colours. */
  show(bags, robots, force = false) {
    this.bags = bags;
    this.robots = robots;
    if (this.pending) return;
    const keep = new Set(bags.map((b) => b.id));
    for (const [id, { node }] of this.shown) {
      if (!keep.has(id)) {
        node.remove();
        this.shown.delete(id);
      }
    }
    let before = null;
    for (const bag of bags) {
      const colour = robots.find((r) => r.logId === bag.id)?.colour;
      const key = JSON.stringify([bag.picks, bag.picked, bag.truthHidden, bag.lost, bag.records, colour]);
      let entry = this.shown.get(bag.id);
      if (!entry || entry.key !== key || force) {
        const node = card(bag, colour);
        for (const s of node.querySelectorAll('select')) s.addEventListener('change', () => this.picked(bag.id, node));
        if (entry) entry.node.replaceWith(node);
        entry = { key, node };
        this.shown.set(bag.id, entry);
      }
      if (entry.node.previousElementSibling !== before || entry.node.parentNode !== this.box) {
        if (before) before.after(entry.node);
        else this.box.prepend(entry.node);
      }
      before = entry.node;
    }
    this.box.hidden = !bags.length;
  }

  /** A select of bag `id`'s card changed: its replays are made anew (or, refused, the card shows what is). */
  async picked(id, node) {
    const bag = this.bags.find((b) => b.id === id);
    if (!bag) return;
    const { picks, truthHidden } = picksOf(node, bag.auto);
    this.pending = true;
    node.classList.add('busy');
    for (const s of node.querySelectorAll('select')) s.disabled = true;
    try {
      await this.onPick(id, picks, truthHidden);
    } finally {
      this.pending = false;
      this.show(this.bags, this.robots, true);
    }
  }
}
