#!/usr/bin/env bash
# Packs built executables with the shared libraries they load, to run a Debian 12 build on
# another x86-64 Linux (a GPU machine without Debian's packages). glibc's own libraries stay
# out: the target's are used. The archive is split into parts of at most 46 MB.
#   scripts/bundle.sh OUTDIR EXE...     e.g. scripts/bundle.sh .gpu build/server/effectd build/tests/render_test
# On the target: cat OUTDIR/bundle.part.* | xz -d | tar -x -C DIR, then run
#   LD_LIBRARY_PATH=DIR/lib:<the driver's libraries> DIR/<exe>
# for these executables only (exported globally, the bundled libraries would replace the
# target's for its own tools). NVIDIA's EGL through glvnd also needs
# __EGL_VENDOR_LIBRARY_FILENAMES=<the driver's 10_nvidia.json>, its Vulkan VK_DRIVER_FILES.
set -euo pipefail
[ $# -ge 2 ] || { sed -n '2,11p' "$0"; exit 2; }
out=$1
shift
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/lib" "$out"
for exe in "$@"; do
  cp "$exe" "$stage/"
  ldd "$exe" | awk '$2 == "=>" && $3 ~ /^\// {print $3}'
done | sort -u | grep -Ev '/(libc|libm|libpthread|libdl|librt|libresolv|libutil|ld-linux-x86-64)\.so' |
  while read -r lib; do cp -L "$lib" "$stage/lib/"; done
rm -f "$out"/bundle.part.*
tar -C "$stage" -cf - . | xz -6 -T0 | split -b 46M - "$out/bundle.part."
ls -l "$out"/bundle.part.*
