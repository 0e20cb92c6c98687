#!/usr/bin/env bash
# CTest driver of the browser's H.264 check (h264_webcodecs.mjs): writes the
# server encoder's orbit stream with the H.264 client test binary, vendors
# the browser client's npm packages when missing (as run_browser_e2e.sh
# does), then decodes the stream in Debian's headless Chromium. Exits 77
# (CTest's skip code) only when node, npm or chromium is absent.
#
# usage: run_h264_webcodecs.sh H264_CLIENT_TEST_BINARY OUT_DIR
set -euo pipefail

tests="${1:?usage: run_h264_webcodecs.sh H264_CLIENT_TEST_BINARY OUT_DIR}"
out="${2:?usage: run_h264_webcodecs.sh H264_CLIENT_TEST_BINARY OUT_DIR}"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
web="$repo/client/web"
chromium="${CHROMIUM:-/usr/bin/chromium}"

for tool in node npm; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool is not installed (deploy/run.sh installs it)"
    exit 77
  fi
done
if [[ ! -x "$chromium" ]]; then
  echo "SKIP: no Chromium at $chromium (apt-get install chromium, or set CHROMIUM)"
  exit 77
fi

rm -rf "$out"
HAARCAST_H264_STREAM_DIR="$out" "$tests" --gtest_filter=H264Client.WritesTheOrbitForTheBrowserCheck
[[ -f "$out/orbit.h264" ]] || { echo "FAIL: $tests wrote no stream under $out"; exit 1; }

export PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1
if [[ ! -d "$web/node_modules/playwright-core" ||
      "$web/package-lock.json" -nt "$web/node_modules/.package-lock.json" ]]; then
  echo "npm ci in $web"
  (cd "$web" && npm ci --no-audit --no-fund)
fi
exec node "$repo/tests/e2e/h264_webcodecs.mjs" --stream "$out" --chromium "$chromium"
