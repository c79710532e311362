#!/usr/bin/env bash
# Regenerates both reports in one run at one commit: docs/error-vs-time.md (+ .json and the plots)
# and docs/stability.md. Each is stamped with this commit (or "+uncommitted" where effects/
# differs from it), the date and the machine; tests/CMakeLists.txt's reports_current fails when a
# committed report describes other effect code than HEAD's. Run it on an otherwise idle machine
# (the times are medians with interquartile ranges, but a busy machine widens them), commit, and
# commit the reports it wrote.
#
#   scripts/report.sh           the full configuration (about 35 min on 2 cores, 2026-11-28)
#   scripts/report.sh --quick   the reduced one, written to build/report-quick/ (a smoke run)
set -euo pipefail
cd "$(dirname "$0")/.."
quick=0
[ "${1:-}" = "--quick" ] && quick=1
scripts/build.sh -DEFFECTD_BENCH=ON >/dev/null
stamp() { python3 -c 'import sys; sys.path.insert(0, "scripts"); from report_stamp import stamp; print(stamp(sys.argv[1], "error-vs-time.md"))' "$1"; }
if [ $quick = 1 ]; then
  out=build/report-quick
  mkdir -p "$out"
  build/bench/error_report --quick --out "$out" --stamp "$(stamp "scripts/report.sh --quick")"
  python3 scripts/stability-report.py build/server/effectd --quick --check --no-sweep --mutations --out "$out/stability.md"
  echo "report.sh: wrote $out"
else
  build/bench/error_report --out docs --stamp "$(stamp "scripts/report.sh")"
  python3 scripts/stability-report.py build/server/effectd --check --mutations --out docs/stability.md --command "scripts/report.sh"
  echo "report.sh: wrote docs/error-vs-time.md, docs/error-vs-time.json, docs/error-vs-time/, docs/stability.md"
fi
