#!/usr/bin/env bash
# Packs built binaries with every shared library they load beyond glibc
# and libstdc++, the Vulkan loader, glvnd's dispatch libraries (which NVIDIA's
# Vulkan driver links) and the Khronos validation layer, into one tarball that
# runs on a GPU machine with a driver but none of haarcast's Debian packages
# and no network (deploy/gpu_check.sh unpacks and runs it).
#
#   deploy/gpu_bundle.sh OUT.tar.xz [BINARY…]
#
# BINARY defaults to build/bin/haarcast and build/bin/haarcast_gpu_tests.
# libavcodec's tree alone is over 120 MB: for a small bundle take haarcast
# from a build configured with -DHAARCAST_H264=OFF -DHAARCAST_GRPC=OFF
# -DHAARCAST_BUILD_TESTS=OFF (the GPU tests link no codec either).
# The binaries are stripped and the tarball packed with a 256 MiB
# dictionary (xz, one thread: about 4 minutes), because the device tool
# carries at most 64 MiB with the working tree: the full build's libraries,
# haarcast, the GPU tests and a baseline haarcast come to about 62 MB.
# The tarball unpacks to hc/{bin,lib,layers}. glibc, libm, libstdc++ and
# libgcc_s are left to the target: its own are the same or newer, and a
# second copy of glibc cannot be loaded beside the system's.
set -euo pipefail
out="${1:?usage: deploy/gpu_bundle.sh OUT.tar.xz [BINARY…]}"
shift
bins=("$@")
[[ ${#bins[@]} -gt 0 ]] || bins=(build/bin/haarcast build/bin/haarcast_gpu_tests)
stage="$(mktemp -d)"
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/hc/bin" "$stage/hc/lib" "$stage/hc/layers"

for b in "${bins[@]}"; do
  [[ -x "$b" ]] || { echo "error: $b is not built (deploy/run.sh build, or a build folder of its own)" >&2; exit 1; }
  cp "$b" "$stage/hc/bin/"
  strip --strip-unneeded "$stage/hc/bin/$(basename "$b")" 2>/dev/null || true
done

libdir=/usr/lib/x86_64-linux-gnu
layer_json=/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json
extra=("$libdir/libvulkan.so.1" "$libdir/libGLdispatch.so.0" "$libdir/libGLX.so.0" "$libdir/libEGL.so.1"
  "$libdir/libOpenGL.so.0" "$libdir/libVkLayer_khronos_validation.so")
skip='^(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|librt|ld-linux-x86-64|linux-vdso)\.so'
for f in "${bins[@]}" "${extra[@]}"; do
  [[ -e "$f" ]] || { echo "error: $f is missing (deploy/run.sh install runtime test)" >&2; exit 1; }
  ldd "$f" | awk '$2 == "=>" && $3 ~ /^\// { print $3 }'
  [[ "$f" == "$libdir"/* ]] && echo "$f"
done | sort -u | while read -r lib; do
  basename "$lib" | grep -Eq "$skip" || cp -L "$lib" "$stage/hc/lib/"
done
cp "$layer_json" "$stage/hc/layers/"

tar -C "$stage" -cf - hc | xz -T1 --lzma2=preset=9e,dict=256MiB >"$out"
echo "$out: $(du -h "$out" | cut -f1), $(ls "$stage/hc/lib" | wc -l) libraries"
tree=$(git ls-files -z 2>/dev/null | xargs -0 stat -c %s 2>/dev/null | awk '{ s += $1 } END { print s + 0 }')
total=$(($(stat -c %s "$out") + tree))
((total < 64 * 1024 * 1024 - 512 * 1024)) ||
  echo "warning: with the working tree ($tree bytes) this is $total bytes, at or over the device tool's 64 MiB" >&2
