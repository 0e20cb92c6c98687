#!/usr/bin/env bash
# One entry point for people and CI: installs the Debian packages haarcast
# needs, configures (Release, Ninja) into build/, builds, then runs one job.
#
#   deploy/run.sh demo  [args]   render the default scene on both backends (build/demo/),
#                                 then serve it: prints the browser client's URL and runs
#                                 the CLI client against the server for a few seconds
#                                 (on a terminal the server keeps running until Ctrl-C)
#   deploy/run.sh test  [args]   ctest --test-dir build --output-on-failure --parallel JOBS [args]
#   deploy/run.sh test --sanitize  the fast unit tests (core, io, render, net) built with
#                                 ASan + UBSan (clang) into build-sanitize/ (no GPU, no end-to-end),
#                                 run in two lanes at once
#   (HAARCAST_TEST_JOBS: tests at once, default nproc; 1 runs them one by one)
#   deploy/run.sh fuzz [--seconds N]  deploy/fuzz.sh: builds the libFuzzer targets (clang)
#                                 into build-sanitize/ and runs each N seconds (default 20)
#   deploy/run.sh bench [args]   the speed table (bench-frame, fused: 128², 256², 512² at
#                                 levels 4-6, fps per backend), then build/bin/haarcast-bench [args]
#                                 e.g. deploy/run.sh bench -- --benchmark_filter=Rotate
#   deploy/run.sh build          install and build only
#   deploy/run.sh install ROLE…  install the packages of these roles (build, runtime, test)
#                                 and nothing else: the container image's stages use it
#   deploy/run.sh packages ROLE… print the packages of these roles, one per line
#
# Packages: build and demo and bench install the build and runtime roles, test
# installs all three.
#
# A leading "--" in [args] is dropped. Environment: HAARCAST_JOBS (build jobs,
# default nproc), HAARCAST_BUILD_DIR (default build), HAARCAST_PORT (demo's
# server port, default 8080; 0 picks a free one), HAARCAST_BACKEND (demo's
# server backend, default vulkan), HAARCAST_BENCH_BACKEND (the speed table's
# backends: cpu, vulkan or both, default both; none skips it). Runs without a terminal
# (CI): no prompts, no stdin.
set -euo pipefail

# Debian packages, one list per role, and nowhere else: the container image's
# stages install them through `deploy/run.sh install ROLE`, and
# tests/deploy/runtime_packages_test.py checks the runtime list against the
# libraries the built binaries load.
#
# build: compilers, headers and generators; Node.js vendors the browser
# client's one runtime package (protobufjs) from its lock file.
BUILD_PACKAGES=(
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
  # Step 3: Vulkan; glslang compiles the shaders at build time.
  libvulkan-dev
  glslang-tools
  # Step 4: the wire contract, the service (Asio + Beast) and its encoders.
  libprotobuf-dev
  protobuf-compiler
  libboost-dev
  libturbojpeg0-dev
  nodejs
  # Step 5: Google Highway for the fused kernel's SIMD (runtime dispatch).
  libhwy-dev
  # H.264 frames: libx264 through libavcodec, RGBA ↔ YUV through libswscale.
  libavcodec-dev
  libavutil-dev
  libswscale-dev
  # The gRPC transport (serve --grpc-port): libgrpc++ (reflection included)
  # and the protoc plugins for C++ and for the Python stubs of the docs' client.
  libgrpc++-dev
  protobuf-compiler-grpc
)
# runtime: the shared libraries `haarcast` and `haarcast-client` name as
# NEEDED (readelf -d), the Vulkan loader and Mesa's Vulkan drivers (lavapipe:
# the device where no GPU is passed in; they are loaded with dlopen, so no
# NEEDED entry names them), and vulkaninfo to see which devices a container
# has. libc6 and libgcc-s1 are in every Debian image (Priority: required).
RUNTIME_PACKAGES=(
  libstdc++6
  libembree3-3
  libopenexr-3-1-30
  libimath-3-1-29
  libpng16-16
  libtinyobjloader2rc10
  libprotobuf32
  libturbojpeg0
  libhwy1
  libavcodec59
  libavutil57
  libswscale6
  # gRPC: libgrpc++ and its reflection library, libgrpc's libgpr, Abseil.
  libgrpc++1.51
  libgrpc29
  libabsl20220623
  libvulkan1
  mesa-vulkan-drivers
  vulkan-tools
)
# test: the validation layers (GPU tests run with them on), Debian's Chromium
# for the browser client's end-to-end test, matplotlib for eval's figures
# (tools/plot_report.py), PyYAML and kubectl for the Kubernetes manifests' test.
TEST_PACKAGES=(
  vulkan-validationlayers
  chromium
  python3-matplotlib
  python3-yaml
  kubernetes-client
  # The gRPC transport's Python client in docs/service.md, run by its test.
  python3-grpcio
  python3-protobuf
  # deploy/fuzz.sh: libFuzzer targets built with clang.
  clang
  libfuzzer-14-dev
)

# Build folder, relative to the repository root (HAARCAST_BUILD_DIR overrides).
BUILD_DIR="${HAARCAST_BUILD_DIR:-build}"

usage() {
  # The header comment above, without its "# ".
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0" >&2
  exit 2
}

log() { printf '==> %s\n' "$*"; }

# The packages of the roles named (build, runtime, test), one per line.
role_packages() {
  local role
  for role in "$@"; do
    case "$role" in
      build) printf '%s\n' "${BUILD_PACKAGES[@]}" ;;
      runtime) printf '%s\n' "${RUNTIME_PACKAGES[@]}" ;;
      test) printf '%s\n' "${TEST_PACKAGES[@]}" ;;
      *)
        echo "error: unknown package role '$role' (valid: build, runtime, test)" >&2
        exit 2
        ;;
    esac
  done
}

# Installs the packages of the roles named that are not installed yet.
install_packages() {
  local missing=() pkg packages
  packages="$(role_packages "$@")" || exit 2
  for pkg in $packages; do
    # A kubectl already on PATH (a newer one, often from another package that
    # owns /usr/bin/kubectl) stands in for Debian's kubernetes-client, which
    # would conflict with it.
    [[ "$pkg" == kubernetes-client ]] && command -v kubectl >/dev/null 2>&1 && continue
    if [[ "$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)" != "install ok installed" ]]; then
      missing+=("$pkg")
    fi
  done
  # npm ships inside NodeSource's nodejs; Debian's own nodejs needs the npm
  # package beside it (installing that over NodeSource's would conflict).
  if grep -qx nodejs <<<"$packages"; then command -v npm >/dev/null 2>&1 || missing+=(npm); fi

  if ((${#missing[@]} > 0)); then
    log "installing ${missing[*]}"
    as_root "${missing[*]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q </dev/null
    as_root "${missing[*]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
      "${missing[@]}" </dev/null
  fi
  if grep -qx mesa-vulkan-drivers <<<"$packages"; then lavapipe_with_ray_tracing; fi
}

# Runs a command as root (itself, or through sudo); $1 names what it is for.
as_root() {
  local what="$1"
  shift
  if ((EUID == 0)); then
    "$@"
  elif command -v sudo >/dev/null 2>&1; then
    sudo "$@"
  else
    echo "error: not root and no sudo; install these first: $what" >&2
    exit 1
  fi
}

# Mesa's lavapipe traces rays (VK_KHR_acceleration_structure and
# VK_KHR_ray_tracing_pipeline: the Vulkan backend's device rays, docs/gpu.md)
# from Mesa 24.1 on; Debian 12's own Mesa is 22.3.6. On Debian 12 this adds
# the bookworm-backports suite (/etc/apt/sources.list.d/haarcast-bookworm-backports.list;
# apt prefers the main suite for everything else, backports only where asked)
# and takes mesa-vulkan-drivers 25 from it, with the Mesa and libdrm packages
# it needs (libgl1-mesa-dri, mesa-libgallium, libdrm*; about 5 s). Elsewhere, or
# where a Mesa ≥ 24.1 is installed already, it changes nothing.
lavapipe_with_ray_tracing() {
  local version codename=""
  version="$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)"
  if [[ -n "$version" ]] && dpkg --compare-versions "$version" ge 24.1; then return 0; fi
  # shellcheck disable=SC1091
  [[ -r /etc/os-release ]] && codename="$(. /etc/os-release && echo "${VERSION_CODENAME:-}")"
  if [[ "$codename" != bookworm ]]; then
    log "note: mesa-vulkan-drivers ${version:-absent} has no ray tracing on lavapipe; the Vulkan backend traces its rays on the host"
    return 0
  fi
  local list=/etc/apt/sources.list.d/haarcast-bookworm-backports.list
  log "taking mesa-vulkan-drivers from bookworm-backports (lavapipe with ray tracing; Debian 12 has ${version:-none})"
  if [[ ! -f "$list" ]]; then
    echo "deb http://deb.debian.org/debian bookworm-backports main" | as_root "$list" tee "$list" >/dev/null
  fi
  as_root "bookworm-backports" env DEBIAN_FRONTEND=noninteractive apt-get update -q </dev/null
  as_root "mesa-vulkan-drivers from bookworm-backports" env DEBIAN_FRONTEND=noninteractive \
    apt-get install -y -q --no-install-recommends -t bookworm-backports mesa-vulkan-drivers </dev/null
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
  demo | test | bench | build | fuzz | install | packages) ;;
  -h | --help | help) usage ;;
  *)
    echo "error: unknown command '$command'" >&2
    usage
    ;;
esac

# Work from the repository root whatever the caller's directory.
cd "$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")/.."
export DEBIAN_FRONTEND=noninteractive

# The browser client's npm packages (protobufjs for the page, playwright-core
# for its end-to-end test), from the committed package-lock.json: fetched at
# setup, never at run time. Skipped when node_modules is newer than the lock.
vendor_web_client() {
  local web=client/web
  [[ -f "$web/package-lock.json" ]] || return 0
  if [[ -d "$web/node_modules" && "$web/node_modules" -nt "$web/package-lock.json" ]]; then
    return 0
  fi
  log "vendoring the browser client's npm packages (npm ci in $web)"
  (cd "$web" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund </dev/null)
  touch "$web/node_modules"
}

case "$command" in
  packages)
    (($# >= 1)) || { echo "error: packages needs a role (build, runtime, test)" >&2; exit 2; }
    role_packages "$@"
    exit 0
    ;;
  install)
    (($# >= 1)) || { echo "error: install needs a role (build, runtime, test)" >&2; exit 2; }
    install_packages "$@"
    exit 0
    ;;
  test | fuzz) install_packages build runtime test ;;
  *) install_packages build runtime ;;
esac

# The fast unit tests under AddressSanitizer and UBSan (undefined behaviour
# fatal), in a build folder of their own; the GPU and end-to-end tests are
# left to the ordinary build.
SANITIZE_TESTS=(haarcast_core_tests haarcast_io_tests haarcast_render_tests haarcast_wire_tests haarcast_net_tests)
# One binary under ASan + UBSan, its output into $2: status 0 when it passed.
# A limit per binary: a test that hangs on another machine fails the run
# instead of holding it.
sanitized_binary() {
  local dir="${HAARCAST_SANITIZE_DIR:-build-sanitize}" t="$1" out="$2"
  shift 2
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    timeout --kill-after=10 1800 "$dir/bin/$t" "$@" >"$out" 2>&1 </dev/null
}
# Two lanes at once on two cores (the render tests, about 4 minutes here,
# beside the other four, about 3½): each binary's output is printed whole
# when it ends, with its time and status.
sanitized_tests() {
  local dir="${HAARCAST_SANITIZE_DIR:-build-sanitize}" failed=0 t lane rc
  deploy/sanitize_build.sh "${SANITIZE_TESTS[@]}"
  local logs
  logs="$(mktemp -d -t haarcast-sanitize.XXXXXX)"
  local -a lanes=("haarcast_render_tests" "haarcast_net_tests haarcast_core_tests haarcast_io_tests haarcast_wire_tests")
  ((${HAARCAST_TEST_JOBS:-$(nproc)} >= 2)) || lanes=("${SANITIZE_TESTS[*]}")
  local -a pids=()
  for lane in "${lanes[@]}"; do
    (
      lane_failed=0
      for t in $lane; do
        start=$SECONDS
        rc=0
        sanitized_binary "$t" "$logs/$t.log" "$@" || rc=$?
        {
          echo "==> $t (ASan + UBSan): $( ((rc == 0)) && echo passed || echo "FAILED, status $rc") in $((SECONDS - start)) s"
          ((rc == 0)) && tail -n 3 "$logs/$t.log" || cat "$logs/$t.log"
        } | flock "$logs" cat
        ((rc == 0)) || lane_failed=1
      done
      exit "$lane_failed"
    ) &
    pids+=($!)
  done
  for lane in "${pids[@]}"; do wait "$lane" || failed=1; done
  rm -rf "$logs"
  return "$failed"
}

if [[ "$command" == fuzz ]]; then
  exec deploy/fuzz.sh "$@"
fi
if [[ "$command" == test && "${1:-}" == --sanitize ]]; then
  shift
  sanitized_tests "$@"
  exit
fi
configure_and_build
vendor_web_client

# Runs one named step of a job under a wall-clock limit: `step NAME SECONDS
# cmd...`. A step that fails or runs past its limit ends the job with an
# error naming the step (timeout(1) sends TERM, then KILL 10 s later).
step() {
  local name="$1" limit="$2" rc=0
  shift 2
  timeout --kill-after=10 "$limit" "$@" || rc=$?
  if ((rc == 124 || rc == 137)); then
    echo "error: step '$name' did not finish within $limit s" >&2
    exit 1
  elif ((rc != 0)); then
    echo "error: step '$name' failed (exit status $rc)" >&2
    exit "$rc"
  fi
}

case "$command" in
  demo)
    # The main job on the built-in default scene: render it on both backends
    # (EXR + PNG in build/demo/), then serve it and drive it with the CLI
    # client. Every step has a wall-clock limit (HAARCAST_DEMO_STEP_SECONDS,
    # default 600: a first Vulkan frame on lavapipe compiles its shaders,
    # about a minute on two cores) and a failure names its step.
    step_limit="${HAARCAST_DEMO_STEP_SECONDS:-600}"
    mkdir -p "$BUILD_DIR/demo"
    for backend in cpu vulkan; do
      log "rendering the default scene with --backend $backend into $BUILD_DIR/demo/default-$backend.exr (+ .png)"
      step "render --backend $backend" "$step_limit" \
        "$BUILD_DIR/bin/haarcast" render --backend "$backend" --width 192 --height 128 --level 5 \
        --cache-dir "$BUILD_DIR/cache" --out "$BUILD_DIR/demo/default-$backend.exr" "$@" </dev/null
    done
    port="${HAARCAST_PORT:-8080}"
    log "starting haarcast serve on port $port (backend ${HAARCAST_BACKEND:-vulkan})"
    server_log="$BUILD_DIR/demo/serve.log"
    "$BUILD_DIR/bin/haarcast" serve --port "$port" --backend "${HAARCAST_BACKEND:-vulkan}" \
      --cache-dir "$BUILD_DIR/cache" </dev/null >"$server_log" 2>&1 &
    server=$!
    trap 'kill -KILL "$server" 2>/dev/null || true' EXIT
    url=""
    for _ in $(seq 1 600); do
      url="$(sed -n 's/^listening on \(http:[^ ]*\)$/\1/p' "$server_log" | head -n 1)"
      [[ -n "$url" ]] && break
      kill -0 "$server" 2>/dev/null || { cat "$server_log" >&2; echo "error: step 'serve' failed: the server exited" >&2; exit 1; }
      sleep 0.1
    done
    [[ -n "$url" ]] || { cat "$server_log" >&2; echo "error: step 'serve' did not start listening within 60 s" >&2; exit 1; }
    log "browser client: $url"
    ws="ws://${url#http://}ws"
    # The client plays a 36-pose orbit for at most 10 s at 256² with the
    # server's default method (fused). The first frame may wait for the
    # server's renderer build and, on lavapipe, for its shaders' compilation
    # at the server's level (a minute or more on two busy cores): up to 300 s
    # a frame, within the step's limit.
    log "running haarcast-client $ws for 10 s (frames in $BUILD_DIR/demo/frames/)"
    step "haarcast-client" "$step_limit" \
      "$BUILD_DIR/bin/haarcast-client" "$ws" --duration 10 --frames 36 --size 256x256 --encoding jpeg \
      --timeout 300 --out "$BUILD_DIR/demo/frames" --json </dev/null
    if [[ -t 0 ]]; then
      log "the server keeps running at $url (log: $server_log); Ctrl-C stops it"
      wait "$server"
    else
      # SIGTERM, then at most 10 s for a clean exit.
      kill -TERM "$server"
      for _ in $(seq 1 100); do
        kill -0 "$server" 2>/dev/null || break
        sleep 0.1
      done
      if kill -0 "$server" 2>/dev/null; then
        cat "$server_log" >&2
        echo "error: step 'stop server' did not finish within 10 s of SIGTERM" >&2
        exit 1
      fi
      rc=0
      wait "$server" || rc=$?
      trap - EXIT
      ((rc == 0)) || { cat "$server_log" >&2; echo "error: step 'stop server' failed: serve exited with status $rc" >&2; exit 1; }
      log "server stopped cleanly"
    fi
    ;;
  build)
    log "built into $BUILD_DIR/"
    ;;
  test)
    log "running tests"
    # The install step gave lavapipe ray tracing where it can (Debian 12):
    # there the device-ray tests fail rather than skip without it.
    if [[ -z "${HAARCAST_REQUIRE_RAY_TRACING:-}" ]] &&
      dpkg --compare-versions "$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || echo 0)" ge 24.1; then
      export HAARCAST_REQUIRE_RAY_TRACING=1
    fi
    # --timeout: the limit of a test that sets none of its own (each suite
    # sets one; this catches a test added without). Tests run in parallel,
    # one per core (HAARCAST_TEST_JOBS): the suite is checked that way on
    # the 2-core machines it runs on.
    exec ctest --test-dir "$BUILD_DIR" --output-on-failure --timeout 600 \
      --parallel "${HAARCAST_TEST_JOBS:-$(nproc)}" "$@" </dev/null
    ;;
  bench)
    bench_backend="${HAARCAST_BENCH_BACKEND:-both}"
    if [[ "$bench_backend" != none ]]; then
      log "speed table: fused, 128² 256² 512², levels 4-6, backend $bench_backend"
      "$BUILD_DIR/bin/haarcast" bench-frame --backend "$bench_backend" --method fused --sizes 128,256,512 \
        --levels 4,5,6 --frames 3 --cache-dir "$BUILD_DIR/cache" </dev/null
    fi
    log "running benchmarks"
    exec "$BUILD_DIR/bin/haarcast-bench" "$@" </dev/null
    ;;
esac
