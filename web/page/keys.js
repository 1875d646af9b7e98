// The keyboard: every shortcut the help overlay (`?`) lists. Keys typed into
// a field stay there (Esc leaves the field); focused buttons and links keep
// their own Space and Enter. A slider (the speed) keeps its arrow keys but
// not Space, which a slider has no use for: after moving the speed, Space
// still runs and pauses. Space is both run/pause (on release) and, held
// down, pan-by-dragging (web/page/pointer.js), so the run toggles only if
// no drag used it. While the summary is open it has the keyboard: Esc closes
// it and Tab stays inside it.

/** A slider: it keeps every key but Space. */
const isSlider = (t) => t?.tagName === 'INPUT' && t.type === 'range';

function typingTarget(t) {
  if (!t || !t.tagName) return false;
  if (t.tagName === 'TEXTAREA' || t.tagName === 'SELECT') return true;
  if (t.tagName === 'INPUT') return !['checkbox', 'radio', 'button', 'file', 'range'].includes(t.type);
  return t.isContentEditable;
}

export class Keys {
  /**
   * @param {object} page  the collaborators: {guard, store, runner, editor, view, pointer,
   *                       toolbar, summary, merge, guide, refreshPanels, refreshControls}
   */
  constructor(page) {
    this.page = page;
  }

  listen() {
    document.addEventListener('keydown', this.page.guard((e) => this.down(e)));
    document.addEventListener('keyup', this.page.guard((e) => this.up(e)));
  }

  down(e) {
    const { store, runner, editor, summary } = this.page;
    if (!store.lab) return;
    const t = e.target;
    if (summary.isOpen) {
      summary.key(e);
      return;
    }
    const slider = isSlider(t);
    if (typingTarget(t) || (slider && e.key !== ' ')) {
      if (e.key === 'Escape') t.blur();
      return;
    }
    // Let focused buttons and links keep their own Space/Enter.
    if (!slider && (e.key === ' ' || e.key === 'Enter') && t.closest?.('button, a, label.button, input')) return;
    if ((e.ctrlKey || e.metaKey) && (e.key === 'z' || e.key === 'Z')) {
      e.preventDefault();
      editor.undo();
      return;
    }
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    const big = e.shiftKey ? 1 : 0.1;
    const editing = () => store.selection && runner.editable();
    switch (e.key) {
      case ' ':
        e.preventDefault();
        if (!e.repeat) {
          this.page.pointer.spaceDown = true;
          this.page.pointer.spaceUsed = false;
        }
        break;
      case 's':
      case 'S':
        runner.step();
        break;
      case 'ArrowRight':
        e.preventDefault();
        if (editing()) editor.nudge(big, 0);
        else runner.step();
        break;
      case 'ArrowLeft':
      case 'ArrowUp':
      case 'ArrowDown':
        if (editing()) {
          e.preventDefault();
          editor.nudge(...{ ArrowLeft: [-big, 0], ArrowUp: [0, big], ArrowDown: [0, -big] }[e.key]);
        }
        break;
      case '[':
        editor.turnSelected(Math.PI / 12);
        break;
      case ']':
        editor.turnSelected(-Math.PI / 12);
        break;
      case 'r':
      case 'R':
        runner.reset();
        break;
      case 'f':
      case 'F':
        this.page.view.fit();
        break;
      case 'w':
      case 'W':
        editor.setTool('wall');
        break;
      case 'v':
      case 'V':
        editor.setTool('select');
        break;
      case 'Delete':
      case 'Backspace':
        e.preventDefault();
        editor.deleteSelection();
        break;
      case 'Escape':
        this.escape();
        break;
      case '?':
        this.page.toolbar.toggleHelp();
        break;
      case 'g':
      case 'G':
        this.page.guide.toggle();
        break;
      default:
        break;
    }
  }

  /** Esc: the innermost thing open or going on stops. */
  escape() {
    const { store, editor, toolbar, merge, guide, pointer } = this.page;
    if (!pointer.cancel()) {
      if (toolbar.helpOpen) toolbar.toggleHelp(false);
      else if (merge.pairOpen) merge.closePair();
      else if (guide.isOpen) guide.close();
      else if (editor.tool === 'wall') editor.setTool('select');
      else if (store.selection) {
        store.select(null);
        this.page.refreshPanels();
        this.page.refreshControls();
      }
    }
    this.page.view.invalidate();
  }

  up(e) {
    const { pointer, runner } = this.page;
    if (e.key !== ' ' || !pointer.spaceDown) return;
    pointer.spaceDown = false;
    if (typingTarget(e.target)) return;
    if (!pointer.spaceUsed) {
      if (runner.running) runner.pause();
      else runner.run();
    }
  }
}
