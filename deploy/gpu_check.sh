#!/usr/bin/env bash
# The GPU check (docs/gpu.md, "On a real GPU") on a machine with an NVIDIA
# driver and none of haarcast's packages: unpacks a bundle made by
# deploy/gpu_bundle.sh, then runs the GPU unit tests with validation on and
# bench-frame on the GPU. Each step has its own time limit, so one that
# hangs still leaves the others' figures.
#
#   deploy/gpu_check.sh BUNDLE.tar.xz OUT_DIR [quick]
#
# OUT_DIR receives device.txt, gpu_tests.log, bench.log, one JSON file per
# bench-frame run and the load test's report (at most 8 files).
set -uo pipefail
bundle="${1:?usage: deploy/gpu_check.sh BUNDLE.tar.xz OUT_DIR [quick]}"
out="${2:?usage: deploy/gpu_check.sh BUNDLE.tar.xz OUT_DIR [quick]}"
mode="${3:-full}"
mkdir -p "$out" /tmp/hcgpu
tar -C /tmp/hcgpu -xJf "$bundle" || exit 1
hc=/tmp/hcgpu/hc
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
step() { echo "==> $*"; }

{
  step "device"
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
  echo "ICD: ${VK_DRIVER_FILES:-none found}; libGLX_nvidia: ${glx:-none found}"
  [[ -n "${VK_DRIVER_FILES:-}" ]] && cat "$VK_DRIVER_FILES"
  nproc; uname -r
} 2>&1 | tee "$out/device.txt"

# On the H200 every vkCreateInstance after about 40 in one process failed
# (VK_ERROR_INCOMPATIBLE_DRIVER; gpu.md, "On a real GPU"), and the tests
# make one per test: each suite runs in its own process, so all of them
# run; the suites share HAARCAST_GPU_TEST_SECONDS. Each process's thread
# count is sampled every 2 s (one suspect of that limit).
step "GPU unit tests, validation on, a process per suite"
suites=$("$hc/bin/haarcast_gpu_tests" --gtest_list_tests | awk '/^[^ ]/ && /\.$/ { print $1 }')
deadline=$((SECONDS + ${HAARCAST_GPU_TEST_SECONDS:-140}))
: >"$out/gpu_tests.log"
for suite in $suites; do
  left=$((deadline - SECONDS))
  if ((left <= 0)); then echo "out of time before $suite" | tee -a "$out/gpu_tests.log"; break; fi
  "$hc/bin/haarcast_gpu_tests" --gtest_brief=1 --gtest_filter="${suite}*" >>"$out/gpu_tests.log" 2>&1 &
  pid=$!
  ( while kill -0 "$pid" 2>/dev/null; do
      printf '%s %s\n' "$suite" "$(ls /proc/"$pid"/task 2>/dev/null | wc -l)"; sleep 2
    done ) >>/tmp/hcgpu/threads.txt &
  ( sleep "$left"; kill "$pid" 2>/dev/null ) &
  killer=$!
  wait "$pid"
  echo "$suite rc=$?"
  kill "$killer" 2>/dev/null
done
echo "threads per suite process (most seen):" \
  $(sort -k1,1 -k2,2n /tmp/hcgpu/threads.txt 2>/dev/null | awk '{ m[$1] = $2 } END { for (s in m) printf "%s%s ", s, "=" m[s] }')
grep -E '^\[  (PASSED|FAILED|SKIPPED)|validation:|G-buffer|PSNR' "$out/gpu_tests.log" | head -80

bench() {
  local name="$1" limit="$2"; shift 2
  step "bench-frame $*"
  timeout "$limit" "$hc/bin/haarcast" bench-frame --cache-dir /tmp/hcgpu/cache --json "$@" >"$out/$name.json" 2>/tmp/hcgpu/bench.err
  echo "rc=$?"
  grep -E 'row|error' /tmp/hcgpu/bench.err | tail -12
  cat /tmp/hcgpu/bench.err >>"$out/bench.log"
}
frames="${HAARCAST_GPU_FRAMES:-10}"
bench fused_grid 90 --backend vulkan --method fused --sizes 256,1280x720,1920x1080 --levels 5,6,auto --frames "$frames"
if [[ "$mode" != quick ]]; then
  bench both 50 --backend both --method fused --sizes 256,1280x720 --levels 5 --frames "$frames"
  bench all_720 40 --backend vulkan --method all --sizes 1280x720 --levels 5 --frames 5
  step "loadtest: serve --backend vulkan, 1 and 4 clients at 1280x720"
  timeout 40 "$hc/bin/haarcast" loadtest --backend vulkan --methods fused --clients 1,4 --sizes 1280x720 \
    --encodings jpeg --seconds 4 --cache-dir /tmp/hcgpu/cache --out /tmp/hcgpu/loadtest >"$out/loadtest.log" 2>&1
  echo "rc=$?"
  cp /tmp/hcgpu/loadtest/report.json "$out/loadtest.json" 2>/dev/null
  grep -v 's in, about' "$out/loadtest.log" | tail -8
fi
ls -la "$out"
