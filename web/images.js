// SURF on single images as JavaScript sees it: a facade over the raw
// wasm-bindgen functions `surf_features`, `surf_features_rgba` and
// `surf_match` (crate/src/bindings/surf.rs), used by the `features` and
// `match` commands (web/cli/surf.mjs).
//
// These take image files, not a lab: the bytes of a PNG or JPEG (decoded in
// wasm, so node and the page see the same pixels) or a canvas's RGBA, and
// return the `features` and `match` documents of docs/interfaces.md. As
// web/lab.js does for `Lab`, this module parses each JSON text the binding
// returns once, here: `features(wasm, bytes)` is an object, and
// `featuresText(wasm, bytes)` the binding's text byte for byte, for a
// caller that prints it (`features --json`). The binding's errors (an image
// that does not decode, one too large) are thrown unchanged, as `Error`s
// whose message names the problem.
//
// This module imports nothing: each function takes the loaded wasm-bindgen
// module `wasm`.

/** The `features` document of a PNG/JPEG (Uint8Array): `{width, height, keypoints: [{x, y, scale, orientation, laplacian, response, descriptor}]}`. */
export function features(wasm, bytes) {
  return JSON.parse(featuresText(wasm, bytes));
}

/** The same as the binding's JSON text, byte for byte. */
export function featuresText(wasm, bytes) {
  return wasm.surf_features(bytes);
}

/** The `features` document of straight RGBA pixels (a canvas's `ImageData.data`) `width` × `height`. */
export function featuresOfRgba(wasm, rgba, width, height) {
  return JSON.parse(wasm.surf_features_rgba(rgba, width, height));
}

/**
 * The `match` document of two PNG/JPEG images: `{matches, inliers,
 * homography, quad, shrinkage, shift, left_right_ratio, keypoints}`, with
 * `homography` (image 1 pixels to image 2 pixels) and the region null when
 * MSAC finds no model.
 */
export function match(wasm, bytes1, bytes2) {
  return JSON.parse(matchText(wasm, bytes1, bytes2));
}

/** The same as the binding's JSON text, byte for byte. */
export function matchText(wasm, bytes1, bytes2) {
  return wasm.surf_match(bytes1, bytes2);
}
