#!/usr/bin/env bash
# CTest driver of the browser's H.264 check (h264_webcodecs.mjs): writes the
# server encoder's orbit stream with the H.264 client test binary, vendors
# the browser client's npm packages when missing (browser_env.sh), then decodes the stream in Debian's headless Chromium. Exits 77
# (CTest's skip code) only when node, npm or chromium is absent.
#
# usage: run_h264_webcodecs.sh H264_CLIENT_TEST_BINARY OUT_DIR
set -euo pipefail

tests="${1:?usage: run_h264_webcodecs.sh H264_CLIENT_TEST_BINARY OUT_DIR}"
out="${2:?usage: run_h264_webcodecs.sh H264_CLIENT_TEST_BINARY OUT_DIR}"
source "$(dirname "${BASH_SOURCE[0]}")/browser_env.sh"

rm -rf "$out"
HAARCAST_H264_STREAM_DIR="$out" "$tests" --gtest_filter=H264Client.WritesTheOrbitForTheBrowserCheck
[[ -f "$out/orbit.h264" ]] || { echo "FAIL: $tests wrote no stream under $out"; exit 1; }

exec node "$repo/tests/e2e/h264_webcodecs.mjs" --stream "$out" --chromium "$chromium"
