#!/usr/bin/env bash
# The GPU check (docs/gpu.md, "On a real GPU") on a machine with an NVIDIA
# driver and none of haarcast's packages: unpacks a bundle made by
# deploy/gpu_bundle.sh (haarcast, haarcast_gpu_tests and vulkaninfo), then
# runs, each step under its own time limit so that one that hangs still
# leaves the others' figures:
#   the device and whether it offers ray queries (vulkaninfo);
#   every GPU test, validation on, in one process (one engine per process);
#   bench-frame, Vulkan, fused at 1280×720 and 1920×1080, levels auto and 6
#   (rays on the device where it traces them), and 1080p level 6 with the host's rays;
#   frames in flight on one renderer (bench-frame --in-flight), each slot
#   on a queue of its own, then all on one queue;
#   serve --backend vulkan with 1, 4 and 16 load-test clients at 1280×720,
#   then with four frames in flight on four queues and on one;
#   H.264 at 1920×1080 (libx264 on the CPU: the H100/H200 have no NVENC),
#   its encode time per frame read from the server's /metrics;
#   bench-frame with both backends (Vulkan = CPU in dB, and the ratio).
# A bundle that also holds bin/haarcast.old (an earlier build) runs its
# bench-frame and load test too, in the same run: ratios against a baseline
# measured on the same machine.
#
#   deploy/gpu_check.sh BUNDLE.tar.xz OUT_DIR [quick|profile]
#
# profile: the device, the GPU tests of HAARCAST_GPU_TEST_FILTER (default
# all), then bench-frame's JSON with each stage's parts (render::Frame::parts:
# device timestamps within the stages) for the service's frame (1280×720,
# level 4, antialiased; again with fused's workgroups of 64 and 128, and
# without the sky the objects hide from each other) and 1920×1080 at levels auto and 6, and frames in flight on one
# queue and on every queue at 256² and 1280×720.
#
# OUT_DIR receives device.txt, vulkaninfo.txt, gpu_tests.log, one JSON file
# per bench-frame run with bench.log, loadtest logs and reports, metrics.txt:
# give it the device tool's $OUT, so that a run cut short still returns what
# it wrote (and expect at most 8 files back: tar the folder if asked for more).
# HAARCAST_GPU_SECONDS (default 400) is the whole run's budget: a step whose
# own limit no longer fits in what is left is skipped and says so.
set -uo pipefail
bundle="${1:?usage: deploy/gpu_check.sh BUNDLE.tar.xz OUT_DIR [quick|profile]}"
out="${2:?usage: deploy/gpu_check.sh BUNDLE.tar.xz OUT_DIR [quick|profile]}"
mode="${3:-full}"
mkdir -p "$out" /tmp/hcgpu
tar -C /tmp/hcgpu -xJf "$bundle" || exit 1
hc=/tmp/hcgpu/hc
cache=/tmp/hcgpu/cache
export LD_LIBRARY_PATH="$hc/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export VK_LAYER_PATH="$hc/layers"
# NVIDIA's Vulkan driver manifest: where the container runtime mounts it, or
# where the driver's own installer puts it.
for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json \
  /etc/vulkan/icd.d/nvidia_icd.json; do
  if [[ -f "$icd" ]]; then export VK_DRIVER_FILES="$icd" VK_ICD_FILENAMES="$icd"; break; fi
done
if [[ -z "${VK_DRIVER_FILES:-}" ]]; then
  icd="$(find / -xdev -name 'nvidia_icd*.json' -not -path '/proc/*' 2>/dev/null | head -1)"
  [[ -n "$icd" ]] && export VK_DRIVER_FILES="$icd" VK_ICD_FILENAMES="$icd"
fi
# The driver's own libraries (libGLX_nvidia, libnvidia-*), which the manifest
# names without a folder: where the runtime mounts them, else wherever they are.
glx="$(ldconfig -p | awk '/libGLX_nvidia.so.0/ { print $NF; exit }')"
[[ -n "$glx" ]] || glx="$(find / -xdev -name 'libGLX_nvidia.so.0' -not -path '/proc/*' 2>/dev/null | head -1)"
[[ -n "$glx" ]] && export LD_LIBRARY_PATH="$LD_LIBRARY_PATH:$(dirname "$glx")"
step() { echo "==> [$(date +%T), ${SECONDS}s] $*"; }
budget="${HAARCAST_GPU_SECONDS:-400}"
fits() {  # fits LIMIT: whether a step of LIMIT seconds fits in the budget left
  if ((SECONDS + $1 > budget)); then echo "skipped: ${1}s would pass the ${budget}s budget (${SECONDS}s spent)"; return 1; fi
}

{
  step "device"
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
  echo "ICD: ${VK_DRIVER_FILES:-none found}; libGLX_nvidia: ${glx:-none found}"
  nproc; uname -r; grep -m1 'model name' /proc/cpuinfo
} 2>&1 | tee "$out/device.txt"

step "vulkaninfo: the device and its ray-query support"
if [[ -x "$hc/bin/vulkaninfo" ]]; then
  timeout 30 "$hc/bin/vulkaninfo" --summary >"$out/vulkaninfo.txt" 2>&1
  timeout 30 "$hc/bin/vulkaninfo" 2>/dev/null |
    grep -iE 'ray_query|rayQuery|acceleration_structure|accelerationStructure +=|ray_tracing|rayTracingPipeline +=' |
    sort -u | tee -a "$out/vulkaninfo.txt"
  grep -E 'apiVersion|driverVersion|deviceName|driverName' "$out/vulkaninfo.txt" | head -8
else
  echo "no vulkaninfo in the bundle"
fi

# One process, as CI runs them: step 14 made one VkInstance per process, so
# every test starts (on the H200 the 41st instance used to fail).
step "GPU unit tests, validation on, one process"
timeout "${HAARCAST_GPU_TEST_SECONDS:-240}" "$hc/bin/haarcast_gpu_tests" --gtest_brief=1 \
  --gtest_filter="${HAARCAST_GPU_TEST_FILTER:-*}" >"$out/gpu_tests.log" 2>&1
echo "rc=$?"
grep -E '^\[  (PASSED|FAILED|SKIPPED)|^\[==========\]|validation:|Failure|PSNR|dB' "$out/gpu_tests.log" | head -60

bench() {
  local name="$1" limit="$2" bin="${BIN:-$hc/bin/haarcast}"; shift 2
  step "bench-frame $* ($(basename "$bin"))"
  fits "$limit" || return 0
  timeout "$limit" "$bin" bench-frame --cache-dir "$cache" --json "$@" >"$out/$name.json" 2>/tmp/hcgpu/bench.err
  echo "rc=$?"
  grep -E 'row|error|fps' /tmp/hcgpu/bench.err | tail -12
  cat /tmp/hcgpu/bench.err >>"$out/bench.log"
}
frames="${HAARCAST_GPU_FRAMES:-20}"
if [[ "$mode" == profile ]]; then
  bench profile_720_service 60 --backend vulkan --method fused --sizes 1280x720 --levels 4 --antialias on --frames "$frames"
  bench profile_1080 60 --backend vulkan --method fused --sizes 1920x1080 --levels auto,6 --frames "$frames"
  # fused's workgroup: 256 invocations a pixel by default on a GPU; fewer may
  # fit a pixel's directions now that cells and the reach cut leave fewer.
  for local in 64 128; do
    bench "profile_720_local$local" 60 --backend vulkan --method fused --sizes 1280x720 --levels 4 --antialias on \
      --fused-local-size "$local" --frames "$frames"
  done
  # What the sky the objects hide from each other costs the rays and the pass.
  bench profile_720_no_object_sky 60 --backend vulkan --method fused --sizes 1280x720 --levels 4 --antialias on \
    --object-sky 0 --frames "$frames"
  for q in 1 0; do
    bench "in_flight_queues$q" 90 --backend vulkan --vulkan-queues "$q" --method fused --sizes 256,1280x720 --levels 4 \
      --antialias on --in-flight 1,2,4 --frames "$frames"
  done
  # Each run's stages and their parts, in ms.
  for f in "$out"/profile_*.json; do
    python3 -c 'import json,sys
for r in json.load(open(sys.argv[1]))["runs"]:
  print(r["width"], r["height"], r["level"], "fps %.2f" % r["fps"])
  for k, v in r["stages"].items(): print("  %-16s %8.3f ms" % (k, 1e3 * v))
  for k, v in r.get("parts", {}).items(): print("    %-34s %8.3f ms" % (k, 1e3 * v))' "$f" | tee -a "$out/profile.txt"
  done
  ls -la "$out"
  exit 0
fi
bench fused_vulkan 120 --backend vulkan --method fused --sizes 1280x720,1920x1080 --levels auto,6 --frames "$frames"
# `auto` takes the device's rays on a GPU that traces them: the host's
# (Embree, the frame in two parts) beside it, the same run.
bench fused_vulkan_host_rays 60 --backend vulkan --rays host --method fused --sizes 1920x1080 --levels 6 --frames "$frames"
# Frames in flight on one renderer, the service's frame (1280×720, level 4,
# antialiased): its slots on queues of their own, then every slot on one queue.
bench in_flight 90 --backend vulkan --vulkan-queues 0 --method fused --sizes 1280x720 --levels 4 --antialias on \
  --in-flight 1,2,4,8 --frames "$frames"
bench in_flight_one_queue 60 --backend vulkan --vulkan-queues 1 --method fused --sizes 1280x720 --levels 4 \
  --antialias on --in-flight 1,4 --frames "$frames"
old="$hc/bin/haarcast.old"
[[ -x "$old" ]] && BIN="$old" bench fused_vulkan_old 60 --backend vulkan --method fused --sizes 1280x720,1920x1080 \
  --levels auto,6 --frames "$frames"
[[ "$mode" == quick ]] && { ls -la "$out"; exit 0; }

# The service: one server, whose /metrics gives the stage times (the encode
# stage included) over every frame it served.
metrics() {
  exec 3<>/dev/tcp/127.0.0.1/18080 || return 1
  printf 'GET /metrics HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n' >&3
  timeout 5 cat <&3 | grep -E '^haarcast_(stage_seconds|frames|device)'
  exec 3<&-
}
# Every load-test client comes from 127.0.0.1: the per-address limits
# admit 16 at once.
serve() {
  step "serve --backend vulkan ($(basename "$1")) ${3:-}"
  "$1" serve --backend vulkan ${3:-} --port 18080 --io-threads 4 --cache-dir "$cache" --quiet --max-pending-per-address 32 \
    --max-sessions-per-address 32 --max-connections-per-address 64 >"$out/serve$2.log" 2>&1 &
  server=$!
  for _ in $(seq 60); do
    (exec 3<>/dev/tcp/127.0.0.1/18080) 2>/dev/null && break
    sleep 0.5
  done
}
stop_server() { kill -TERM "$server"; wait "$server"; echo "serve rc=$?"; }
loadtest() {
  local name="$1" limit="$2"; shift 2
  step "loadtest $*"
  fits "$limit" || return 0
  timeout "$limit" "$hc/bin/haarcast" loadtest --url ws://127.0.0.1:18080 --backend vulkan --methods fused \
    --storage-level 4 --fps-cap 60 --seconds 4 --cache-dir "$cache" --out "/tmp/hcgpu/$name" "$@" \
    >"$out/$name.log" 2>&1
  echo "rc=$?"
  cp "/tmp/hcgpu/$name/report.md" "$out/$name.md" 2>/dev/null
  grep -v 's in, about' "$out/$name.log" | tail -8
}
serve "$hc/bin/haarcast" ""
loadtest loadtest_720 100 --clients 1,4,16 --sizes 1280x720 --encodings jpeg
metrics >"$out/metrics_720.txt"
loadtest loadtest_1080_h264 45 --clients 1 --sizes 1920x1080 --encodings h264
metrics >"$out/metrics.txt"
grep stage_seconds "$out/metrics.txt"
stop_server
# Against the default (two frames in flight on one queue): four frames on
# four queues of their own, and four on one queue.
serve "$hc/bin/haarcast" _k4_queues "--vulkan-queues 0 --frames-in-flight 4"
loadtest loadtest_720_k4_queues 60 --clients 4,16 --sizes 1280x720 --encodings jpeg
stop_server
serve "$hc/bin/haarcast" _k4_one_queue "--frames-in-flight 4"
loadtest loadtest_720_k4_one_queue 60 --clients 4,16 --sizes 1280x720 --encodings jpeg
stop_server
if [[ -x "$old" ]]; then
  serve "$old" _old
  loadtest loadtest_720_old 60 --clients 1,4,16 --sizes 1280x720 --encodings jpeg
  stop_server
fi

bench fused_both 120 --backend both --method fused --sizes 1280x720,1920x1080 --levels 6 --frames 5
ls -la "$out"
