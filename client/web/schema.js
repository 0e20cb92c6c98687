// The wire contract, as the server states it: the schema is fetched from the
// server (GET /haarcast.proto), so the page keeps no copy that could drift.
// The message types and enums are set once by loadSchema(), before the page
// connects; the other modules read them from here.
/* global protobuf */

export let ClientMessage, ServerMessage, Encoding, RotationMethod, ErrorCode, ExposureMode, ToneCurve, LevelMode;
export let methodNames = [];  // "haar", …, "fused": the schema's RotationMethod values
export let toneNames = [];    // "reinhard", "aces", "agx": the schema's ToneCurve values

export async function loadSchema() {
  if (typeof protobuf === 'undefined') {
    throw new Error('protobufjs did not load (vendor/protobuf.min.js): run `npm ci` in client/web');
  }
  const root = await protobuf.load('/haarcast.proto');
  ClientMessage = root.lookupType('haarcast.v1.ClientMessage');
  ServerMessage = root.lookupType('haarcast.v1.ServerMessage');
  Encoding = root.lookupEnum('haarcast.v1.Encoding');
  RotationMethod = root.lookupEnum('haarcast.v1.RotationMethod');
  ErrorCode = root.lookupEnum('haarcast.v1.ErrorCode');
  ExposureMode = root.lookupEnum('haarcast.v1.ExposureMode');
  ToneCurve = root.lookupEnum('haarcast.v1.ToneCurve');
  LevelMode = root.lookupEnum('haarcast.v1.LevelMode');
  toneNames = Object.keys(ToneCurve.values)
    .filter((n) => n !== 'TONE_CURVE_UNSPECIFIED')
    .map((n) => n.replace('TONE_CURVE_', '').toLowerCase());
  methodNames = Object.keys(RotationMethod.values)
    .filter((n) => n !== 'ROTATION_METHOD_UNSPECIFIED')
    .map((n) => n.replace('ROTATION_METHOD_', '').toLowerCase());
}

const enumName = (e, value, prefix) => (e.valuesById[value] || '').replace(prefix, '').toLowerCase();
export const methodName = (value) => enumName(RotationMethod, value, 'ROTATION_METHOD_') || null;
export const methodValue = (name) => (name ? RotationMethod.values[`ROTATION_METHOD_${name.toUpperCase()}`] : 0);
export const toneName = (value) => enumName(ToneCurve, value, 'TONE_CURVE_') || null;
export const toneValue = (name) => (name ? ToneCurve.values[`TONE_CURVE_${name.toUpperCase()}`] : 0);
