// The user's hands on the view: drags and the wheel on the canvas, and the
// reset button. Which thing a drag turns is the user's choice under "drag
// rotates"; shift and alt reach the objects and the light without changing it.
import { canvas } from './layout.js';
import { state } from './page_state.js';
import { resetView, steer, touched, view, zoom } from './view.js';

const $ = (id) => document.getElementById(id);

let drag = null;

function dragTarget(e) {
  const chosen = (document.querySelector('#drag-target input:checked') || {}).value || 'camera';
  if (e.altKey) return 'light';
  if (e.shiftKey) return chosen.startsWith('object:') ? chosen : 'object:0';
  return chosen;
}

canvas.addEventListener('pointerdown', (e) => {
  drag = { x: e.clientX, y: e.clientY };
  canvas.setPointerCapture(e.pointerId);
  canvas.classList.add('dragging');
  e.preventDefault();
});

canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x;
  const dy = e.clientY - drag.y;
  drag = { x: e.clientX, y: e.clientY };
  steer(dragTarget(e), dx, dy);
});

const endDrag = (e) => {
  if (!drag) return;
  drag = null;
  canvas.classList.remove('dragging');
  if (canvas.hasPointerCapture(e.pointerId)) canvas.releasePointerCapture(e.pointerId);
};
canvas.addEventListener('pointerup', endDrag);
canvas.addEventListener('pointercancel', endDrag);
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
