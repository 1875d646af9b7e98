// Files dropped on the lab: a browser that gets a file dropped where the
// page does not take it leaves the page to show the file, and the lab's
// run with it. The lab takes every drop instead and hands the files to the
// view that reads them (web/page/real/dropped.js tells which by their
// names): saved maps open "Your maps", a log or a bag opens "Your log",
// each with those files, over the lab, which stays as it was. Anything
// else is refused in the status line. Drops on an open view are that
// view's own (its handler has taken them: `defaultPrevented`).
import { dropKind, droppedFiles } from './real/dropped.js';

const carriesFiles = (e) => [...(e.dataTransfer?.types ?? [])].includes('Files');

/**
 * Listens on `target` (the document) for dropped files.
 * @param {EventTarget} target
 * @param {{maps: {toggle: (open: boolean) => void, open: (files: File[]) => unknown},
 *          log: {toggle: (open: boolean) => void, open: (entries: Array<{file: File, path: string}>) => unknown},
 *          say: (text: string, kind: string) => void}} views
 */
export function takeDrops(target, views) {
  target.addEventListener('dragover', (e) => {
    if (!carriesFiles(e)) return;
    e.preventDefault();
    e.dataTransfer.dropEffect = 'copy';
  });
  target.addEventListener('drop', (e) => {
    if (e.defaultPrevented || !carriesFiles(e)) return;
    e.preventDefault();
    // read while the event is dispatched: the items are gone after it
    const entries = droppedFiles(e.dataTransfer);
    entries.then((list) => {
      const kind = dropKind(list);
      if (kind === 'log') {
        views.log.toggle(true);
        views.log.open(list);
      } else if (kind === 'maps') {
        views.maps.toggle(true);
        views.maps.open(list.map((x) => x.file));
      } else {
        const names = list.map((x) => x.path).join(', ') || 'nothing';
        views.say(`The lab cannot open ${names}: drop a saved map (its .yaml with the .pgm or .png image) ` +
          'or a robot\u2019s log (.log, .clf, .bag, .mcap, .db3) to open it in Your maps or Your log.', 'warn');
      }
    }, (err) => views.say(`Could not read the dropped files: ${err?.message ?? err}`, 'error'));
  });
}
