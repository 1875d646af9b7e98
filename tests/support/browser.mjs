// What the browser tests share: a static server of the repository root on a
// free port of 127.0.0.1, headless /usr/bin/chromium driven by
// playwright-core, and pages that record console errors.
//
// A test file calls `useBrowser()` once at its top level; it registers the
// before/after hooks and returns an object whose `browser` and `baseUrl`
// are set once the hooks have run. Needs the wasm build in web/pkg
// (`./build.sh build`).
import { before, after } from 'node:test';
import http from 'node:http';
import { readFile, mkdir, access } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
export const ARTIFACTS = path.join(ROOT, 'test-artifacts');

export const CHROMIUM_FLAGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
];
const MIME = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json',
  '.wasm': 'application/wasm',
  '.png': 'image/png',
  '.svg': 'image/svg+xml',
  '.ts': 'text/plain; charset=utf-8',
};

/** A static file server for the repository root; resolves to {server, url}. */
export function serveRoot() {
  const server = http.createServer(async (req, res) => {
    try {
      const url = new URL(req.url, 'http://localhost');
      let rel = decodeURIComponent(url.pathname);
      if (rel.endsWith('/')) rel += 'index.html';
      const file = path.resolve(ROOT, `.${rel}`);
      if (!file.startsWith(ROOT + path.sep)) {
        res.writeHead(403).end();
        return;
      }
      const body = await readFile(file);
      res.writeHead(200, {
        'Content-Type': MIME[path.extname(file)] ?? 'application/octet-stream',
        'Cache-Control': 'no-store',
      });
      res.end(body);
    } catch {
      res.writeHead(404, { 'Content-Type': 'text/plain' }).end('not found');
    }
  });
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(0, '127.0.0.1', () => resolve({ server, url: `http://127.0.0.1:${server.address().port}/` }));
  });
}

/** Registers the hooks that start the server and the browser (and stop them). */
export function useBrowser() {
  const env = { browser: null, baseUrl: '', server: null };
  before(async () => {
    await access(path.join(ROOT, 'web/pkg/slamlab_bg.wasm')).catch(() => {
      throw new Error('web/pkg is missing: run ./build.sh build first');
    });
    await mkdir(ARTIFACTS, { recursive: true });
    ({ server: env.server, url: env.baseUrl } = await serveRoot());
    env.browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: CHROMIUM_FLAGS });
  });
  after(async () => {
    await env.browser?.close();
    await new Promise((resolve) => (env.server ? env.server.close(resolve) : resolve()));
  });
  return env;
}

/** A fresh context and page (no autosave) that record console errors and page errors. */
export async function newPage(browser, viewport = { width: 1280, height: 720 }) {
  const context = await browser.newContext({ viewport });
  const page = await context.newPage();
  const problems = [];
  page.on('console', (m) => {
    if (m.type() === 'error') problems.push(`console error: ${m.text()} (${m.location().url})`);
  });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  return { context, page, problems };
}

/** Waits until the page has loaded its wasm and drawn. */
export async function waitReady(page) {
  await page.waitForFunction(() => window.slamlab?.ready === true && document.body.dataset.ready === 'true', null, {
    timeout: 15000,
  });
}
