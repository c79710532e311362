#!/usr/bin/env bash
# Regenerates the reports (docs/reports.md): the error report's data, docs/error-vs-time/<id>.json,
# with its plots and docs/error-vs-time.md rendered from them; and the stability report's data,
# docs/stability/<effect>.json, with docs/stability.md. Each data file records the commit, date and
# machine it was measured at. Run it on an otherwise idle machine (times are medians with
# interquartile ranges over 3 processes, but a busy machine widens them), then commit what it wrote.
#
#   scripts/report.sh                      both reports, every section
#   scripts/report.sh --section ID ...     those error-report sections only (error_report --list names them)
#   scripts/report.sh --effect E ...       those stability effects only (tests/stability/run.py --list)
#   scripts/report.sh --quick              the reduced configuration, into build/report-quick/ (a smoke run)
#
# `ctest -R reports_current` says which sections a change left stale, and the command for each.
set -euo pipefail
cd "$(dirname "$0")/.."
sections=() effects=() quick=0
while [ $# -gt 0 ]; do
  case "$1" in
    --section) sections+=(--section "$2"); shift 2 ;;
    --effect) effects+=(--effect "$2"); shift 2 ;;
    --quick) quick=1; shift ;;
    *) echo "usage: scripts/report.sh [--section ID ...] [--effect E ...] [--quick]" >&2; exit 2 ;;
  esac
done
scripts/build.sh -DEFFECTD_BENCH=ON >/dev/null
meta=$(python3 scripts/report_meta.py)
if [ $quick = 1 ]; then
  out=build/report-quick
  mkdir -p "$out"
  build/bench/error_report --quick --out "$out" --meta "$meta" "${sections[@]}"
  python3 scripts/report_render.py --data "$out" --out "$out/error-vs-time.md"
  python3 tests/stability/run.py build/server/effectd --quick --mutations --check "${effects[@]}"
  echo "report.sh: wrote $out"
  exit 0
fi
# Only what was asked for; with neither flag, both reports whole.
if [ ${#sections[@]} -gt 0 ] || [ ${#effects[@]} -eq 0 ]; then
  start=$SECONDS
  build/bench/error_report --out docs/error-vs-time --meta "$meta" --command "scripts/report.sh" "${sections[@]}"
  python3 scripts/report_render.py
  echo "report.sh: the error report in $((SECONDS - start)) s: docs/error-vs-time/, docs/error-vs-time.md"
fi
if [ ${#effects[@]} -gt 0 ] || [ ${#sections[@]} -eq 0 ]; then
  start=$SECONDS
  python3 tests/stability/run.py build/server/effectd --write "${effects[@]}"
  echo "report.sh: the stability report in $((SECONDS - start)) s: docs/stability/, docs/stability.md"
fi
