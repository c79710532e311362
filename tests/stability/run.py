#!/usr/bin/env python3
"""The stability report as tests: every effect's stiff and extreme cases (tests/stability/<effect>.py)
sent to a running effectd, each checked by something that can fail (a closed form computed here,
an invariance between requests, or the exact 4xx it must get), each fed a mutation (a plausible
wrong answer) that its check must reject; docs/stability.md rendered from the data they measured.

    run.py BINARY --list                        the effects and their row counts
    run.py BINARY [--effect E ...] [--quick] [--mutations] [--check]
                                                run and print the rows; --check: exit 1 on a failed
                                                row (or, with --mutations, a mutation not caught)
    run.py BINARY --write [--effect E ...]      the full sizes with mutations, and the quick sizes for
                                                the fingerprint: writes docs/stability/<effect>.json
                                                (with every effect: also the property sweep's
                                                docs/stability/sweep.json), then renders docs/stability.md
    run.py BINARY --current [--effect E ...]    the quick sizes with mutations (what ctest runs as
                                                reports_current_stability): exit 1 when a row fails, a
                                                mutation is not caught, an effect's results differ from
                                                the quick fingerprint in its data file (STALE, naming the
                                                command that regenerates it), or docs/stability.md is
                                                not the rendering of the data files
    run.py --render                             re-renders docs/stability.md from the data files

Current by behaviour: a data file is stale only when what it measures changed its results (row
names, statuses, verdicts, the seen text and its numbers within the tolerances below), never
because code or comments changed. Timings (ms, seconds) are recorded and never compared.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from types import MappingProxyType

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != HERE]  # no `import fog` by accident
sys.path.insert(0, os.path.join(ROOT, "tests"))  # the package `stability`, sweep_test, effectd_process
sys.path.insert(0, os.path.join(ROOT, "scripts"))  # report_meta

import importlib  # noqa: E402

from report_meta import measured_at  # noqa: E402  (scripts/report_meta.py)

EFFECTS = ("fog", "lightning", "bubble", "tangents", "scene", "render", "glow")  # the doc's order
DATA = os.path.join(ROOT, "docs", "stability")
DOC = os.path.join(ROOT, "docs", "stability.md")
SWEEP_REQUESTS = 3000

# Fingerprint tolerances: a number seen now matches the committed one when |now − then| is within
# the largest of `relative`·max(|now|, |then|), `absolute`, and one unit in the last digit the more
# precise of the two printed (the seen text rounds: 0.9999 and 1 may be the same float32 on two
# machines). Effects whose numbers come from GPU rendering (llvmpipe where there is no GPU: its
# rasterisation and shading differ in the last bits between CPUs) use RENDER.
TOLERANCE = MappingProxyType({"relative": 1e-6, "absolute": 1e-6})
RENDER = MappingProxyType({"relative": 2e-2, "absolute": 2.0})  # the render rows print /255 levels, pixels and ΔE*ab

NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def effect_module(effect):
    return importlib.import_module("stability." + effect)


def tolerance(effect):
    return RENDER if getattr(effect_module(effect), "GPU", False) else TOLERANCE


def command_text(args, binary):
    return " ".join(["python3", "tests/stability/run.py", shown(binary)] + args)


def shown(binary):
    path = os.path.abspath(binary)
    return os.path.relpath(path, ROOT) if path.startswith(ROOT + os.sep) else binary


# ---- running rows --------------------------------------------------------------------------------
def try_mutation(c, answers, server):
    """(text, caught): the row's mutation fed to its own check, which must reject it."""
    if c.mutation is None:
        return "none", False
    try:
        wrong = c.mutation.apply(answers, server)
    except Exception as e:  # noqa: BLE001  (a mutation that cannot be made proves nothing)
        return f"{c.mutation.text} (could not be made: {e!r})", False
    try:
        ok, _ = c.check(wrong, server)
    except Exception:  # noqa: BLE001  (a check that cannot read the wrong answer rejects it)
        ok = False
    return c.mutation.text, not ok


def run_case(server, c, mutations):
    answers, ms = [], []
    for endpoint, body in c.requests():
        status, answer, seconds = server.post("/v1/" + endpoint, body)
        answers.append((status, answer if isinstance(answer, (dict, bytes)) else {}))  # bytes: a PNG
        ms.append(seconds * 1000)
    try:
        ok, seen = c.check(answers, server)
    except Exception as e:  # noqa: BLE001  (a check that cannot read the answer fails its row)
        ok, seen = False, f"check could not read the answer: {e!r}"
    text, caught = c.mutation.text if c.mutation else "none", None
    if mutations and ok:  # a failed row fails the run already: its answers are no base for a mutation
        text, caught = try_mutation(c, answers, server)
    first = answers[0]
    method = first[1].get("method", "") if first[0] == 200 and isinstance(first[1], dict) else ""
    return {"case": c.name, "status": "/".join(sorted({str(s) for s, _ in answers})), "method": method,
            "ms": round(sorted(ms)[len(ms) // 2], 1), "must": c.must, "seen": seen, "mutation": text,
            "caught": caught, "passed": bool(ok)}


def run_effect(server, effect, quick, mutations, echo=True):
    rows = []
    for c in effect_module(effect).cases(quick):
        assert c.effect == effect, f"{c.name}: effect {c.effect} in {effect}.py"
        r = run_case(server, c, mutations)
        rows.append(r)
        if echo:
            print(f"{'ok  ' if r['passed'] else 'FAIL'} {effect}: {r['case']}: {r['seen']}"
                  + (f" [mutation {'caught' if r['caught'] else 'NOT CAUGHT'}]" if mutations and r["passed"] else ""),
                  flush=True)
    return rows


def verdicts(rows):
    """(failed, missed): rows whose check failed, rows that passed with their mutation not caught."""
    return [r for r in rows if not r["passed"]], [r for r in rows if r["passed"] and r["caught"] is False]


# ---- the fingerprint: what --current compares --------------------------------------------------------
def numbers_of(text):
    out = []
    for tok in NUMBER.findall(text):
        v = float(tok)
        out.append(int(v) if is_integer_token(tok) and abs(v) < 2 ** 53 else v)
    return out


def is_integer_token(tok):
    return not any(ch in tok for ch in ".eE")


def significant(tok):
    digits = re.sub(r"[eE].*", "", tok.lstrip("+-")).replace(".", "").lstrip("0")
    return max(1, len(digits))


def fingerprint(rows):
    return [{"case": r["case"], "status": r["status"], "passed": r["passed"], "caught": r["caught"],
             "seen": r["seen"], "numbers": numbers_of(r["seen"])} for r in rows]


def same_number(then, now, tok_then, tok_now, tol):
    if then == now:
        return True
    if not (math.isfinite(then) and math.isfinite(now)):
        return False
    big = max(abs(then), abs(now))
    allowed = max(tol["relative"] * big, tol["absolute"])
    if not (is_integer_token(tok_then) and is_integer_token(tok_now)):  # a rounded float: its last digit
        allowed = max(allowed, 10.0 ** (math.floor(math.log10(big)) - (max(significant(tok_then), significant(tok_now)) - 1)))
    return abs(now - then) <= allowed


def row_difference(then, now, tol):
    """None when the row's results are the same, else what differs (the first thing)."""
    for key in ("status", "passed", "caught"):
        if then.get(key) != now[key]:
            return f"{key} {json.dumps(now[key])} was {json.dumps(then.get(key))}"
    old_seen, new_seen = then.get("seen", ""), now["seen"]
    old_toks, new_toks = NUMBER.findall(old_seen), NUMBER.findall(new_seen)
    old_nums = then.get("numbers", [])
    changed = (NUMBER.sub("#", old_seen) != NUMBER.sub("#", new_seen) or len(old_toks) != len(new_toks)
               or len(old_nums) != len(new_toks)
               or not all(same_number(a, b, ta, tb, tol)
                          for a, b, ta, tb in zip(old_nums, now["numbers"], old_toks, new_toks)))
    if changed:
        return f"seen {new_seen!r} was {old_seen!r}" + ("" if numbers_of(old_seen) == old_nums else f" (numbers {old_nums})")
    return None


def keyed(rows):
    """{(case, k): row}: the k-th row of that name (two rows may share a name: a table and samples)."""
    out, seen = {}, {}
    for r in rows:
        k = seen[r["case"]] = seen.get(r["case"], -1) + 1
        out[(r["case"], k)] = r
    return out


def stale(effect, rows_now, data, binary):
    """None when the effect's quick results match its committed fingerprint, else the STALE line."""
    regen = f"regenerate: {command_text(['--write', '--effect', effect], binary)}"
    if data is None:
        return f"STALE {effect}: no docs/stability/{effect}.json; {regen}"
    tol = tolerance(effect)
    then, now = keyed(data.get("quick", [])), keyed(fingerprint(rows_now))
    diffs = []
    for key, r in now.items():
        if key not in then:
            diffs.append((key[0], "a new row"))
        else:
            d = row_difference(then[key], r, tol)
            if d:
                diffs.append((key[0], d))
    diffs += [(key[0], "no longer a row") for key in then if key not in now]
    if not diffs:
        return None
    name, what = diffs[0]
    return (f"STALE {effect}: {len(diffs)} row{'s' if len(diffs) != 1 else ''} changed (first: {name!r}: {what}); "
            f"{regen}")


# ---- data files and the doc ------------------------------------------------------------------------
def data_path(effect):
    return os.path.join(DATA, effect + ".json")


def load(effect):
    try:
        with open(data_path(effect), encoding="utf-8") as f:
            return json.load(f)
    except FileNotFoundError:
        return None


def dump(path, obj):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(obj, f, indent=1, ensure_ascii=False)
        f.write("\n")


def cell(x):
    return str(x).replace("|", "\\|").replace("\n", " ")


def mutation_cell(r):
    if r["caught"] is None:
        return f"{r['mutation']}: " + ("not tried (the check failed)" if not r["passed"] else "not run")
    return f"{r['mutation']}: {'caught' if r['caught'] else 'NOT caught'}"


def measured_line(d):
    m = d["measuredAt"]
    return (f"Measured at commit `{m['commit']}{'+uncommitted' if m.get('dirty') else ''}` on {m['date']}, machine: "
            f"{m['machine']}; `{d['command']}` took {d['regenerationSeconds']:.1f} s.")


def render():
    """docs/stability.md's text from the committed data files."""
    data = [(e, load(e)) for e in EFFECTS]
    present = [(e, d) for e, d in data if d]
    rows = [r for _, d in present for r in d["rows"]]
    failed, missed = verdicts(rows)
    caught = sum(r["caught"] is True for r in rows)
    quick = [r for _, d in present for r in d["quick"]]
    qfailed, _ = verdicts(quick)
    qcaught = sum(r["caught"] is True for r in quick)
    rel, floor, grel, gfloor = TOLERANCE["relative"], TOLERANCE["absolute"], RENDER["relative"], RENDER["absolute"]
    md = ["# Numerical stability: stiff and extreme cases, checked",
          "",
          f"**{len(rows) - len(failed)} of {len(rows)} checks pass; {caught} of {len(rows)} mutations caught** (the "
          f"full sizes; at the quick sizes the test suite runs, {len(quick) - len(qfailed)} of {len(quick)} pass and "
          f"{qcaught} mutations are caught)."
          + ("" if len(present) == len(EFFECTS) else
             " Not measured yet: " + ", ".join(e for e, d in data if not d) + "."),
          "",
          "Rendered by `python3 tests/stability/run.py --render` from the data files `docs/stability/<effect>.json`, "
          "which `python3 tests/stability/run.py build/server/effectd --write` measures (one effect: add "
          "`--effect fog`; with every effect it also runs the property sweep into `docs/stability/sweep.json`). The "
          "rows are tests: each effect's cases live in `tests/stability/<effect>.py`, one `Case` per row (effect, "
          "name, endpoint, bodies, check, must, mutation) with its mutation beside it; `--list` counts them. A data "
          "file holds where and when it was measured (`measuredAt`: commit, uncommitted changes, date, machine), the "
          "`command`, `regenerationSeconds`, the full-size `rows` this page shows, and `quick`: the fingerprint of the "
          "quick sizes (each row's name, status, verdicts, seen text and the numbers in it).",
          "",
          "Each row is one or more requests to the running server and a check that can fail: a closed form "
          "computed in Python (docs/effects.md's formulas, not the server's code), an invariance between "
          "requests (the same answer at another scale, length or size), or the exact 4xx it must get. "
          "A row is right only when its check passes (✓). ms: the median request's wall-clock time from the client. "
          "Fog factors, transmittances and colours are compared within 2e-6 and, above 1e-30, within 1e-5 relative "
          "(so that e^−50 1 % off fails); a bolt's \"connected tree\" is checked cell by cell: rooted at the start, "
          "every parent grown before its child and a grid neighbour of it, no cell twice, the main channel the parent "
          "chain from the start to the target. Render rows decode the PNGs in Python (zlib) and compare the preview "
          "with the CPU reference over the sphere's closed-form silhouette. mutation: a plausible wrong answer made "
          "from the real ones (a fog factor 1 % off or the naive overflow's 1, a bolt cell moved off its tree, a mesh "
          "vertex nudged, a tangent frame flipped, a 4xx naming another field, a preview 20 % brighter or moved 3 "
          "pixels, ...) and fed to the same check, which must reject it (caught).",
          "",
          "Current by behaviour: the test suite runs `python3 tests/stability/run.py build/server/effectd --current` "
          "(ctest `reports_current_stability`, about 7 s): every effect's rows at the quick sizes with their "
          "mutations, failing on a failed row or a mutation not caught, and comparing each effect's results with the "
          "`quick` fingerprint in its data file. An effect is stale only when its results changed: a row added or "
          "gone, a status, a verdict (passed, caught), the words of what it saw, or a number in them beyond the "
          "tolerance; a comment or a refactor anywhere leaves it current, whatever the commit in `measuredAt` says. "
          "The failure names the effect and the command that regenerates just it (`STALE lightning: 1 row changed "
          "(first: '...': seen '...' was '...'); regenerate: python3 tests/stability/run.py build/server/effectd "
          "--write --effect lightning`). Timings (ms, seconds) are recorded and never compared. The tolerance: two "
          f"numbers match when they differ by at most the largest of {rel:g} relative, {floor:g} absolute (the "
          "measured errors near 0 are float32 rounding, and differ in the last bits between machines' libm and "
          "CPUs) and one unit in the last digit the more precise of the two printed (the seen text rounds: 0.9999 "
          "and 1 can be the same float32 seen on two machines; a number printed as an integer, a count, has no such "
          "allowance). The render rows' numbers come from GPU rendering (llvmpipe where there is no GPU, "
          f"whose rasterisation and shading differ between CPUs): {grel:g} relative, {gfloor:g} absolute (levels of "
          "255, pixels, ΔE*ab). `--current` also fails when this page is not the rendering of the data files. The "
          "property sweep's data is not fingerprinted: ctest's `sweep` runs it.",
          ""]
    for e, d in present:
        f, _ = verdicts(d["rows"])
        md += [f"## {e}",
               "",
               measured_line(d) + f" {len(d['rows']) - len(f)} of {len(d['rows'])} pass; "
               f"{sum(r['caught'] is True for r in d['rows'])} mutations caught.",
               "",
               "| effect | case | status | method | ms | must hold | seen | mutation | check |",
               "|---|---|---|---|---|---|---|---|---|"]
        for r in d["rows"]:
            md.append("| " + " | ".join(cell(x) for x in (e, r["case"], r["status"], r["method"], f"{r['ms']:.1f}",
                                                          r["must"], r["seen"], mutation_cell(r),
                                                          "✓" if r["passed"] else "✗ FAILED")) + " |")
        md.append("")
    sweep = load("sweep")
    if sweep:
        c = sweep["counts"]
        md += ["## The property sweep",
               "",
               measured_line(sweep),
               "",
               f"`tests/sweep_test.py build/server/effectd --requests {sweep['requests']} --seed {sweep['seed']}` (the "
               "test suite runs 800 requests in Release, 150 under ASan+UBSan): requests drawn from the full ranges the "
               "request schemas allow, checked against invariants (tests/sweep_test.py's docstring lists them).",
               "",
               f"- requests: {c['requests']} (regressions replayed first: {c['regressions']}); per endpoint: "
               + ", ".join(f"{k} {v}" for k, v in sorted(c["byEndpoint"].items())),
               "- statuses: " + ", ".join(f"{k}: {v}" for k, v in sorted(c["byStatus"].items())),
               f"- invariants checked: {c['invariantsChecked']}; **violations: {c['violations']}**",
               f"- slowest request: {c['slowest'][0]} s ({c['slowest'][1]})"]
        for v in sweep["failures"]:
            md.append(f"- VIOLATION: `{json.dumps(v)[:400]}`")
        md.append("")
    return "\n".join(md)


def write_doc():
    with open(DOC, "w", encoding="utf-8") as f:
        f.write(render())
    print(f"wrote {os.path.relpath(DOC, ROOT)}")


def doc_current():
    try:
        with open(DOC, encoding="utf-8") as f:
            return f.read() == render()
    except FileNotFoundError:
        return False


# ---- the verbs ----------------------------------------------------------------------------------------
def start(binary):
    from sweep_test import Server  # noqa: E402  (tests/sweep_test.py: effectd on a free port)
    return Server(binary, 600)


def summary(rows, mutations):
    failed, missed = verdicts(rows)
    caught = sum(r["caught"] is True for r in rows)
    text = f"{len(rows) - len(failed)} of {len(rows)} checks pass"
    if mutations:
        text += f"; {caught} of {len(rows)} mutations caught" + (f" ({len(failed)} not tried: their rows fail)" if failed else "")
    for r in failed:
        print(f"FAILED: {r['case']}: {r['seen']}")
    for r in missed:
        print(f"mutation NOT caught: {r['case']}: {r['mutation']}")
    return text, bool(failed or (mutations and missed))


def do_write(binary, effects, args):
    cmd = command_text(["--write"] + [x for e in args.effect or [] for x in ("--effect", e)], binary)
    bad = False
    server = start(binary)
    try:
        for effect in effects:
            t0 = time.monotonic()
            rows = run_effect(server, effect, quick=False, mutations=True)
            quick = run_effect(server, effect, quick=True, mutations=True, echo=False)
            seconds = time.monotonic() - t0
            dump(data_path(effect), {"effect": effect, "measuredAt": measured_at(), "command": cmd,
                                     "regenerationSeconds": round(seconds, 1), "rows": rows, "quick": fingerprint(quick)})
            text, failed = summary(rows + quick, True)
            bad |= failed
            print(f"{effect}: regenerated in {seconds:.1f} s ({len(rows)} rows): wrote docs/stability/{effect}.json", flush=True)
    finally:
        server.stop()
    if set(effects) == set(EFFECTS):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "sweep.json")
            t0 = time.monotonic()
            rc = subprocess.run([sys.executable, os.path.join(ROOT, "tests", "sweep_test.py"), binary, "--requests",
                                 str(SWEEP_REQUESTS), "--seed", "1", "--json", out]).returncode
            seconds = time.monotonic() - t0
            with open(out) as f:
                sweep = json.load(f)
        dump(data_path("sweep"), {"effect": "sweep", "measuredAt": measured_at(), "command": cmd,
                                  "regenerationSeconds": round(seconds, 1), "requests": SWEEP_REQUESTS, **sweep})
        bad |= rc != 0
        print(f"sweep: regenerated in {seconds:.1f} s: wrote docs/stability/sweep.json", flush=True)
    write_doc()
    return bad


def do_current(binary, effects):
    t0 = time.monotonic()
    all_rows, stale_lines = [], []
    server = start(binary)
    try:
        for effect in effects:
            rows = run_effect(server, effect, quick=True, mutations=True)
            all_rows += rows
            line = stale(effect, rows, load(effect), binary)
            if line:
                stale_lines.append(line)
    finally:
        server.stop()
    text, bad = summary(all_rows, True)
    for line in stale_lines:
        print(line)
    if not doc_current():
        print("STALE docs/stability.md: not the rendering of docs/stability/*.json; regenerate: "
              "python3 tests/stability/run.py --render")
        bad = True
    print(f"stability --current: {text}; {len(effects) - len(stale_lines)} of {len(effects)} effects current "
          f"({time.monotonic() - t0:.1f} s)")
    return bad or bool(stale_lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binary", nargs="?", help="the effectd binary (build/server/effectd)")
    ap.add_argument("--effect", action="append", choices=EFFECTS, help="only this effect (repeatable)")
    ap.add_argument("--list", action="store_true", help="the effects and their row counts")
    ap.add_argument("--quick", action="store_true", help="the smaller sizes of the heavy cases")
    ap.add_argument("--mutations", action="store_true", help="feed each row's mutation to its check")
    ap.add_argument("--check", action="store_true", help="exit 1 on a failed row (with --mutations: or a mutation not caught)")
    ap.add_argument("--write", action="store_true", help="measure and write docs/stability/<effect>.json and docs/stability.md")
    ap.add_argument("--current", action="store_true", help="the suite's check: rows, mutations and fingerprints")
    ap.add_argument("--render", action="store_true", help="re-render docs/stability.md from the data files")
    args = ap.parse_args()
    effects = [e for e in EFFECTS if e in (args.effect or EFFECTS)]
    if args.list:
        for e in effects:
            full, quick = effect_module(e).cases(False), effect_module(e).cases(True)
            print(f"{e}: {len(full)} rows" + (f" ({len(quick)} at the quick sizes)" if len(quick) != len(full) else ""))
        print(f"total: {sum(len(effect_module(e).cases(False)) for e in effects)} rows")
        return 0
    if args.render:
        write_doc()
        return 0
    if not args.binary:
        ap.error("BINARY is needed to run rows")
    if args.write:
        return 1 if do_write(args.binary, effects, args) else 0
    if args.current:
        return 1 if do_current(args.binary, effects) else 0
    server = start(args.binary)
    try:
        rows = [r for e in effects for r in run_effect(server, e, args.quick, args.mutations)]
    finally:
        server.stop()
    text, bad = summary(rows, args.mutations)
    print(f"stability: {text}")
    return 1 if args.check and bad else 0


if __name__ == "__main__":
    sys.exit(main())
