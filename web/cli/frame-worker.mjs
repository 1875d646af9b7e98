// A worker thread of `node web/cli.mjs run`: its own instance of the wasm
// build and its own Lab of the same scenario (never run), which renders the
// main lab's stored frames from their specs and describes them with SURF
// (crate/src/merge/described_ahead.rs), or only renders them for the main thread
// to describe. Messages in: {robot, index, spec, render}; out: {robot, index,
// packed} (features) or, with `render`, {robot, index, gray} (pixels), the
// buffer transferred; or {robot, index, error}.
import { parentPort, workerData } from 'node:worker_threads';
import { pathToFileURL } from 'node:url';

const wasm = await import(pathToFileURL(workerData.pkgJs).href);
wasm.initSync({ module: workerData.module });
const lab = new wasm.Lab(workerData.scenarioJson);

parentPort.on('message', ({ robot, index, spec, render }) => {
  try {
    if (render) {
      const gray = lab.renderFrameSpec(spec);
      parentPort.postMessage({ robot, index, gray }, [gray.buffer]);
      return;
    }
    const packed = lab.describeFrameSpec(spec, workerData.method);
    parentPort.postMessage({ robot, index, packed }, [packed.buffer]);
  } catch (e) {
    parentPort.postMessage({ robot, index, error: String(e?.message ?? e) });
  }
});
