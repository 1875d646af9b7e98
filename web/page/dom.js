// Small helpers the panels share: building DOM elements and formatting
// numbers for display.

/** A number with `d` decimals, or an en dash when it is missing. */
export const fmt = (x, d = 2) => (Number.isFinite(x) ? x.toFixed(d) : '–');

/** Radians to degrees. */
export const deg = (rad) => (rad * 180) / Math.PI;

/**
 * `el('td', { class: 'num', text: '3' }, child…)`: an element. Props:
 * `class`, `text` (text content), `html` (inner HTML: only ever constant
 * text written in this repository), `style` (CSS text), `on<event>`
 * (a listener); any other is an attribute (`true` sets it empty; `false`
 * and `null` leave it out). Null children are skipped.
 */
export function el(tag, props = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else if (k === 'html') e.innerHTML = v;
    else if (k === 'style') e.style.cssText = v;
    else if (k.startsWith('on') && typeof v === 'function') e.addEventListener(k.slice(2), v);
    else if (v !== false && v != null) e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children) if (c != null) e.append(c);
  return e;
}
