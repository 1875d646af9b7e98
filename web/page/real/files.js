// Which picked files make which maps (used by the merge worker).
//
// A ROS map_server map is a YAML file whose `image` field names its image
// (a path relative to the YAML's folder). A browser's file picker or a drop
// gives bare file names, no folders, so each YAML's image is matched to a
// picked file by its last path component. An image no YAML names becomes a
// map of its own at the resolution the user typed (origin 0, thresholds as
// map_server's defaults); an image with the stem of a YAML that could not
// be read is left out with it. Every problem is a message that names the file
// and the field, and the files that are fine still load.

const YAML = /\.ya?ml$/i;
const IMAGE = /\.(pgm|png)$/i;

/** The last component of a path as a YAML writes it (either slash). */
export function baseName(p) {
  return String(p).split(/[\\/]/).pop();
}

/** The YAML map_server would need for an image picked without one. */
export function yamlForImage(image, resolution) {
  return `image: ${image}\nresolution: ${resolution}\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n`;
}

/**
 * Groups picked files into maps. `files`: [{name, bytes}] (bytes an
 * ArrayBuffer or Uint8Array); `imageOf(name, yamlText)` returns a YAML's
 * `image` field or throws a message naming the field; `resolution`: metres
 * per cell for lone images (a string as typed). Returns
 * `{maps: [{name, yaml, imageName, image, assumed}], errors: [text]}`,
 * `assumed` the resolution a lone image is read at (absent for a YAML's).
 */
export function groupFiles(files, imageOf, resolution) {
  const images = new Map();
  const yamls = [];
  const errors = [];
  for (const f of files) {
    if (YAML.test(f.name)) yamls.push(f);
    else if (IMAGE.test(f.name)) images.set(f.name, f);
    else errors.push(`${f.name}: not a map file (expected a .yaml with its .pgm or .png image)`);
  }
  const used = new Set();
  const maps = [];
  for (const f of yamls) {
    const yaml = new TextDecoder().decode(f.bytes);
    let image;
    try {
      image = imageOf(f.name, yaml);
    } catch (e) {
      errors.push(e instanceof Error ? e.message : String(e));
      // Its image (by the usual same stem) is not a map of its own.
      const stem = f.name.replace(YAML, '');
      for (const n of images.keys()) if (n.replace(IMAGE, '') === stem) used.add(n);
      continue;
    }
    const picked = images.get(baseName(image));
    if (!picked) {
      errors.push(`${f.name}: image: '${image}' is not among the picked files; pick it together with the YAML`);
      continue;
    }
    used.add(picked.name);
    maps.push({ name: f.name, yaml, imageName: picked.name, image: new Uint8Array(picked.bytes) });
  }
  for (const [name, f] of images) {
    if (used.has(name)) continue;
    const r = Number(resolution);
    if (!(Number.isFinite(r) && r > 0)) {
      errors.push(`${name}: resolution: no YAML names this image, and '${resolution}' is not a positive resolution to read it at`);
      continue;
    }
    maps.push({ name, yaml: yamlForImage(name, r), imageName: name, image: new Uint8Array(f.bytes), assumed: r });
  }
  return { maps, errors };
}
