// One opened map's card in "Your maps" (web/page/real/panel.js): its
// picture in its colour (made by the merge worker at its shown size), its
// name, size, resolution and origin. An image opened without a YAML was
// read at a resolution the page assumed: the card says so ("0.05 m,
// assumed — change") and lets the user type the right one, which reads the
// image again (`reread(name, resolution)`). An image that does not look
// like an occupancy grid carries the worker's warning.

/** A number as a short decimal: no float noise (1.2000000000000002 is 1.2). */
export function tidy(v) {
  return String(Number(Number(v).toFixed(6)));
}

/** The card of map `m` (the worker's facts: name, imageName, width, height, resolution, origin, assumed, warning, thumb, colour). */
export function mapCard(m, reread) {
  const div = document.createElement('figure');
  div.className = 'real-card';
  div.dataset.map = m.name;
  div.style.borderColor = m.colour;
  const c = document.createElement('canvas');
  c.width = m.thumb.width;
  c.height = m.thumb.height;
  c.getContext('bitmaprenderer').transferFromImageBitmap(m.thumb);
  c.setAttribute('aria-label', `${m.name}, drawn in its colour`);
  const cap = document.createElement('figcaption');
  const b = document.createElement('b');
  b.style.color = m.colour;
  b.textContent = m.imageName === m.name ? m.name : `${m.name} + ${m.imageName}`;
  const o = m.origin.map(tidy).join(', ');
  cap.append(b, document.createElement('br'), `${m.width} × ${m.height} cells · `);
  if (m.assumed) cap.append(assumedResolution(m, reread));
  else cap.append(`${tidy(m.resolution)} m`);
  cap.append(` · origin [${o}]`);
  div.append(c, cap);
  if (m.warning) {
    const w = document.createElement('p');
    w.className = 'real-card-warning';
    w.setAttribute('role', 'note');
    w.textContent = m.warning;
    div.append(w);
  }
  return div;
}

/** "0.05 m, assumed — change": the button opens a box to type the resolution and read the image again. */
function assumedResolution(m, reread) {
  const span = document.createElement('span');
  span.className = 'real-assumed';
  const change = document.createElement('button');
  change.type = 'button';
  change.className = 'real-assumed-change';
  change.textContent = 'change';
  change.setAttribute('aria-label', `Change the resolution of ${m.name}, assumed ${tidy(m.resolution)} m`);
  span.append(`${tidy(m.resolution)} m, assumed — `, change);
  change.addEventListener('click', () => {
    const input = document.createElement('input');
    input.type = 'number';
    input.min = '0.001';
    input.step = '0.005';
    input.value = tidy(m.resolution);
    input.className = 'num';
    input.setAttribute('aria-label', `Resolution of ${m.name} in metres per cell`);
    const read = document.createElement('button');
    read.type = 'button';
    read.textContent = 'Read again';
    const go = () => reread(m.name, input.value);
    read.addEventListener('click', go);
    input.addEventListener('keydown', (e) => {
      if (e.key === 'Enter') go();
    });
    span.replaceChildren(input, ' m per cell ', read);
    input.focus();
    input.select();
  });
  return span;
}
