#!/usr/bin/env bash
# The render figures on a GPU machine that lacks Debian's packages, from a bundle of this build
# made here with ../shared/tools/bundle-build.sh (effectd, render_bench, render_test, and the
# baseline's effectd-base and render_bench-base, each built from the commit compared against):
#   scripts/gpu-bench.sh BUNDLE_DIR [OUT_DIR]
# Runs render_test against the goldens (EFFECTD_EXAMPLES_DIR=examples), render_bench for both
# builds, and bench/render_client.py (this build against the baseline, from a client). The
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
for exe in effectd effectd-base render_bench render_bench-base render_test; do
  [ -x "$dir/$exe" ] || continue
  printf '#!/bin/sh\nLD_LIBRARY_PATH=%s/lib exec %s/%s "$@"\n' "$dir" "$dir" "$exe" > "$dir/$exe.sh"
  chmod +x "$dir/$exe.sh"
done
{
  date -u; nvidia-smi -L 2>&1; echo "EGL vendor file: $vendor"
  echo "== render_test"; EFFECTD_EXAMPLES_DIR=$PWD/examples "$dir/render_test.sh" --gtest_brief=1
  echo "== render_bench (baseline)"; "$dir/render_bench-base.sh" 30
  echo "== render_bench (this build)"; "$dir/render_bench.sh" 30
  echo "== render_client"; python3 bench/render_client.py --requests 20 "$dir/effectd.sh" "$dir/effectd-base.sh"
} 2>&1 | tee "$out/gpu-bench.log"
