"""Comparing effectd answers across runs: the fields that differ from run to run (timings,
the per-request id in problems) removed. Used by tests/schema_truth_test.py and
scripts/same-answers.py."""
import re

RUN_FIELDS = re.compile(r"Ms$|^ms$|^requestId$")


def scrub(v):
    """The JSON value v without its run-dependent fields, at any depth."""
    if isinstance(v, dict):
        return {k: scrub(x) for k, x in v.items() if not RUN_FIELDS.search(k)}
    if isinstance(v, list):
        return [scrub(x) for x in v]
    return v
