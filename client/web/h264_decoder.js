// H.264 frames (ENCODING_H264) in the browser: a WebCodecs VideoDecoder fed
// one Annex-B access unit per Frame message, each picture drawn and closed at
// once. The server's stream (server/net/include/haarcast/net/h264_encoder.h):
// SPS and PPS before every IDR, no B-frames, BT.709 limited range stated in
// the SPS, so the decoder needs no out-of-band description (no `description`
// in the config: Annex-B) and every keyframe is a place to start.
//
// Where WebCodecs or an H.264 decoder is missing (no secure context, a
// browser built without the codec), h264Support() says so and names the
// encoding to ask for instead: the page then sends its Hello with JPEG.
//
// The pure parts (NAL scanning, the codec string) run in node as well.

export const H264_FALLBACK_ENCODING = 'jpeg';

// A codec string every H.264 decoder that WebCodecs offers knows:
// Constrained Baseline, level 3.0. Used to probe before any stream arrives.
export const H264_PROBE_CODEC = 'avc1.42E01E';

const NAL_SLICE = 1;
const NAL_IDR = 5;
const NAL_SPS = 7;

// The NAL units of an Annex-B buffer: {type, start, end}, `start` at the NAL
// header byte (after the 00 00 01 or 00 00 00 01 start code).
export function nalUnits(bytes) {
  const units = [];
  let start = -1;
  for (let i = 0; i + 2 < bytes.length; i++) {
    if (bytes[i] === 0 && bytes[i + 1] === 0 && bytes[i + 2] === 1) {
      if (start >= 0) units.push({ type: bytes[start] & 0x1f, start, end: i > 0 && bytes[i - 1] === 0 ? i - 1 : i });
      start = i + 3;
      i += 2;
    }
  }
  if (start >= 0 && start < bytes.length) units.push({ type: bytes[start] & 0x1f, start, end: bytes.length });
  return units;
}

// An access unit is a key chunk for WebCodecs when it holds an IDR slice.
export function isKeyframe(bytes) {
  return nalUnits(bytes).some((u) => u.type === NAL_IDR);
}

// RFC 6381's avc1.PPCCLL from the SPS: profile_idc, the constraint flags
// byte and level_idc, the three bytes after the NAL header (H.264 §7.3.2.1).
// null when the access unit has no SPS.
export function codecFromSps(bytes) {
  const sps = nalUnits(bytes).find((u) => u.type === NAL_SPS);
  if (!sps || sps.end - sps.start < 4) return null;
  const hex = (b) => b.toString(16).toUpperCase().padStart(2, '0');
  return `avc1.${hex(bytes[sps.start + 1])}${hex(bytes[sps.start + 2])}${hex(bytes[sps.start + 3])}`;
}

// Whether this browser decodes H.264 through WebCodecs:
// {supported: true, codec} or {supported: false, reason, fallback}.
export async function h264Support(codec = H264_PROBE_CODEC) {
  const unsupported = (reason) => ({ supported: false, reason, fallback: H264_FALLBACK_ENCODING });
  if (typeof globalThis.VideoDecoder === 'undefined') {
    return unsupported(globalThis.isSecureContext === false
      ? 'WebCodecs needs a secure context (https:// or localhost)'
      : 'this browser has no WebCodecs VideoDecoder');
  }
  try {
    const result = await VideoDecoder.isConfigSupported({ codec, optimizeForLatency: true });
    return result.supported ? { supported: true, codec } : unsupported(`VideoDecoder cannot decode ${codec}`);
  } catch (e) {
    return unsupported(`VideoDecoder.isConfigSupported(${codec}) failed: ${e.message}`);
  }
}

// One session's decoder. `draw(frame)` gets each VideoFrame and must not
// keep it: the frame is closed when draw returns (a VideoFrame holds decoder
// memory until closed). `onError(message)` hears of a decoder failure; the
// next keyframe starts over, so the caller asks for one (PoseUpdate.keyframe).
export class H264Decoder {
  constructor({ draw, onError = () => {} }) {
    this.draw = draw;
    this.onError = onError;
    this.decoder = null;
    this.codec = null;
    this.size = null;
    this.decoded = 0;   // pictures drawn
    this.skipped = 0;   // access units dropped while waiting for a keyframe
  }

  // Queues one access unit (a Uint8Array) for decoding; pictures come back
  // through `draw`, in order. Returns false when the unit was dropped
  // because the decoder waits for a keyframe: ask the server for one.
  decode(bytes, width, height, timestampUs) {
    const key = isKeyframe(bytes);
    if (key) {
      // A new stream (first frame, resize, new settings) starts at a keyframe
      // with its SPS: reconfigure when the codec string or the size changed.
      const codec = codecFromSps(bytes);
      const size = `${width}x${height}`;
      if (!codec) {
        this.fail('an H.264 keyframe without an SPS: the stream cannot be configured');
        return false;
      }
      if (!this.decoder || this.decoder.state === 'closed' || codec !== this.codec || size !== this.size) {
        this.reset();
        this.decoder = new VideoDecoder({
          output: (frame) => this.output(frame),
          error: (e) => this.fail(`VideoDecoder: ${e.message}`),
        });
        this.decoder.configure({ codec, codedWidth: width, codedHeight: height, optimizeForLatency: true });
        this.codec = codec;
        this.size = size;
      }
    } else if (!this.decoder || this.decoder.state !== 'configured') {
      this.skipped++;
      return false;
    }
    this.decoder.decode(new EncodedVideoChunk({ type: key ? 'key' : 'delta', timestamp: timestampUs, data: bytes }));
    return true;
  }

  output(frame) {
    try {
      this.draw(frame);
      this.decoded++;
    } finally {
      frame.close();
    }
  }

  fail(message) {
    this.reset();
    this.onError(message);
  }

  // Waits for every queued unit to be drawn (for tests and before a resize).
  async flush() {
    if (this.decoder && this.decoder.state === 'configured') await this.decoder.flush();
  }

  reset() {
    if (this.decoder && this.decoder.state !== 'closed') this.decoder.close();
    this.decoder = null;
    this.codec = null;
    this.size = null;
  }

  close() {
    this.reset();
  }
}

// Exported for the tests: which NAL unit types mean what.
export const NAL_TYPES = { slice: NAL_SLICE, idr: NAL_IDR, sps: NAL_SPS };
