#!/usr/bin/env bash
# The C API from a second language: Effects.cs (C#, P/Invoke, Mono: what Unity's scripting
# descends from) grows one bolt and builds one fog table through libeffects.so; both must equal
# what `capi_test --print` gets from C. Skips (77) without mcs and mono (scripts/setup.sh
# installs them).
#   ffi_test.sh CAPI_TEST LIBEFFECTS_SO
set -euo pipefail
capi=$1
libdir=$(dirname "$2")
here=$(cd "$(dirname "$0")" && pwd)
command -v mcs >/dev/null && command -v mono >/dev/null || { echo "SKIP mcs or mono not installed (apt install mono-mcs mono-runtime)"; exit 77; }
work=$(mktemp -d /tmp/effectd-ffi.XXXXXX)
trap 'rm -rf "$work"' EXIT
mcs -nologo -out:"$work/effects_ffi.exe" "$here/Effects.cs"
LD_LIBRARY_PATH="$libdir" mono "$work/effects_ffi.exe" >"$work/cs.txt"
"$capi" --print >"$work/c.txt"
if ! cmp -s "$work/c.txt" "$work/cs.txt"; then
  diff <(tr ' ' '\n' <"$work/c.txt") <(tr ' ' '\n' <"$work/cs.txt") | head -20
  echo "FAIL C# and C disagree"
  exit 1
fi
echo "ok   C# (P/Invoke) and C: the same bolt ($(awk 'NR==1 {print (NF-1)/3}' "$work/c.txt") cells) and fog table ($(awk 'NR==2 {print NF-1}' "$work/c.txt") entries)"
