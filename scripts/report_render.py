#!/usr/bin/env python3
"""Renders docs/error-vs-time.md (and its plots) from the error report's data, one JSON file per
section in docs/error-vs-time/ (written by build/bench/error_report; docs/reports.md).

    scripts/report_render.py [--data DIR] [--out FILE] [--no-plots]
    scripts/report_render.py --check      exit 1 when FILE is not the rendering of DIR's data

The summary is one row per thing a game asks for and one column per budget (1 ms, a 16 ms frame,
a 100 ms loading screen, offline). A section's groups name their ask; the groups of several
sections with the same ask are joined by the request fields of their rows, so that a pick is
held to the limit of use of every metric that measures it.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
EFFECTS = ["lightning", "fog", "tangents", "bubble", "glow", "render"]  # report order
BUDGETS = [("≤ 1 ms", 1.0), ("≤ 16 ms (a frame)", 16.0), ("≤ 100 ms (a loading screen)", 100.0), ("offline", math.inf)]
CELL_LIMIT = 160  # visible characters of a summary cell


def git(*args):
    return subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True)


def fmt(v, digits=3):
    if v is None:
        return "—"
    if v == 0:
        return "0"
    return f"{v:.{digits}g}"


def anchor(s):
    """The link to a section's table (each section starts with an anchor named by its id)."""
    return "#" + s["id"]


def compact(obj):
    return json.dumps(obj, separators=(",", ":"), ensure_ascii=False)


def load(data_dir):
    sections = []
    for name in os.listdir(data_dir):
        if name.endswith(".json"):
            with open(os.path.join(data_dir, name), encoding="utf-8") as f:
                sections.append(json.load(f))
    sections.sort(key=lambda s: (EFFECTS.index(s["effect"]) if s["effect"] in EFFECTS else len(EFFECTS), s["id"]))
    return sections


def ms_of(row):
    t = row.get("time")
    return t["ms"] if t else None


# ---- the summary ------------------------------------------------------------------------------
def candidates(sections):
    """{ask: {"fixed": ..., "sections": [...], "by": {request key: candidate}}}, in report order."""
    asks = {}
    for s in sections:
        limits = {m["id"]: m for m in s["metrics"]}
        for a in s["asks"]:
            entry = asks.setdefault(a["ask"], {"fixed": a["fixed"], "sections": [], "by": {}})
            entry["sections"].append(s)
            for r in s["rows"]:
                if r["group"] != a["group"] or not r["request"]:
                    continue
                key = compact(r["request"])
                c = entry["by"].setdefault(key, {"request": r["request"], "ms": None, "metrics": [], "rows": []})
                c["rows"].append((s, r))
                if ms_of(r) is not None:
                    c["ms"] = max(c["ms"] or 0, ms_of(r))
                for mid, v in r["errors"].items():
                    if v is not None:
                        m = limits[mid]
                        c["metrics"].append({"label": m["label"], "value": v, "limit": m["limit"], "section": s})
    return asks


def worst_ratio(c):
    r = [m["value"] / m["limit"] for m in c["metrics"] if m["limit"]]
    return max(r) if r else math.inf


def failing(c):
    return [m for m in c["metrics"] if m["limit"] is not None and m["value"] > m["limit"]]


def cell(c):
    metrics = " · ".join(f"{m['label']} {fmt(m['value'], 2)}" for m in c["metrics"])
    link = anchor(c["rows"][0][0])
    text = f"`{compact(c['request'])}` {metrics} · {fmt(c['ms'], 2)} ms"
    if len(text) > CELL_LIMIT:
        text = text[:CELL_LIMIT - 1] + "…"
    return f"{text} [§]({link})"


def pick(entry, budget):
    timed = [c for c in entry["by"].values() if c["ms"] is not None]
    fits = [c for c in timed if c["ms"] <= budget]
    if not fits:
        fastest = min((c["ms"] for c in timed), default=None)
        return f"nothing fits (fastest {fmt(fastest, 2)} ms)" if fastest is not None else "—"
    within = [c for c in fits if not failing(c)]
    if within:
        best = min(within, key=lambda c: (worst_ratio(c), c["ms"]))
        return cell(best)
    best = min(fits, key=lambda c: (worst_ratio(c), c["ms"]))
    fails = ", ".join(f"{m['label']} {fmt(m['value'], 2)} > {fmt(m['limit'])}" for m in failing(best))
    return f"none within use; closest: `{compact(best['request'])}` fails {fails}"


def summary(sections):
    asks = candidates(sections)
    out = ["## Summary: what to send, per budget", "",
           "One row per thing a game asks for, one column per time budget. A cell is the request fields to send "
           "(besides the row's own), their errors and the median time; it is the most accurate setting within the "
           "budget (the smallest of error ÷ limit over every metric that measures it) and within every limit of use "
           "below. Where each setting that fits fails a limit, the cell names the metric. Rows of several sections "
           "with the same ask and request fields are one setting here: a bolt is held to its per-step distribution, "
           "its dimension and its shape at once. § links to the section's table; ← same: the budget to the left's pick. Computed from the data, not written "
           "by hand.", "",
           "| asks for | measured by | " + " | ".join(b[0] for b in BUDGETS) + " |",
           "|---|---|" + "---|" * len(BUDGETS)]
    for ask, entry in asks.items():
        fixed = f" `{compact(entry['fixed'])}`" if entry["fixed"] else ""
        measured = ", ".join(f"[{s['id']}]({anchor(s)})" for s in entry["sections"])
        cells = []
        for _, b in BUDGETS:  # a budget whose pick is the smaller one's says so instead of repeating it
            c = pick(entry, b)
            cells.append("← same" if cells and c == previous else c)
            previous = c
        out.append(f"| {ask}{fixed} | {measured} | " + " | ".join(cells) + " |")
    out += ["", "**Limits of use.** Past these a setting is no budget's choice, however fast; answers state the "
            "limit with each figure (`X-Effect-Error: …; limit=…`).", "",
            "| section | metric | limit | why |", "|---|---|---|---|"]
    for s in sections:
        for m in s["metrics"]:
            out.append(f"| {s['id']} | {m['name']} | {fmt(m['limit'])} | {m['why']} |")
    return out + [""]


# ---- a section --------------------------------------------------------------------------------
def time_text(s, r):
    t = r.get("time")
    if not t:
        return "—"
    k = s["timeScale"]
    text = fmt(t["ms"] * k)
    if t["repeats"] > 1:
        text += f" [{fmt(t['q1'] * k)}, {fmt(t['q3'] * k)}]"
    if len(t["runMedians"]) > 1:
        text += " (" + " · ".join(fmt(m * k) for m in t["runMedians"]) + ")"
    return text


def tie(a, b):
    return a["time"]["q1"] <= b["time"]["q3"] and b["time"]["q1"] <= a["time"]["q3"]


def pareto(rows, mid):
    """The rows no other beats on both axes (as fast or tied in time, and strictly closer), fastest first."""
    pts = [r for r in rows if r.get("time") and r["errors"].get(mid) is not None]
    pts.sort(key=lambda r: (r["time"]["ms"], r["errors"][mid]))
    front = []
    for p in pts:
        if front and not p["errors"][mid] < front[-1]["errors"][mid]:
            continue
        while front and tie(front[-1], p) and p["errors"][mid] < front[-1]["errors"][mid]:
            front.pop()
        front.append(p)
    return front


def times_note(s):
    """When the code a section times changed after its times were measured."""
    at = s.get("measuredAt") or {}
    since = at.get("commit")
    if not since or since == "unknown" or at.get("dirty"):  # measured on uncommitted code: the commit that landed the data
        since = git("log", "-1", "--format=%H", "--", f"docs/error-vs-time/{s['id']}.json").stdout.strip() or since
    if not since or git("cat-file", "-e", since + "^{commit}").returncode != 0:
        return ""
    changed = git("diff", "--name-only", since, "HEAD", "--", *s["code"]).stdout.split()
    if not changed:
        return ""
    return (f" **The times are older than the code they time:** {len(changed)} file(s) of {', '.join(s['code'])} changed "
            f"since `{since[:12]}` (first: `{changed[0]}`); the errors are current (`ctest -R reports_current` "
            "recomputes them).")


def section(s, plots):
    at = s.get("measuredAt") or {}
    commit = (at.get("commit") or "unknown")[:12] + (" + uncommitted changes" if at.get("dirty") else "")
    out = [f'<a id="{s["id"]}"></a>', "", f"## {s['title']}", "",
           f"Reference: {s['reference']}.", "",
           f"*Measured at `{commit}` on {at.get('date', 'an unknown date')}, {at.get('machine', 'an unknown machine')}; "
           f"{s['configuration']} configuration, {s['timingProcesses']} timing processes; regenerated in "
           f"{s['regenerationSeconds']:.0f} s by `scripts/report.sh --section {s['id']}`.*{times_note(s)}", ""]
    for p in plots:
        out += [f"![{s['title']}: {p[1]}](error-vs-time/{p[0]})", ""]
    metrics = s["metrics"]
    head = f"| method | {s['settingName']} | {s['timeName']} [interquartile range] (per process) | " + \
        " | ".join(m["name"] for m in metrics) + " |" + (f" {s['noteName']} |" if s["noteName"] else "")
    out += [head, "|---|---|---|" + "---|" * len(metrics) + ("---|" if s["noteName"] else "")]
    for r in s["rows"]:
        errs = " | ".join(fmt(r["errors"].get(m["id"])) for m in metrics)
        note = f" {r['note']} |" if s["noteName"] else ""
        out.append(f"| {r['series']} | {r['setting']} | {time_text(s, r)} | {errs} |{note}".replace("\n", " "))
    out += ["", "**Pareto fronts** (no other setting of the group is as fast and closer):", ""]
    groups = list(dict.fromkeys(r["group"] for r in s["rows"]))
    for g in groups:
        rows = [r for r in s["rows"] if r["group"] == g]
        for m in metrics:
            front = pareto(rows, m["id"])
            if front:
                out.append(f"- {g or 'all'}, {m['label']}: " + " → ".join(
                    f"{r['series']} {r['setting']} ({fmt(r['time']['ms'] * s['timeScale'], 2)}, {fmt(r['errors'][m['id']], 2)})"
                    for r in front))
    out += ["", f"**Conclusion.** {s['conclusion']}", ""]
    pics = s.get("pictures", [])
    stills = [p for p in pics if not p["file"].startswith("lightning-shape-")]
    if stills:
        out += ["| " + " | ".join(p["caption"] for p in stills) + " |", "|" + "---|" * len(stills),
                "| " + " | ".join(f"![](error-vs-time/{p['file']})" for p in stills) + " |", ""]
    for p in pics:
        if p not in stills:
            out += [f"![{p['caption']}](error-vs-time/{p['file']})", ""]
    return out


def plot(s, metric, path):
    """A log-log plot of the metric against time, one curve per series (gnuplot)."""
    series = {}
    exact = []
    for r in s["rows"]:
        v, t = r["errors"].get(metric["id"]), r.get("time")
        if v is None or not t or t["ms"] <= 0:
            continue
        (exact if v == 0 else series.setdefault(r["series"], [])).append((t["ms"] * s["timeScale"], v, r))
    if not series and not exact:
        return False
    floor = min((v for pts in series.values() for _, v, _ in pts), default=1.0) / 10
    with tempfile.TemporaryDirectory() as tmp:
        data = os.path.join(tmp, "d.dat")
        blocks = []
        with open(data, "w") as d:
            for name, pts in series.items():
                d.write(f"# {name}\n" + "".join(f"{x} {y}\n" for x, y, _ in pts) + "\n\n")
                blocks.append(name.replace("'", ""))
            for x, _, r in exact:
                d.write(f"{x} {floor}\n\n\n")
                blocks.append(f"{r['series']} {r['setting']} (error 0, at the floor)".replace("'", ""))
        longest = max(len(b) for b in blocks)
        many = len(blocks) > 10 or longest > 32
        width = 1500 if many else 800
        columns = max(1, min(3, width // (longest * 9 + 80)))
        rows = (len(blocks) + columns - 1) // columns
        height = 560 + 18 * rows if many else 520
        g = [f"set terminal pngcairo noenhanced size {width},{height} font 'sans,10'", f"set output '{path}'",
             f"set title \"{s['title']}\"", "set logscale xy", "set grid",
             f"set key outside below maxcols {columns} maxrows {rows}" if many else "set key outside right top",
             f"set xlabel \"{s['timeName']}, log scale\"", f"set ylabel \"{metric['label']}, log scale\"",
             "set format y '%.0e'", f"set arrow from graph 0, first {floor} to graph 1, first {floor} nohead dt 3 lc rgb 'gray'"]
        curves = []
        for i, b in enumerate(blocks):
            style = "points pt 12 ps 2" if i >= len(series) else \
                f"linespoints pt {[7, 5, 9][min(i // 8, 2)]} dt {i // 8 + 1} ps 0.8"
            curves.append(f"'{data}' index {i} with {style} lc {i % 8 + 1} title '{b}'")
        g.append("plot " + ", ".join(curves))
        script = os.path.join(tmp, "p.gp")
        with open(script, "w") as f:
            f.write("\n".join(g) + "\n")
        return subprocess.run(["gnuplot", script], capture_output=True).returncode == 0


def render(sections, data_dir, plots=False):
    out = ["# Error against run time", "",
           "Every effect's methods and settings on fixed seeds, against each section's reference: the error of what "
           "a request computes and its run time (the median over the repeats of several separate processes, with the "
           "interquartile range and each process's own median; two times whose ranges overlap are a tie). Each "
           "section's data lies in `docs/error-vs-time/<id>.json`; this page is rendered from them by "
           "`scripts/report_render.py`. How the report is made and kept current: [docs/reports.md](reports.md).", ""]
    out += summary(sections)
    for s in sections:
        shown = []
        for m in s["metrics"]:
            name = f"{s['id']}.png" if len(s["metrics"]) == 1 else f"{s['id']}-{m['id']}.png"
            if plots and not plot(s, m, os.path.join(data_dir, name)):
                continue
            if os.path.exists(os.path.join(data_dir, name)):
                shown.append((name, m["label"]))
        out += section(s, shown)
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", default=os.path.join(ROOT, "docs", "error-vs-time"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "error-vs-time.md"))
    ap.add_argument("--no-plots", action="store_true")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    sections = load(a.data)
    if a.check:
        # The note on times older than their code follows git, not the data: left out of the comparison.
        note = re.compile(r" \*\*The times are older than the code they time:\*\*[^\n]*")
        with open(a.out, encoding="utf-8") as f:
            same = note.sub("", f.read()) == note.sub("", render(sections, a.data))
        print(f"{a.out}: " + ("the rendering of the data" if same else
                              "NOT the rendering of the data: run scripts/report_render.py"))
        return 0 if same else 1
    text = render(sections, a.data, plots=not a.no_plots)
    with open(a.out, "w", encoding="utf-8") as f:
        f.write(text)
    print(f"wrote {a.out} from {len(sections)} sections")
    return 0


if __name__ == "__main__":
    sys.exit(main())
