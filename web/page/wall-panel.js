// The side panel of the selected wall: its ends and length, its texture
// name (walls with the same name look alike), a picture from a file as its
// texture, and Delete. Rebuilt only when the wall, the selection or the
// editing state changes.
import { fmt } from './dom.js';
import { message, setStatus } from './status.js';

export class WallPanel {
  /**
   * @param {import('./state.js').Store} store
   * @param {import('./editor.js').Editor} editor
   * @param {{guard: Function, editable: () => boolean}} hooks
   */
  constructor(store, editor, hooks) {
    this.store = store;
    this.editor = editor;
    this.hooks = hooks;
    this.panel = document.getElementById('selection-panel');
    this.body = document.getElementById('selection-body');
    this.title = document.getElementById('selection-title');
    this.key = '';
  }

  sync(editable) {
    const scenario = this.store.scenario;
    const sel = this.store.selection;
    if (!sel || sel.kind !== 'wall' || !scenario.walls[sel.index]) {
      this.panel.hidden = true;
      this.key = '';
      return;
    }
    const w = scenario.walls[sel.index];
    const key = JSON.stringify([sel, w, editable]);
    if (key === this.key) return;
    this.key = key;
    this.panel.hidden = false;
    this.title.textContent = `Selected wall ${sel.index + 1} of ${scenario.walls.length}`;
    const len = Math.hypot(w.to[0] - w.from[0], w.to[1] - w.from[1]);
    const textures = [...new Set(scenario.walls.map((x) => x.texture).filter(Boolean)), 'plain'];
    this.body.innerHTML = '';
    const coords = document.createElement('div');
    coords.className = 'field-row mono';
    coords.textContent = `(${fmt(w.from[0])}, ${fmt(w.from[1])}) → (${fmt(w.to[0])}, ${fmt(w.to[1])})  ${fmt(len)} m`;
    const row = document.createElement('div');
    row.className = 'field-row';
    row.innerHTML = `<label for="wall-texture">Texture</label>
    <input type="text" id="wall-texture" list="texture-names" placeholder="(own texture)" aria-label="Texture name of the selected wall">
    <datalist id="texture-names"></datalist>
    <button type="button" id="wall-delete" aria-label="Delete the selected wall">Delete wall</button>
    <label class="button" id="wall-picture-label" role="button" tabindex="0" aria-label="Put a PNG or JPEG picture on the selected wall">Picture…
      <input type="file" id="wall-picture" accept="image/png,image/jpeg" hidden></label>`;
    this.body.append(coords, row);
    const input = row.querySelector('#wall-texture');
    input.value = w.texture ?? '';
    input.disabled = !editable;
    row.querySelector('#wall-delete').disabled = !editable;
    const list = row.querySelector('#texture-names');
    for (const t of textures) {
      const o = document.createElement('option');
      o.value = t;
      list.append(o);
    }
    input.addEventListener('change', this.hooks.guard(() => this.setTexture(sel.index, input.value.trim())));
    row.querySelector('#wall-delete').addEventListener('click', () => this.editor.deleteSelection());
    const picture = row.querySelector('#wall-picture');
    picture.disabled = !editable;
    row.querySelector('#wall-picture-label').addEventListener('keydown', (e) => {
      if (e.key === 'Enter' || e.key === ' ') {
        e.preventDefault();
        picture.click();
      }
    });
    picture.addEventListener('change', async () => {
      const file = picture.files && picture.files[0];
      picture.value = '';
      if (file) await this.setPicture(sel.index, file);
    });
    const note = document.createElement('p');
    note.className = 'hint';
    note.textContent =
      'Walls with the same texture name look alike; "plain" is featureless. A picture lives in this browser session; ' +
      'the scenario keeps its name, and a wall whose picture is not loaded shows a generated texture.';
    this.body.append(note);
  }

  setTexture(index, t) {
    if (!this.hooks.editable()) return this.editor.notEditable();
    const next = this.store.draft();
    if (t) next.walls[index].texture = t;
    else delete next.walls[index].texture;
    this.store.commit(next);
    setStatus(t ? `Wall ${index + 1} now has texture “${t}”.` : `Wall ${index + 1} gets its own texture.`, 'info');
  }

  async setPicture(index, file) {
    if (!this.hooks.editable()) return this.editor.notEditable();
    try {
      const bytes = new Uint8Array(await file.arrayBuffer());
      const name = file.name.replace(/\.[^.]*$/, '').replace(/[^\w-]+/g, '_').slice(0, 48) || 'picture';
      this.store.lab.addImageTexture(name, bytes); // throws with a message for a bad file
      const next = this.store.draft();
      next.walls[index].texture = `image:${name}`;
      this.store.commit(next);
      setStatus(`Wall ${index + 1} now shows ${file.name} (texture “image:${name}”).`, 'ok');
    } catch (e) {
      setStatus(`Could not use ${file.name}: ${message(e)}. The wall is unchanged.`, 'error');
    }
  }
}
