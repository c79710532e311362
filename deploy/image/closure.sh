#!/bin/sh
# Copies into $1 the files the runtime image needs and nothing else: the given executables,
# the shared libraries they load (ldd), Mesa's EGL vendor and its software DRI driver (which
# libglvnd and Mesa dlopen, so ldd cannot see them) with their libraries, and the ELF loader.
# Debian 12 has merged /usr: /lib, /lib64, /bin and /sbin are links into /usr, kept as links.
# Runs inside the full runtime stage of the Dockerfile, where every package is installed.
set -eu
out="$1"
shift
mkdir -p "$out/usr/lib" "$out/usr/lib64" "$out/usr/bin" "$out/usr/sbin"
for link in /lib /lib64 /bin /sbin; do [ -L "$link" ] && cp -a "$link" "$out$link"; done
mesa_egl=/usr/share/glvnd/egl_vendor.d/50_mesa.json
dri=/usr/lib/x86_64-linux-gnu/dri/swrast_dri.so
egl=/usr/lib/x86_64-linux-gnu/libEGL_mesa.so.0
for f in "$@" "$dri" "$egl"; do
  echo "$f"
  ldd "$f" | awk '/=> \// { print $3 } /^\t\// { print $1 }'
done | sort -u | while read -r f; do
  cp -L --parents "$f" "$out"  # the file, under the name the loader asks for (links followed,
done                           # /etc/alternatives ones too)
cp -a --parents "$mesa_egl" /usr/share/drirc.d "$out"
mkdir -p "$out/etc" "$out/tmp" "$out/proc" "$out/sys" "$out/dev"  # mount points a runtime fills
chmod 1777 "$out/tmp"
grep -E '^(root|effectd):' /etc/passwd > "$out/etc/passwd"
grep -E '^(root|effectd|nogroup):' /etc/group > "$out/etc/group"
