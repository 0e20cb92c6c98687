#!/usr/bin/env bash
# One entry point for people and CI: installs the Debian packages haarcast
# needs, configures (Release, Ninja) into build/, builds, then runs one job.
#
#   deploy/run.sh demo  [args]   render the default scene (build/demo/), then the rotation report
#   deploy/run.sh test  [args]   ctest --test-dir build --output-on-failure [args]
#   deploy/run.sh bench [args]   build/bin/haarcast-bench [args]
#                                 e.g. deploy/run.sh bench -- --benchmark_filter=Rotate
#
# A leading "--" in [args] is dropped. Environment: HAARCAST_JOBS (build jobs,
# default nproc), HAARCAST_BUILD_DIR (default build). Runs without a terminal
# (CI): no prompts, no stdin.
set -euo pipefail

# Debian packages the build needs. Later steps (Vulkan, Embree, OpenEXR,
# Boost, protobuf, …) add their packages here, and nowhere else.
PACKAGES=(
  build-essential
  cmake
  ninja-build
  pkg-config
  libgtest-dev
  libgmock-dev
  libbenchmark-dev
  libglm-dev
  libcli11-dev
  nlohmann-json3-dev
  libopenexr-dev
  libembree-dev
  libtinyobjloader-dev
  libpng-dev
  # Step 3: Vulkan on Mesa's lavapipe (a CPU device) where no GPU exists;
  # glslang compiles the shaders at build time.
  libvulkan-dev
  mesa-vulkan-drivers
  vulkan-tools
  vulkan-validationlayers
  glslang-tools
  # Step 4: the wire contract, the service (Asio + Beast) and its encoders;
  # Debian's Chromium and Node.js for the browser client's end-to-end test.
  libprotobuf-dev
  protobuf-compiler
  libboost-dev
  libturbojpeg0-dev
  chromium
  nodejs
)

# Build folder, relative to the repository root (HAARCAST_BUILD_DIR overrides).
BUILD_DIR="${HAARCAST_BUILD_DIR:-build}"

usage() {
  # The header comment above, without its "# ".
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0" >&2
  exit 2
}

log() { printf '==> %s\n' "$*"; }

install_packages() {
  local missing=() pkg
  for pkg in "${PACKAGES[@]}"; do
    if [[ "$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)" != "install ok installed" ]]; then
      missing+=("$pkg")
    fi
  done
  # npm ships inside NodeSource's nodejs; Debian's own nodejs needs the npm
  # package beside it (installing that over NodeSource's would conflict).
  command -v npm >/dev/null 2>&1 || missing+=(npm)
  ((${#missing[@]} == 0)) && return 0

  log "installing ${missing[*]}"
  local -a as_root=()
  if ((EUID != 0)); then
    if ! command -v sudo >/dev/null 2>&1; then
      echo "error: not root and no sudo; install these packages first: ${missing[*]}" >&2
      exit 1
    fi
    as_root=(sudo)
  fi
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q </dev/null
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
    "${missing[@]}" </dev/null
}

configure_and_build() {
  local cache="$BUILD_DIR/CMakeCache.txt"
  if [[ -f "$cache" ]] && ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$cache"; then
    echo "error: $BUILD_DIR/ was configured with another generator; remove it and rerun" >&2
    exit 1
  fi
  log "configuring $BUILD_DIR/ (Release, Ninja)"
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release </dev/null
  local jobs="${HAARCAST_JOBS:-$(nproc)}"
  log "building with $jobs jobs"
  ninja -C "$BUILD_DIR" -j "$jobs" </dev/null
}

(($# >= 1)) || usage
command="$1"
shift
[[ "${1:-}" == "--" ]] && shift
case "$command" in
  demo | test | bench) ;;
  -h | --help | help) usage ;;
  *)
    echo "error: unknown command '$command'" >&2
    usage
    ;;
esac

# Work from the repository root whatever the caller's directory.
cd "$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")/.."
export DEBIAN_FRONTEND=noninteractive

install_packages
configure_and_build

case "$command" in
  demo)
    # The main job on the built-in default scene: render it (CPU backend,
    # EXR + PNG in build/demo/), then print the rotation report the render
    # rests on. Extra args go to `render`.
    mkdir -p "$BUILD_DIR/demo"
    log "rendering the default scene into $BUILD_DIR/demo/default.exr (+ .png)"
    "$BUILD_DIR/bin/haarcast" render --width 192 --height 128 --level 5 \
      --cache-dir "$BUILD_DIR/cache" --out "$BUILD_DIR/demo/default.exr" "$@" </dev/null
    log "running haarcast rotation-report --level 5"
    exec "$BUILD_DIR/bin/haarcast" rotation-report --level 5 </dev/null
    ;;
  test)
    log "running tests"
    exec ctest --test-dir "$BUILD_DIR" --output-on-failure "$@" </dev/null
    ;;
  bench)
    log "running benchmarks"
    exec "$BUILD_DIR/bin/haarcast-bench" "$@" </dev/null
    ;;
esac
