// The user's hands on the view: drags and the wheel on the canvas, pinches
// on a touch screen, and the reset button. Which thing a drag turns is the
// user's choice under "drag rotates"; shift and alt reach the objects and the
// light without changing it.
import { canvas } from './layout.js';
import { state } from './page_state.js';
import { pinch, resetView, steer, touched, view, zoom } from './view.js';

const $ = (id) => document.getElementById(id);

// The pointers down on the canvas (id → {x, y}): one drags, two pinch.
const pointers = new Map();
let drag = null;    // {x, y} of the dragging pointer
let spread = 0;     // two pointers: their distance at the last move

function dragTarget(e) {
  const chosen = (document.querySelector('#drag-target input:checked') || {}).value || 'camera';
  if (e.altKey) return 'light';
  if (e.shiftKey) return chosen.startsWith('object:') ? chosen : 'object:0';
  return chosen;
}

function distance() {
  const [a, b] = [...pointers.values()];
  return Math.hypot(a.x - b.x, a.y - b.y);
}

canvas.addEventListener('pointerdown', (e) => {
  pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
  canvas.setPointerCapture(e.pointerId);
  e.preventDefault();
  if (pointers.size === 2) {
    // A second finger: a pinch, not a drag (the first finger's drag ends).
    drag = null;
    spread = distance();
    canvas.classList.remove('dragging');
  } else if (pointers.size === 1) {
    drag = { x: e.clientX, y: e.clientY };
    canvas.classList.add('dragging');
  }
});

canvas.addEventListener('pointermove', (e) => {
  if (!pointers.has(e.pointerId)) return;
  pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
  if (pointers.size === 2) {
    const now = distance();
    if (spread > 0 && now > 0) pinch(spread, now);
    spread = now;
    state.pinches++;
    return;
  }
  if (!drag) return;
  const dx = e.clientX - drag.x;
  const dy = e.clientY - drag.y;
  drag = { x: e.clientX, y: e.clientY };
  steer(dragTarget(e), dx, dy);
});

const endPointer = (e) => {
  if (!pointers.delete(e.pointerId)) return;
  if (canvas.hasPointerCapture(e.pointerId)) canvas.releasePointerCapture(e.pointerId);
  spread = 0;
  // The finger left after a pinch drags from where it is, without a jump.
  const rest = [...pointers.values()];
  drag = rest.length === 1 ? { ...rest[0] } : null;
  canvas.classList.toggle('dragging', drag !== null);
};
canvas.addEventListener('pointerup', endPointer);
canvas.addEventListener('pointercancel', endPointer);
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  zoom(e.deltaY);
}, { passive: false });

$('reset-view').addEventListener('click', () => {
  if (!state.sceneInfo) return;
  resetView();
  touched.camera = true;  // say it: the server's camera may be a dragged one
  touched.light = true;
  view.poseDirty = true;
});
