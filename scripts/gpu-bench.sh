#!/usr/bin/env bash
# The render figures on a GPU machine that lacks Debian's packages, from a bundle of this build
# made here with scripts/bundle.sh (effectd, render_bench, render_test, and the
# baseline's effectd-base, render_bench-base and render_test-base, built from the commit
# compared against; any of the baseline's may be left out):
#   scripts/gpu-bench.sh BUNDLE_DIR [OUT_DIR]
# Runs render_test against the goldens (EFFECTD_EXAMPLES_DIR=examples), render_bench for both
# builds (with the allocator settings effectd gives itself), and bench/render_client.py (this
# build against the baseline, from a client). The
# bundled libraries are given to effectd's own executables only (LD_LIBRARY_PATH in wrappers);
# EGL finds the NVIDIA driver through glvnd's vendor file.
set -uo pipefail
bundle=$1
out=${2:-${OUT:-/tmp/gpu-bench}}
dir=/tmp/effectd-bundle
mkdir -p "$dir" "$out"
cat "$bundle"/bundle.part.* | xz -d -T0 | tar -x -C "$dir" || exit 1
vendor=$(ls /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json \
  /etc/glvnd/egl_vendor.d/10_nvidia.json 2>/dev/null | head -1)
[ -n "$vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$vendor
for exe in effectd effectd-base render_bench render_bench-base render_test render_test-base; do
  [ -x "$dir/$exe" ] || continue
  printf '#!/bin/sh\nLD_LIBRARY_PATH=%s/lib exec %s/%s "$@"\n' "$dir" "$dir" "$exe" > "$dir/$exe.sh"
  chmod +x "$dir/$exe.sh"
done
{
  date -u; nvidia-smi -L 2>&1; echo "EGL vendor file: $vendor"
  for t in render_test-base render_test; do
    [ -x "$dir/$t" ] || continue
    echo "== $t"; EFFECTD_EXAMPLES_DIR=$PWD/examples "$dir/$t.sh" --gtest_brief=1 2>&1 | grep -E "FAILED|PASSED|actual:|frame [0-9]+$|json$" | head -40
  done
  export MALLOC_MMAP_THRESHOLD_=$((32 << 20)) MALLOC_TRIM_THRESHOLD_=$((1 << 30)) MALLOC_ARENA_MAX=1
  for b in render_bench-base render_bench; do
    [ -x "$dir/$b" ] && { echo "== $b"; "$dir/$b.sh" 30; }
  done
  echo "== render_client"
  python3 bench/render_client.py --requests 20 "$dir/effectd.sh" $([ -x "$dir/effectd-base" ] && echo "$dir/effectd-base.sh")
} 2>&1 | tee "$out/gpu-bench.log"
