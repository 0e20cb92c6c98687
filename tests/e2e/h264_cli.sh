#!/usr/bin/env bash
# H.264 through haarcast-client against a real server (issue 13's test): a
# 60-frame orbit at 256² with --encoding h264 --check-not-blank decodes every
# frame (none undecoded, none blank, no keyframe asked for) and costs well
# under JPEG's bytes per frame on the same orbit; the ratio is printed. --out
# writes the decoded frames as PNG.
#
# A server that refuses ENCODING_H264 (its Error names the encoding) makes
# this a skip (77) with that Error quoted, not a failure: the server side of
# H.264 is a separate piece.
#
# usage: h264_cli.sh HAARCAST HAARCAST_CLIENT
set -uo pipefail
server_bin="${1:?usage: h264_cli.sh HAARCAST HAARCAST_CLIENT}"
client_bin="${2:?usage: h264_cli.sh HAARCAST HAARCAST_CLIENT}"
# "Well below": at most half of JPEG's bytes per frame at the server's default quality.
max_ratio="${H264_MAX_RATIO_TO_JPEG:-0.5}"
work="$(mktemp -d -t haarcast-h264-cli.XXXXXX)"
server_pid=""
cleanup() {
  [[ -n "$server_pid" ]] && { kill -KILL "$server_pid"; wait "$server_pid"; } 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

source "$(dirname "${BASH_SOURCE[0]}")/start_server.sh"
start_server "$server_bin" serve --port 0 --backend "${HAARCAST_SMOKE_BACKEND:-cpu}"
url="ws://127.0.0.1:$port"
run=(--frames 60 --size 256x256 --orbit 360 --check-not-blank --quiet --json --timeout 120)

rc=0
"$client_bin" "$url" "${run[@]}" --encoding h264 --out "$work/frames" >"$work/h264.json" 2>"$work/h264.err" || rc=$?
if [[ "$rc" != 0 ]] && grep -q "server error ERROR_CODE_[A-Z_]*: .*\(encoding\|[Hh]\.\?264\)" "$work/h264.err" &&
   ! grep -q '"frames": [1-9]' "$work/h264.json"; then
  echo "SKIP: this server refuses H.264 frames:"
  grep "server error" "$work/h264.err" | head -1 | sed 's/^/    /'
  exit 77
fi
failures=0
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
if [[ "$rc" != 0 ]]; then
  fail "--encoding h264 exited $rc:"
  sed 's/^/    /' "$work/h264.err"
fi
"$client_bin" "$url" "${run[@]}" --encoding jpeg >"$work/jpeg.json" 2>"$work/jpeg.err" || fail "--encoding jpeg exited $?: $(cat "$work/jpeg.err")"

field() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2" 2>/dev/null; }
h264_frames="$(field "$work/h264.json" frames)"
[[ "$(field "$work/h264.json" encoding)" == h264 ]] || fail "the summary says encoding $(field "$work/h264.json" encoding), not h264"
[[ "$h264_frames" == 60 ]] || fail "H.264: $h264_frames of 60 frames"
for counter in undecoded_frames keyframe_requests blank_frames errors; do
  value="$(field "$work/h264.json" "$counter")"
  [[ "$value" == 0 ]] || fail "H.264: $counter is $value, want 0"
done
pngs=$(find "$work/frames" -name 'frame-*.png' 2>/dev/null | wc -l)
[[ "$pngs" == 60 ]] || fail "--out wrote $pngs PNG frames, want 60"
head -c 8 "$(find "$work/frames" -name 'frame-000001.png' | head -1)" 2>/dev/null | od -An -tx1 | grep -q "89 50 4e 47" ||
  fail "--out frame-000001.png is not a PNG"

h264_bytes="$(field "$work/h264.json" bytes_per_frame)"
jpeg_bytes="$(field "$work/jpeg.json" bytes_per_frame)"
if [[ -n "$h264_bytes" && -n "$jpeg_bytes" ]]; then
  ratio="$(python3 -c "print(f'{$h264_bytes / $jpeg_bytes:.3f}')")"
  echo "256x256, 60-frame orbit: H.264 $h264_bytes B/frame, JPEG $jpeg_bytes B/frame, ratio $ratio (want < $max_ratio)"
  python3 -c "import sys; sys.exit(0 if $ratio < $max_ratio else 1)" || fail "H.264 is $ratio of JPEG's bytes, want < $max_ratio"
else
  fail "no bytes_per_frame in the summaries"
fi

kill -TERM "$server_pid"
wait "$server_pid" || fail "the server exited $? on SIGTERM"
server_pid=""
[[ "$failures" == 0 ]] && echo "all H.264 CLI checks passed" || echo "$failures failure(s)"
[[ "$failures" == 0 ]]
