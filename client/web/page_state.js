// The state the page's modules share, each piece here and nowhere else: what
// the page knows of its session (state), what the address asked for (page)
// and what the user chose on the page (choices).
import { ExposureMode, toneValue } from './schema.js';

// The event on window each move of the view (drag, wheel, pinch) sends (view.js → resolution.js).
export const MOVE_EVENT = 'haarcast-move';

// Exposed for the end-to-end test and for curious users (devtools).
export const state = {
  welcome: null,
  sceneInfo: null,
  framesReceived: 0,
  framesShown: 0,
  lastShownSequence: 0,
  lastFrame: null,     // {sequence, poseSequence, width, height, encoding, method, bytes, exposureStops, exposureMode,
                       //  serverMs, latencyMs}
  posesSent: 0,
  errors: [],          // {code, message, fatal}; page-parameter errors have code "PAGE_PARAMETER"
  closed: null,        // {code, reason} of the last socket close
  hudUpdates: 0,
  connection: 'loading',  // loading | connecting | waiting-welcome | ready | reconnect-wait | stopped
  connections: 0,      // sockets opened (attempts)
  welcomes: 0,
  reconnectAttempt: 0,
  reconnectInS: null,  // seconds to the next attempt while waiting
  scene: { name: '', firstPose: 0 },  // frames answering poses older than firstPose show the previous scene
  h264: null,          // h264Support()'s answer, once H.264 was chosen
  helloEncoding: '',   // what the last Hello asked for (jpeg when H.264 falls back)
  keyframeRequests: 0, // poses sent with PoseUpdate.keyframe
  requestedSize: null, // {width, height} last asked for (Hello or RenderSettings)
  resizes: 0,          // sizes asked for after the Hello (a resized view, auto's steps)
  autoSteps: 0,        // sizes auto's rule changed
  sizeFallback: false, // the server refused the size that fits the view: the Hello asks for its default
  build: null,         // the build on the page: {what, stage, percent, fraction, detail}; null: none
  buildProgressMessages: 0,
  buildsEnded: 0,      // builds shown and over
  progress: null,      // the waiting overlay: {title, stage, fraction (null: indeterminate), detail, shown}
  progressUpdates: 0,  // times it was redrawn
  addressWrites: 0,    // times the address was brought up to date with the view (share_url.js)
  frameProgress: null, // the last FrameProgress shown: {stage, fraction, elapsedSeconds}
  frameProgressMessages: 0,
  hudFolded: false,    // the HUD shows its first line only
  pinches: 0,          // pointer moves with two fingers down (pinch zoom)
  sceneReady: true,    // false while a new scene's renderer is prepared: its objects are not listed yet
};
window.haarcast = state;

// parsePageParameters(location.search), set once at the start.
export let page = null;
export function setPage(p) {
  page = p;
}

// What the user asked for: the next Hello, after a reconnect, says it again.
export const choices = { scene: '', method: '', level: 0, k: 0, exposure: { auto: true, stops: 0 }, tone: '',
                         resolution: 'auto' };

// The exposure the user chose, as RenderSettings fields.
export function exposureSettings() {
  return choices.exposure.auto
    ? { exposureMode: ExposureMode.values.EXPOSURE_MODE_AUTO }
    : { exposureMode: ExposureMode.values.EXPOSURE_MODE_FIXED, exposureStops: choices.exposure.stops };
}

// The tone curve the user chose, as a RenderSettings field ('' → unspecified: the server's).
export function toneSettings() {
  return { toneCurve: toneValue(choices.tone) };
}
