// The page's one-key shortcuts (f: full window, h: the HUD's details, s: save
// the frame), taken wherever focus is except where a key types: a text-like
// <input>, a <select> (its letters pick an option), a <textarea>, editable
// content. A click on a checkbox, radio, button or slider leaves focus on it,
// and the keys must still work there. Pure but for `onShortcut`, so that node
// tests `takesTyping` (tests/e2e/web_client_test.mjs).

// The <input> types whose letters are typed into them; the others (checkbox,
// radio, range, button, color, file…) ignore letter keys.
const TYPED_INPUTS = new Set(['text', 'search', 'url', 'tel', 'email', 'password', 'number',
                              'date', 'datetime-local', 'month', 'time', 'week']);

// el: the keydown's target (an element, or the document).
export function takesTyping(el) {
  if (!el || typeof el.tagName !== 'string') return false;
  const tag = el.tagName.toUpperCase();
  if (tag === 'TEXTAREA' || tag === 'SELECT') return true;
  if (tag === 'INPUT') return TYPED_INPUTS.has(String(el.type || 'text').toLowerCase());
  return el.isContentEditable === true;
}

// action(event) on `key` alone (no Ctrl, Alt or Meta), unless focus types.
export function onShortcut(key, action) {
  document.addEventListener('keydown', (e) => {
    if (e.key !== key || e.ctrlKey || e.metaKey || e.altKey || takesTyping(e.target)) return;
    action(e);
  });
}
