// Do two maps' scales disagree? (used by the merge worker, after a merge)
//
// An image opened without a YAML is read at a resolution the page assumed
// (0.05 m per cell unless typed). When that guess is wrong, the image's
// walls are too long or too short against another map's, and the merge
// cannot lay them on each other. The merge searches turns and shifts, not
// scales, so here the image is tried again, off the page, at a few other
// resolutions (the other map's own, half and twice the assumed one) against
// one map that has its YAML (a known scale). Only a merge that passes the
// same tests is reported: "merges with a.yaml read at 0.05 m per cell".
// Nothing is said when no other scale merges either: the cause may be
// anything.

/**
 * `pictures`: the worker's maps by name (`{name, resolution, read, source}`:
 * `read` the YAML and image bytes of a map, `source` set for an image read
 * at an assumed resolution); `report`: the last merge's. Returns
 * `[{name, other, assumed, resolution, confidence}]`: each image not
 * joined to any map that does merge with a YAML map at another resolution.
 */
export function probeScales(wasm, SavedMaps, pictures, report, yamlForImage) {
  const joined = new Set((report.merge.groups ?? []).filter((g) => g.maps.length > 1).flatMap((g) => g.maps));
  const all = [...pictures.values()];
  const hints = [];
  for (const p of all) {
    if (!p.source || joined.has(p.name)) continue;
    const other = all.find((o) => o !== p && o.read && !o.source);
    if (!other) continue;
    const tries = [...new Set([other.resolution, p.resolution / 2, p.resolution * 2])].filter((r) => Math.abs(r - p.resolution) > 1e-9);
    for (const r of tries) {
      const probe = SavedMaps.open(wasm);
      try {
        probe.addMap(other.name, other.read.yaml, other.read.imageName, other.read.image);
        probe.addMap(p.name, yamlForImage(p.source.imageName, r), p.source.imageName, p.source.image);
        const m = probe.merge().merge;
        if (m.status === 'merged') {
          hints.push({ name: p.name, other: other.name, assumed: p.resolution, resolution: r, confidence: m.confidence });
          break;
        }
      } catch {
        // A resolution the map cannot be read at (too many cells): not a scale it has.
      } finally {
        probe.free();
      }
    }
  }
  return hints;
}

/** The hint's words. */
export function scaleHintText(h) {
  return `${h.name} does not fit ${h.other} at the ${h.assumed} m per cell assumed, but merges with it read at ` +
    `${h.resolution} m per cell (measured: confidence ${h.confidence.toFixed(2)}): change its resolution on its card?`;
}
