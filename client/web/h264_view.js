// H.264 frames on the page: which encoding the Hello asks for when the page
// wants H.264, and one session's view of the stream — its H264Decoder
// (h264_decoder.js), each Frame's fields kept until its picture comes out,
// and the keyframe requests (PoseUpdate.keyframe) when the decoder lost the
// stream. Pure but for the decoder, so node tests it with a stand-in
// VideoDecoder (tests/e2e/web_client_test.mjs).
import { H264Decoder, H264_FALLBACK_ENCODING, isKeyframe } from './h264_decoder.js';

// The encoding for the Hello: the page's choice, except H.264 where this
// browser cannot decode it (`support`, from h264Support()): then the
// fallback (JPEG), with the reason to show on the page.
export function helloEncoding(requested, support) {
  if (requested !== 'h264' || !support || support.supported) return { encoding: requested, note: '' };
  const encoding = support.fallback || H264_FALLBACK_ENCODING;
  return {
    encoding,
    note: `H.264 is not available in this browser (${support.reason}); showing ${encoding.toUpperCase()} frames instead.`,
  };
}

export class H264View {
  // draw(videoFrame, done): paint the picture, then call done() (the frame
  // is closed when draw returns). requestKeyframe(): send a pose with only
  // `sequence` and `keyframe`; returns that sequence, or 0 if not sent.
  constructor({ draw, requestKeyframe, Decoder = H264Decoder }) {
    this.requestKeyframe = requestKeyframe;
    this.pending = new Map();  // chunk timestamp (the Frame's sequence) → done callback
    this.askedAt = 0;          // the pose that asked for a keyframe; 0: none on its way
    this.lastPose = 0;         // the pose the latest frame answered
    this.requests = 0;         // keyframe poses sent
    this.undecoded = 0;        // frames dropped or failed, waiting for a keyframe
    this.errors = [];          // the decoder's error messages
    this.decoder = new Decoder({
      draw: (frame) => {
        const done = this.pending.get(frame.timestamp);
        // Pictures come out in order: whatever is older never will.
        for (const t of this.pending.keys()) if (t <= frame.timestamp) this.pending.delete(t);
        draw(frame, done || (() => {}));
      },
      onError: (message) => {
        this.errors.push(message);
        this.pending.clear();
        this.undecoded++;
        this.askKeyframe(this.lastPose);
      },
    });
  }

  // One Frame message (protobufjs object: sequence, poseSequence, width,
  // height, data). Returns false when it could not be decoded.
  frame(f, done) {
    const sequence = Number(f.sequence);
    const pose = Number(f.poseSequence);
    this.lastPose = pose;
    if (isKeyframe(f.data)) this.askedAt = 0;
    this.pending.set(sequence, done);
    if (!this.decoder.decode(f.data, f.width, f.height, sequence)) {
      this.pending.delete(sequence);
      this.undecoded++;
      this.askKeyframe(pose);
      return false;
    }
    return true;
  }

  // Asks once per loss: frames answering poses sent before the asking one
  // were encoded before the request and cannot be keyframes; a failure on a
  // later frame means the request was lost, so it asks again.
  askKeyframe(failingPose) {
    if (this.askedAt && failingPose < this.askedAt) return;
    const sequence = this.requestKeyframe();
    if (sequence) {
      this.askedAt = sequence;
      this.requests++;
    }
  }

  close() {
    this.decoder.close();
    this.pending.clear();
  }
}
