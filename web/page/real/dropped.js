// The files of a drop or a pick, with their paths, for "Your log"
// (log-panel.js): a rosbag2 bag is a folder (its metadata.yaml and data
// files), and a folder dropped as a folder arrives as a directory entry
// (the File and Directory Entries API: `DataTransferItem.webkitGetAsEntry`)
// whose files are read here, each with its path in the folder, so the log
// worker (bag-read.js) can tell which files belong together. Plain files
// keep their name as their path (or the path a folder picker gives them).

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
