#!/usr/bin/env python3
"""docs/benchmarks.md's performance table, from one run of the benchmarks and their peers.

Runs bench/{fog,lightning,tangents,bubble}_bench (Google Benchmark, JSON output) and the
MikkTSpace peer (bench/mikktspace_peer.mjs: npm's WebAssembly build of the reference), then
prints a Markdown table in which every figure stands beside its baseline or peer measured in
the same run, with the ratio and the goal. With --write, replaces the section of
docs/benchmarks.md between <!-- bench-table:begin --> and <!-- bench-table:end -->.

  scripts/build.sh -DEFFECTD_BENCH=ON && scripts/bench-table.py [--write]   (about 2 minutes)

Each figure is the median of 3 repetitions (the peer: of 7 runs).

Timings are wall-clock on whatever machine runs it: the header says which and when. Nothing is
a pass or a fail here; goals missed are marked.
"""
import datetime
import json
import os
import platform
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.environ.get("BUILD_DIR", os.path.join(ROOT, "build"))


REPETITIONS = 3  # each figure is the median of 3 repetitions: this machine's timings wander
# The server's allocator settings (server/http/idle_trim.cpp): freed blocks up to 32 MB stay in one
# heap between calls instead of being faulted in again by the next one.
ALLOCATOR = {"MALLOC_MMAP_THRESHOLD_": str(32 << 20), "MALLOC_TRIM_THRESHOLD_": str(1 << 30), "MALLOC_ARENA_MAX": "1"}


def bench(name, filt):
    """{benchmark name: the median of its repetitions} for one Google Benchmark executable."""
    cmd = [os.path.join(BUILD, "bench", name), "--benchmark_format=json", f"--benchmark_filter={filt}",
           f"--benchmark_repetitions={REPETITIONS}", "--benchmark_report_aggregates_only=true"]
    print("running", " ".join(cmd[0:1] + cmd[2:3]), file=sys.stderr)
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env={**os.environ, **ALLOCATOR}).stdout
    return {b["run_name"]: b for b in json.loads(out)["benchmarks"] if b.get("aggregate_name") == "median"}


def ms(b):
    """Wall time of one iteration in milliseconds."""
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return b["real_time"] * scale


def fmt_ms(v):
    if v < 1:
        return f"{v * 1000:.0f} µs"
    if v < 10:
        return f"{v:.2f} ms"
    return f"{v:.0f} ms" if v >= 100 else f"{v:.1f} ms"


def goal(v, limit):
    """The goal, and whether this run met it."""
    return f"≤ {fmt_ms(limit)}" + ("" if v <= limit else " — **missed**")


def main():
    write = "--write" in sys.argv[1:]
    rows = []  # (figure, effectd, baseline or peer, ratio, goal)

    fog = bench("fog_bench", "/4096$")
    # Modes 0-6 hold f per entry; 7 is HEIGHT (2-D); 8 is ATMOSPHERIC (f, T and S per channel).
    distance = [ms(b) for n, b in fog.items() if re.match(r"BM_FogTable/[0-6]/", n)]
    atmospheric = ms(fog["BM_FogTable/8/4096"])
    height, closed = ms(fog["BM_FogTable/7/4096"]), ms(fog["BM_HeightTableClosedFormPerEntry/4096"])
    rows.append((f"fog table, 4096 entries, the {len(distance)} single-value distance modes",
                 f"{fmt_ms(min(distance))} … {fmt_ms(max(distance))}",
                 "—", "—", goal(max(distance), 0.1)))
    rows.append(("fog table, 4096 entries, ATMOSPHERIC (7 values an entry: f, T and S per channel)",
                 fmt_ms(atmospheric), "—", "—", goal(atmospheric, 0.1)))
    rows.append(("fog table, 4096 entries (2048 × 2), HEIGHT", fmt_ms(height),
                 f"closed form per entry: {fmt_ms(closed)}", f"{closed / height:.1f}× faster", goal(height, 0.1)))

    lt = bench("lightning_bench", "BM_Fast/(64|128)$|BM_Fast/4096|BM_DbmMgpcg|BM_DbmCg|BM_DbmCapacitance/(64|128)$|"
                                  "BM_Fast1024Obstacles|BM_Charges")
    fast128 = ms(lt["BM_Fast/128"])
    rows.append(("lightning `fast` 128², η 2", fmt_ms(fast128), "—", "—", goal(fast128, 0.25)))
    for n in (64, 128):
        mg, cg = ms(lt[f"BM_DbmMgpcg/{n}"]), ms(lt[f"BM_DbmCg/{n}/iterations:2"])
        direct = ms(lt[f"BM_DbmCapacitance/{n}"])
        fast = ms(lt[f"BM_Fast/{n}"]) if f"BM_Fast/{n}" in lt else None
        rows.append((f"`dbm` {n}², exact (capacitance, the default)", fmt_ms(direct), f"MGPCG, tol 1e-6: {fmt_ms(mg)}",
                     f"{mg / direct:.1f}× faster", goal(direct, 50) if n == 128 else "—"))
        rows.append((f"`dbm` {n}², tol 1e-6, MGPCG", fmt_ms(mg), f"plain CG: {fmt_ms(cg)}", f"{cg / mg:.1f}× faster", "—"))
        if fast:
            rows.append((f"`fast` {n}² against the exact `dbm`", fmt_ms(fast), f"`dbm` capacitance: {fmt_ms(direct)}",
                         f"{direct / fast:.0f}× faster", "—"))
    built, cached = ms(lt["BM_Fast1024Obstacles/0"]), ms(lt["BM_Fast1024Obstacles/1"])
    rows.append(("`fast` 1024², ~20 % obstacles", f"{fmt_ms(cached)} (boundary map cached)",
                 f"map built per call: {fmt_ms(built)}", f"cache saves {built / cached:.1f}×", goal(built, 50)))
    big = lt["BM_Fast/4096/iterations:3"]
    rows.append(("`fast` 4096² (the default grid limit)", fmt_ms(ms(big)), f"process peak RSS {big['peakRssMB']:.0f} MB",
                 "—", "—"))
    rows.append(("`charges` 64² / 128²", f"{fmt_ms(ms(lt['BM_Charges/64']))} / {fmt_ms(ms(lt['BM_Charges/128']))}",
                 "—", "—", "—"))

    tg = bench("tangents_bench", "MikkTSpace|PerTriangle")
    if not os.path.isdir(os.path.join(ROOT, "tests", "mikktspace", "node_modules", "mikktspace")):
        subprocess.run(["npm", "ci", "--no-audit", "--no-fund", "--loglevel=error"], check=True,
                       cwd=os.path.join(ROOT, "tests", "mikktspace"))
    peer = json.loads(subprocess.run(["node", os.path.join(ROOT, "bench", "mikktspace_peer.mjs")], check=True,
                                     capture_output=True, text=True).stdout)
    mikk, mikk1 = tg["BM_MikkTSpace100k"], tg["BM_MikkTSpace100kOneThread"]
    threads = int(mikk["poolThreads"])
    rows.append((f"MikkTSpace, 99 500-triangle sphere, {threads} threads", fmt_ms(ms(mikk)),
                 f"{peer['peer']}: {fmt_ms(peer['ms'])}", f"{peer['ms'] / ms(mikk):.0f}× faster", goal(ms(mikk), 15)))
    rows.append(("MikkTSpace, same mesh, 1 thread", fmt_ms(ms(mikk1)), f"same peer: {fmt_ms(peer['ms'])}",
                 f"{peer['ms'] / ms(mikk1):.0f}× faster", "—"))
    per, err = tg["BM_PerTriangle100k"], tg["BM_PerTriangleErrorVsMikk100k/iterations:3"]
    rows.append(("`perTriangle` (seed 004), same mesh", fmt_ms(ms(per)), f"MikkTSpace: {fmt_ms(ms(mikk))}",
                 f"angle error mean {err['meanAngleDeg']:.2f}°, max {err['maxAngleDeg']:.2f}°", "—"))

    bb = bench("bubble_bench", "BM_Icosphere|BM_ThinFilm256")
    rows.append(("bubble, level-5 icosphere with frames", fmt_ms(ms(bb["BM_Icosphere/5"])), "—", "—", "—"))
    t16, t81 = bb["BM_ThinFilm256/16"], bb["BM_ThinFilm256/81"]
    rows.append(("thin-film table 256², 16 wavelengths", fmt_ms(ms(t16)), f"81 wavelengths: {fmt_ms(ms(t81))}",
                 f"{ms(t81) / ms(t16):.1f}× faster; mean ΔE {t16['meanDeltaE']:.2f} vs 1 nm", "—"))

    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    cpu = "?"
    try:
        cpu = re.search(r"model name\s*:\s*(.*)", open("/proc/cpuinfo").read()).group(1).strip()
    except (OSError, AttributeError):
        pass
    lines = [f"Measured {when} by `scripts/bench-table.py` on {os.cpu_count()} × {cpu} ({platform.system()}), "
             "Release build, medians of 3 repetitions, the server's allocator settings (docs/architecture.md, "
             "memory between requests); every ratio is between two figures of that one run.", "",
             "| figure | effectd | baseline or peer (same run) | ratio | goal |", "|---|---|---|---|---|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    films = sorted((int(n.split("/")[1]), b) for n, b in bb.items() if n.startswith("BM_ThinFilm256/"))
    lines += ["", "Thin-film table 256 × 256 (`bubble_bench`): time, and ΔE*ab against 1 nm sampling, per number of "
              "wavelengths:", "",
              "| wavelengths | " + " | ".join(str(w) for w, _ in films) + " |", "|---" * (len(films) + 1) + "|",
              "| time | " + " | ".join(fmt_ms(ms(b)) for _, b in films) + " |",
              "| mean ΔE | " + " | ".join(f"{b['meanDeltaE']:.3g}" for _, b in films) + " |",
              "| max ΔE | " + " | ".join(f"{b['maxDeltaE']:.3g}" for _, b in films) + " |"]
    table = "\n".join(lines)
    print(table)
    if write:
        page = os.path.join(ROOT, "docs", "benchmarks.md")
        text = open(page, encoding="utf-8").read()
        begin, end = "<!-- bench-table:begin -->", "<!-- bench-table:end -->"
        if begin not in text or end not in text:
            sys.exit(f"docs/benchmarks.md lacks the {begin} … {end} markers")
        head, rest = text.split(begin, 1)
        tail = rest.split(end, 1)[1]
        open(page, "w", encoding="utf-8").write(head + begin + "\n" + table + "\n" + end + tail)
        print("docs/benchmarks.md updated", file=sys.stderr)


if __name__ == "__main__":
    main()
