// The status line under the toolbar, and the page's rule for errors: every
// handler that calls into wasm runs inside a guard, which shows what went
// wrong there. The page never throws an uncaught exception at the user.

const line = () => document.getElementById('status');

/** Shows `text` in the status line; `kind` is info, ok, warn or error. */
export function setStatus(text, kind = 'info') {
  const s = line();
  s.textContent = text;
  s.className = `status ${kind}`;
  s.title = text;
}

/** What the status line says now. */
export function statusText() {
  return line().textContent;
}

/** An error's message (the binding's errors are `Error`s naming the problem). */
export function message(e) {
  if (e instanceof Error) return e.message;
  return String(e);
}

/**
 * A guard: `guard(fn)` wraps a handler so that anything it throws lands in
 * the status line, after `recover()` has put the page in a safe state.
 */
export function makeGuard(recover) {
  return (fn) => (...args) => {
    try {
      return fn(...args);
    } catch (e) {
      recover();
      setStatus(message(e), 'error');
      return undefined;
    }
  };
}

/** Reports errors nothing caught (there should be none) in the status line. */
export function reportUncaught() {
  window.addEventListener('error', (e) => {
    if (/ResizeObserver loop/.test(e.message)) return; // benign, and not ours to report
    setStatus(`Unexpected error: ${e.message}`, 'error');
  });
  window.addEventListener('unhandledrejection', (e) => setStatus(`Unexpected error: ${message(e.reason)}`, 'error'));
}
