// The files of a drop or a pick, with their paths, for "Your log"
// (log-panel.js): a rosbag2 bag is a folder (its metadata.yaml and data
// files), and a folder dropped as a folder arrives as a directory entry
// (the File and Directory Entries API: `DataTransferItem.webkitGetAsEntry`)
// whose files are read here, each with its path in the folder, so the log
// worker (bag-read.js) can tell which files belong together. Plain files
// keep their name as their path (or the path a folder picker gives them).
//
// Files dropped on the lab itself (web/page/lab-drop.js) go to the view
// that reads them, told by their names (`dropKind`): a log or a bag —
// CARMEN `.log`/`.clf` (gzipped too), ROS `.bag`, `.mcap`, rosbag2 `.db3`
// (`.db3.zstd`), or a rosbag2 folder's `metadata.yaml` beside its data —
// opens "Your log"; a saved map — map_server `.yaml`/`.yml` with its
// `.pgm` or `.png` image — opens "Your maps".

const LOG_NAME = /\.(log|clf|bag|mcap|db3|relations)(\.(gz|zstd))?$/i;
const MAP_NAME = /\.(ya?ml|pgm|png)$/i;

/**
 * Which view takes the dropped files (`[{file, path}]`): `'log'` when any is
 * a log or a bag (a rosbag2 folder's `metadata.yaml` goes with its bag),
 * `'maps'` when any is a saved map's YAML or image, `null` when neither.
 */
export function dropKind(entries) {
  const names = entries.map((e) => e.path || e.file?.name || '');
  if (names.some((n) => LOG_NAME.test(n))) return 'log';
  if (names.some((n) => MAP_NAME.test(n))) return 'maps';
  return null;
}

/** A picked file as the worker takes it: `{file, path}`. */
export function picked(file) {
  return { file, path: file.webkitRelativePath || file.name };
}

/** The entries of a directory reader, all batches. */
async function readAll(reader) {
  const out = [];
  for (;;) {
    const batch = await new Promise((resolve, reject) => reader.readEntries(resolve, reject));
    if (!batch.length) return out;
    out.push(...batch);
  }
}

/** Every file under a directory entry, `{file, path}` with the path from the dropped folder on. */
async function walk(entry) {
  if (entry.isFile) {
    const file = await new Promise((resolve, reject) => entry.file(resolve, reject));
    return [{ file, path: entry.fullPath.replace(/^\/+/, '') }];
  }
  const out = [];
  for (const e of await readAll(entry.createReader())) out.push(...(await walk(e)));
  return out;
}

/**
 * Takes what a drop event carries (call it in the handler: the items are
 * readable only while the event is dispatched) and returns a promise of
 * `[{file, path}]`: each dropped folder's files with their paths, each
 * dropped file as itself.
 */
export function droppedFiles(dataTransfer) {
  const items = [...(dataTransfer?.items ?? [])].filter((i) => i.kind === 'file');
  const entries = items.map((i) => i.webkitGetAsEntry?.() ?? null);
  if (!entries.some((e) => e?.isDirectory)) return Promise.resolve([...(dataTransfer?.files ?? [])].map(picked));
  const files = items.map((i) => i.getAsFile());
  return (async () => {
    const out = [];
    for (const [k, e] of entries.entries()) {
      if (e?.isDirectory) out.push(...(await walk(e)));
      else if (files[k]) out.push(picked(files[k]));
    }
    return out;
  })();
}
