// The server's frames onto the canvas, in whichever encoding the session
// has: JPEG and PNG through the browser's image decoder, raw RGBA as is, and
// H.264 through WebCodecs (h264_view.js). Only a frame newer than the one on
// the canvas is drawn, and each is counted for the HUD.
import { buildShown, endBuild } from './build_view.js';
import { endWaiting } from './frame_progress_view.js';
import { H264View } from './h264_view.js';
import { frameWindow } from './hud.js';
import { ctx, setFrameSize } from './layout.js';
import { state } from './page_state.js';
import { frameTiming } from './resolution.js';
import { sceneShown } from './scene_panel.js';
import { Encoding, ExposureMode, methodName, toneName } from './schema.js';
import { generation } from './session.js';
import { setEffective, showFrameExposure } from './settings_panel.js';
import { showBanner } from './status.js';
import { requestKeyframe, view } from './view.js';

// Frames are decoded asynchronously and may finish out of order; only a
// frame newer than the one on the canvas is drawn.
export async function onFrame(f, gen) {
  state.framesReceived++;
  const received = performance.now();
  const bytes = f.data.byteLength;
  // A frame that answers a change (settings, scene, size) rather than a
  // pose, or that ends a build, has no pose-to-frame latency: its pose was
  // sent before what it waited for.
  const answersChange = f.poseSequence < view.changeFromPose;
  const endsBuild = buildShown() && !answersChange;
  // The first frame (pose 0) waited for the renderer to be prepared: not a frame time.
  const serverMs = f.serverMs > 0 && f.poseSequence > 0 ? f.serverMs : NaN;
  const latencyMs = f.clientTimeMs > 0 && !answersChange && !endsBuild ? received - f.clientTimeMs : NaN;
  frameWindow.add(received, { bytes, latencyMs, serverMs, stages: f.timings.map((t) => ({ name: t.name, ms: t.ms })) });
  frameTiming(f.width, f.height, serverMs);
  if (f.poseSequence < state.scene.firstPose) return;  // the previous scene, rendered before the switch
  if (f.settings) setEffective(f.settings);
  const method = f.settings && f.settings.method ? methodName(f.settings.method) : null;
  const exposureMode = f.settings && f.settings.exposureMode === ExposureMode.values.EXPOSURE_MODE_FIXED ? 'fixed' : 'auto';
  const tone = f.settings && f.settings.toneCurve ? toneName(f.settings.toneCurve) : null;
  const fresh = () => gen === generation && f.sequence > state.lastShownSequence;
  const shown = () => {
    state.lastShownSequence = f.sequence;
    state.framesShown++;
    // serverMs, latencyMs: what the HUD counted of this frame (NaN: not counted).
    state.lastFrame = { sequence: f.sequence, poseSequence: f.poseSequence, width: f.width, height: f.height,
                        encoding: f.encoding, method, bytes, exposureStops: f.exposureStops, exposureMode,
                        tone, serverMs, latencyMs, directions: f.directionsPerSample,
                        smoothShare: f.smoothShare };
    showFrameExposure(f.exposureStops, exposureMode);
    // The first frame of a change ends its build on the page, and the first
    // of a new scene lists its objects.
    if (f.poseSequence >= view.changeFromPose) endBuild();
    endWaiting();
    sceneShown();
  };
  if (f.encoding === Encoding.values.ENCODING_RAW_RGBA8) {
    if (bytes !== f.width * f.height * 4) throw new Error(`raw frame of ${bytes} bytes for ${f.width}×${f.height}`);
    // A copy: ImageData needs its own buffer, f.data views the message.
    const image = new ImageData(new Uint8ClampedArray(f.data), f.width, f.height);
    if (!fresh()) return;
    setFrameSize(f.width, f.height);
    ctx.putImageData(image, 0, 0);
    shown();
  } else if (f.encoding === Encoding.values.ENCODING_JPEG || f.encoding === Encoding.values.ENCODING_PNG) {
    const type = f.encoding === Encoding.values.ENCODING_JPEG ? 'image/jpeg' : 'image/png';
    const bitmap = await createImageBitmap(new Blob([f.data], { type }));
    if (fresh()) {
      setFrameSize(f.width, f.height);
      ctx.drawImage(bitmap, 0, 0);
      shown();
    }
    bitmap.close();
  } else if (f.encoding === Encoding.values.ENCODING_H264 && h264View) {
    // Decoded in order by the session's decoder; drawn when its picture comes out.
    h264View.frame(f, () => { if (gen === generation) shown(); });
  } else {
    showBanner(`cannot show ${Encoding.valuesById[f.encoding]} frames here; use ?encoding=jpeg, png, raw or h264`);
  }
}

let h264View = null;  // one per session: the decoder keeps the stream's reference pictures

export function startH264View(on) {
  if (h264View) h264View.close();
  h264View = on ? new H264View({
    draw: (frame, done) => {
      setFrameSize(frame.displayWidth, frame.displayHeight);
      ctx.drawImage(frame, 0, 0);
      done();
    },
    requestKeyframe,
  }) : null;
  state.h264View = h264View;
}
