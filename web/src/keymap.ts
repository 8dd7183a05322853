// The key map, as the page's help (?) shows it and docs/editor.md lists it (the end-to-end test
// compares the two and presses every row). Blender's keys where the editor has the same tool;
// painting is Blender's Sculpt and Weight Paint modes, hiding is Sculpt's box hide.
export interface KeyRow {
  id: string; // what the end-to-end test calls the row
  keys: string;
  does: string;
}

export const KEYMAP: KeyRow[] = [
  { id: 'tools', keys: '1, 2, 3, 4, 5', does: 'tools Handle, Fixed, Erase, Move, Pin' },
  { id: 'tab', keys: 'Tab', does: 'Move, and back to the tool that paints' },
  { id: 'new-group', keys: 'Shift + N', does: 'a new handle group' },
  { id: 'paint', keys: 'left drag', does: 'paint (Handle, Fixed, Erase, Pin) or drag a handle (Move)' },
  { id: 'modal', keys: 'G, R, S', does: 'move, rotate, scale the active group (then X, Y, Z: an axis; digits: a value; Enter or a click: confirm; Esc or a right-click: cancel)' },
  { id: 'cursor', keys: 'Shift + right-click', does: 'place the 3D cursor on the surface' },
  { id: 'all', keys: 'A / Alt + A', does: 'every vertex gets the tool\'s label / the tool\'s label is cleared (pinned regions stay)' },
  { id: 'linked', keys: 'L', does: 'select the piece under the pointer' },
  { id: 'box', keys: 'B, then a left drag / Ctrl + right drag', does: 'box / lasso select (visible vertices; with X-ray, Alt + Z, through the surface)' },
  { id: 'invert', keys: 'Ctrl + I', does: 'invert (the tool\'s label and the free vertices swap)' },
  { id: 'grow', keys: 'Ctrl + numpad + / −', does: 'grow / shrink by a ring (also Ctrl + = / Ctrl + −)' },
  { id: 'hide', keys: 'H, then a left drag / Shift + H / Alt + H', does: 'hide the vertices in a rectangle, to paint behind them (visible ones; with X-ray all) / hide every unlabelled vertex / show everything again; any other key or tool disarms H' },
  { id: 'orbit', keys: 'middle drag / Shift + middle / Ctrl + middle', does: 'orbit / pan / zoom (Alt + left drag as the middle button with "Alt emulates middle")' },
  { id: 'wheel', keys: 'wheel', does: 'zoom towards the pointer; while moving with a region of influence: widen or narrow it' },
  { id: 'views', keys: 'numpad 1, 3, 7 (Ctrl: opposite) / 9 / 5', does: 'look from the front, right, top (back, left, bottom) / from the other side / perspective or orthographic' },
  { id: 'turn', keys: 'numpad 4, 6 / 8, 2', does: 'orbit left, right / up, down by 15°' },
  { id: 'frame', keys: 'F or numpad . / Home', does: 'frame the active group / the whole mesh' },
  { id: 'panel', keys: 'N', does: 'show or hide the panel' },
  { id: 'help', keys: '?', does: 'show or hide this table' },
  { id: 'cancel', keys: 'Esc', does: 'cancel a stroke, a drag, a box or a transform' },
  { id: 'undo', keys: 'Ctrl + Z / Ctrl + Shift + Z or Ctrl + Y', does: 'undo / redo' },
];

// The table in #keymap-table.
export function renderKeymap(table: HTMLTableElement): void {
  table.replaceChildren(...KEYMAP.map((row) => {
    const tr = document.createElement('tr');
    tr.dataset.key = row.id;
    for (const text of [row.keys, row.does]) tr.appendChild(Object.assign(document.createElement('td'), { textContent: text }));
    return tr;
  }));
}
