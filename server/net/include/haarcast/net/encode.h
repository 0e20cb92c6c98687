// The server's frame encoding: which wire Encoding a session streams, and the
// renderer's output handed to the wire library's encoders (haarcast/wire:
// frame_codec.h for JPEG, PNG and RAW from the tonemapped RGBA8, exr_codec.h
// for EXR from the linear image). H.264 is stateful (each frame depends on
// the ones before), so a session's own H264Encoder (h264_encoder.h) encodes
// it, never encodeFrame. The encodings' names: wire::encodingName of toWire
// (protocol.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "haarcast/io/image.h"

namespace haarcast::net {

enum class FrameEncoding { Jpeg, Png, RawRgba8, Exr, H264 };

// One entry point: the RGBA8 image (width × height) for the 8-bit
// encodings, the linear one for EXR (a frame rendered for an 8-bit encoding
// may carry no linear image: FrameRequest::linearImage). jpegQuality is
// clamped to 1..100. Throws std::runtime_error naming the codec.
std::string encodeFrame(FrameEncoding encoding, const std::vector<std::uint8_t>& rgba8, int width, int height,
                        const io::RgbImage& linear, int jpegQuality);

}  // namespace haarcast::net
