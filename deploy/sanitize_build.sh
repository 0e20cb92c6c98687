#!/usr/bin/env bash
# The one sanitized build: clang with AddressSanitizer + UBSan (undefined
# behaviour fatal) and libFuzzer's coverage feedback, in build-sanitize/.
# `deploy/run.sh test --sanitize` builds the fast unit tests here and
# deploy/fuzz.sh the libFuzzer targets, so CI compiles the sources once for both.
#
#   deploy/sanitize_build.sh target …   configure (first time) and build these targets
#
# -O1 with line tables: fast enough to fuzz, cheaper to compile than -O2 -g,
# and every report still names file and line. Without the gRPC transport
# (-DHAARCAST_GRPC=OFF): Debian's libgrpc++ is not instrumented, and its
# message path hands bytes to the same RenderSession the targets fuzz
# (docs/hardening.md). Environment: HAARCAST_JOBS
# (build jobs, default nproc), HAARCAST_SANITIZE_DIR (default build-sanitize).
set -euo pipefail
cd "$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")/.."
(($# > 0)) || { echo "usage: deploy/sanitize_build.sh target …" >&2; exit 2; }
command -v clang++ >/dev/null || { echo "error: clang++ not found (apt-get install clang libfuzzer-14-dev)" >&2; exit 1; }

dir="${HAARCAST_SANITIZE_DIR:-build-sanitize}"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
echo "==> configuring $dir/ (clang, ASan + UBSan, libFuzzer coverage)"
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
  "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -gline-tables-only" "${launcher[@]}" \
  -DHAARCAST_FUZZ=ON -DHAARCAST_BUILD_BENCHMARKS=OFF -DHAARCAST_GRPC=OFF >/dev/null </dev/null
echo "==> building $* in $dir/"
ninja -C "$dir" -j "${HAARCAST_JOBS:-$(nproc)}" "$@" </dev/null
