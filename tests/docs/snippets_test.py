#!/usr/bin/env python3
"""Every documented curl runs as written, offline, and every answer a page shows is the real one.

    snippets_test.py <effectd binary> <repository root>

Reads the shell blocks of the README, docs/*.md, docs/using/*.md and the clients' READMEs. Each
command that calls `localhost:8080` runs as written in bash from the repository root (files
such as `-d @proto/examples/...` resolve there; `-o` writes into a scratch folder), against a
live effectd on loopback, with the port rewritten. It must exit 0 and its answer must be a 2xx,
except in a block that shows a `$ curl` and its problem: there the status shown must come back.
A comment under a command that shows JSON (`# {...}` or `# ... "key":value, ... ...`) is the
answer as the page claims it: each key shown must have that value in the real answer (numbers
to 1e-6 relative). Only loopback is reached: nothing here needs a network.
"""
import json
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from effectd_process import start  # noqa: E402  (effectd on a free port)

PAGES = ["README.md", "clients/three/README.md", "clients/godot/README.md"]


def pages(root):
    out = list(PAGES)
    for folder in ("docs", "docs/using"):
        out += sorted(os.path.join(folder, f) for f in os.listdir(os.path.join(root, folder)) if f.endswith(".md"))
    return out


def commands(block, assigned):
    """(command, shown answer or None, the block's assignments before it) per curl of a shell
    block: continued lines joined (a trailing backslash, or a quote still open), the comment
    lines right after it as what the page says it answers. `assigned` carries a page's shell
    variables (r=..., u=...) from block to block."""
    lines, out, i = block.split("\n"), [], 0
    while i < len(lines):
        line = lines[i]
        if "localhost:8080" not in line:
            if re.match(r"^[a-z_]+=", line):
                assigned.append(line)
            i += 1
            continue
        cmd = line
        while (cmd.rstrip().endswith("\\") or cmd.count("'") % 2) and i + 1 < len(lines):
            i += 1
            cmd = cmd.rstrip().removesuffix("\\") + " " + lines[i] if cmd.rstrip().endswith("\\") else cmd + "\n" + lines[i]
        shown = []
        while i + 1 < len(lines) and lines[i + 1].startswith("# ") and re.search(r'[{"]', lines[i + 1]):
            i += 1
            shown.append(lines[i][2:])
        out.append((cmd, " ".join(shown) or None, "\n".join(assigned)))
        i += 1
    return out


def claimed(text):
    """The keys and values a shown answer claims: a whole JSON object, or fragments between '...'."""
    text = text.strip()
    try:
        return json.loads(text)
    except ValueError:
        pass
    inner = text.replace("...", "").strip().strip(",").strip()
    return json.loads("{" + inner + "}")


def same(want, got, where):
    if isinstance(want, dict):
        if not isinstance(got, dict):
            return [f"{where}: {got!r} is not an object"]
        bad = []
        for k, v in want.items():
            bad += same(v, got.get(k), f"{where}/{k}") if k in got else [f"{where}/{k}: missing"]
        return bad
    if isinstance(want, list):
        if not isinstance(got, list) or len(got) != len(want):
            return [f"{where}: {got!r} is not {want!r}"]
        return [b for k, (w, g) in enumerate(zip(want, got)) for b in same(w, g, f"{where}/{k}")]
    if isinstance(want, float) or isinstance(got, float):
        ok = isinstance(got, (int, float)) and abs(got - want) <= 1e-6 * max(1.0, abs(want))
        return [] if ok else [f"{where}: {got!r}, the page says {want!r}"]
    return [] if want == got else [f"{where}: {got!r}, the page says {want!r}"]


def main():
    binary, root = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    scratch = tempfile.mkdtemp(prefix="effectd-snippets-")
    keys = os.path.join(scratch, "keys.txt")  # docs/serving.md signs with the first line of keys.txt
    with open(keys, "w") as f:
        f.write("a-signing-key-for-the-docs-0123\n")
    # A page that signs URLs runs against a server with that key; every other against a plain one.
    plain, plainPort = start(binary, "--access-log", "0")
    signing, signingPort = start(binary, "--access-log", "0", "--url-signing-key-file", keys)
    failures, ran = [], 0
    try:
        for page in pages(root):
            text = open(os.path.join(root, page), encoding="utf-8").read()
            assigned = []
            for block in re.findall(r"```(?:sh|bash|console)\n(.*?)```", text, re.S):
                port = signingPort if "keys.txt" in block else plainPort
                problem_shown = re.search(r'^\$ curl.*\n\{"detail".*?"status":(\d+)', block, re.S | re.M)
                for cmd, shown, prefix in commands(block, assigned):
                    run = (prefix + "\n" + cmd.lstrip("$ ")).replace("localhost:8080", f"127.0.0.1:{port}")
                    run = run.replace("keys.txt", keys)
                    # Files the command writes go to the scratch folder; the status is appended.
                    run = re.sub(r"-o (\S+)", lambda m: f"-o {scratch}/{os.path.basename(m.group(1))}", run)
                    run = run.replace("curl -s", f"curl -s -w '\\n%{{http_code}}'", 1)
                    r = subprocess.run(["bash", "-c", run], cwd=root, capture_output=True, text=True, timeout=120)
                    ran += 1
                    where = f"{page}: {cmd.splitlines()[0][:90]}"
                    body, _, status = r.stdout.rpartition("\n")
                    want = int(problem_shown.group(1)) if problem_shown and "$ curl" in cmd else None
                    if r.returncode != 0 and "| head" not in cmd:
                        failures.append(f"{where}: exit {r.returncode} {r.stderr[:200]}")
                        continue
                    if want is not None and status.strip() != str(want):
                        failures.append(f"{where}: status {status!r}, the page shows {want}")
                    elif want is None and "| head" not in cmd and not status.strip().startswith("2"):
                        failures.append(f"{where}: status {status!r}: {body[:200]}")
                    if shown:
                        try:
                            bad = same(claimed(shown), json.loads(body), "")
                        except ValueError as e:
                            bad = [f"the shown answer or the body is not JSON: {e}"]
                        failures += [f"{where}: {b}" for b in bad]
                    print(f"{'ok  ' if not failures or not failures[-1].startswith(where) else 'FAIL'} {where}")
    finally:
        for p in (plain, signing):
            p.terminate()
            p.wait()
    for f in failures:
        print("FAIL", f)
    print(f"{ran} documented commands run, {len(failures)} failures")
    if ran < 20:
        print("FAIL fewer than 20 documented commands found: the extraction is broken")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
