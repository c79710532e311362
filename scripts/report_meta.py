"""Where and when a report's data were measured: the commit (and whether the tree had
uncommitted changes), the date and the machine. Both reports record it in every data file they
write (docs/error-vs-time/<section>.json, docs/stability/<effect>.json); their renderers print it
beside each section, so a reader sees how old a time is. Staleness is decided by behaviour, not
by this (docs/reports.md).

    python3 scripts/report_meta.py        prints it as JSON
"""
import datetime
import json
import os
import platform
import subprocess

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def git(*args):
    return subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True)


def machine():
    model = ""
    try:
        with open("/proc/cpuinfo") as f:
            model = next((line.split(":", 1)[1].strip() for line in f if line.startswith("model name")), "")
    except OSError:
        pass
    return f"{model or platform.processor() or 'unknown CPU'}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def measured_at():
    """{"commit": HEAD, "dirty": uncommitted changes outside docs/, "date": UTC, "machine": ...}."""
    head = git("rev-parse", "HEAD").stdout.strip() or "unknown"
    dirty = bool(git("status", "--porcelain", "--untracked-files=no", "--", ".", ":!docs").stdout.strip())
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return {"commit": head, "dirty": dirty, "date": when, "machine": machine()}


if __name__ == "__main__":
    print(json.dumps(measured_at()))
