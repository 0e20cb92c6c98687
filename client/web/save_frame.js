// Save the frame: a PNG of the canvas, which holds the stream's own pixels
// (the frame's size, not the window's), named after the scene, the size and
// the time, as a download (the button on the view, or s).
import { canvas } from './layout.js';
import { state } from './page_state.js';
import { onShortcut } from './shortcuts.js';

// "haarcast-<scene>-<W>x<H>-<YYYYMMDD-HHMMSS>.png", the scene's name cut to
// letters, digits, '-' and '_' so that it is a file name on every system.
export function frameFileName(scene, width, height, when) {
  const safe = String(scene || 'frame').replace(/[^A-Za-z0-9_-]+/g, '_').slice(0, 40) || 'frame';
  const two = (n) => String(n).padStart(2, '0');
  const stamp = `${when.getFullYear()}${two(when.getMonth() + 1)}${two(when.getDate())}-` +
                `${two(when.getHours())}${two(when.getMinutes())}${two(when.getSeconds())}`;
  return `haarcast-${safe}-${width}x${height}-${stamp}.png`;
}

function save() {
  if (!state.lastFrame) return;  // nothing drawn yet
  const name = frameFileName(state.scene && state.scene.name, canvas.width, canvas.height, new Date());
  canvas.toBlob((blob) => {
    if (!blob) return;
    const a = document.createElement('a');
    a.href = URL.createObjectURL(blob);
    a.download = name;
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 10000);
  }, 'image/png');
}

document.getElementById('save-frame').addEventListener('click', save);
onShortcut('s', save);
