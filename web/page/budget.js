// A frame's budget spent on a list of work (issue 22): the page redraws the
// panels of sixteen robots after a pause a few blocks a frame, not all in
// one long task.

/**
 * Calls `fn` on the items of `items` in order until `budgetMs` is spent
 * (always on the first); returns the items left for the next frame.
 */
export function spendFrame(items, budgetMs, fn) {
  const t0 = performance.now();
  let k = 0;
  while (k < items.length && (k === 0 || performance.now() - t0 < budgetMs)) fn(items[k++]);
  return items.slice(k);
}
