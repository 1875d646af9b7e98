// The robots' colours on the page: the renderer's own list
// (`robotColours()` of the wasm build, crate/src/palette.rs), set once the
// wasm is up, so that a robot's card, camera, map, markers and name label
// have the colour it is drawn in on the map.

/** Robot colours by index, `[r, g, b]`; one grey until the wasm is up. */
export const ROBOT_COLOURS = [[80, 80, 80]];

export function setRobotColours(list) {
  ROBOT_COLOURS.splice(0, ROBOT_COLOURS.length, ...list);
}

/** Robot `i`'s colour as CSS, with `alpha` if it is below 1. */
export function robotColour(i, alpha = 1) {
  const [r, g, b] = ROBOT_COLOURS[i % ROBOT_COLOURS.length];
  return alpha === 1 ? `rgb(${r},${g},${b})` : `rgba(${r},${g},${b},${alpha})`;
}

/** Robot `i`'s colour darkened for text (its name on the map). */
export function darkerColour(i) {
  return robotColour(i).replace(/\d+/g, (c) => String(Math.round(Number(c) * 0.7)));
}
