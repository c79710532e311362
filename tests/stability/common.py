"""What every effect's stability file shares: the Case a row is, the Mutation fed to its check,
the generic checks (a status, the exact 4xx), the fog and bolt builders and checks that more than
one effect's rows use, and the tolerances.

A check is `check(answers, server) -> (ok, seen)`: answers holds one (status, answer) per request
(answer a dict, or bytes for a PNG); server is the running effectd (its `post(path, body)`), for the
few checks that ask it something more. A mutation's change is `change(wrong, server)`: it edits a
deep copy of the answers in place into a plausible wrong answer, which the row's check must reject.
Nothing here keeps state between rows."""
import copy
import math
import os
import sys
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Callable, Optional

from stability.closed_forms import distances, fog_model, region_of

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests"))  # sweep_test, effectd_process, schema_walk


def frozen(d):
    """A read-only view of a constant dict (copy it with {**d, ...} to change it)."""
    return MappingProxyType(d)


@dataclass(frozen=True)
class Mutation:
    """A plausible wrong answer: `text` says what it is; `change(wrong, server)` makes it from a deep
    copy of the real answers."""
    text: str
    change: Callable[[list, Any], None]

    def apply(self, answers, server):
        wrong = copy.deepcopy(answers)
        self.change(wrong, server)
        return wrong


@dataclass(frozen=True)
class Case:
    """One row: requests (`bodies`, each to `/v1/<endpoint>`, or to its own endpoint where `endpoint`
    is a tuple, one per body), the check that can fail, what must hold (the doc's words) and the
    mutation that the check must reject."""
    effect: str
    name: str
    endpoint: Any  # str, or a tuple with one endpoint per body
    bodies: tuple
    check: Callable[[list, Any], tuple]
    must: str
    mutation: Optional[Mutation]

    def requests(self):
        eps = self.endpoint if isinstance(self.endpoint, tuple) else (self.endpoint,) * len(self.bodies)
        return list(zip(eps, self.bodies))


def case(effect, name, endpoint, body, check, must, mutation):
    """A Case; body is one request body or a list of them."""
    bodies = tuple(body) if isinstance(body, list) else (body,)
    return Case(effect, name, tuple(endpoint) if isinstance(endpoint, list) else endpoint, bodies, check, must, mutation)


# ---- mutations -----------------------------------------------------------------------------------
def off_values(values):
    """The farthest value in (1e-30, 1) made 1 % smaller; where there is none, the first 0 read as 1
    (the naive overflow: d² = ∞ or 0 taken for no fog), else the last 1 read as 0."""
    inside = [i for i, v in enumerate(values) if 1e-30 < v < 1]
    if inside:
        values[inside[-1]] *= 0.99
    elif 0 in values:
        values[values.index(0)] = 1.0
    else:
        values[-1] = 0.0


def _off_samples(answers, server):
    samples = answers[0][1]["samples"]
    values = [x["factor"] for x in samples]
    off_values(values)
    for x, v in zip(samples, values):
        x["factor"] = v


OFF_FACTOR_TEXT = "the farthest f in (0, 1) ×0.99, or a 0 read as 1 (the naive overflow)"
# A `samples` answer's farthest f in (0, 1) 1 % smaller (or a 0 read as 1).
OFF_SAMPLES = Mutation(OFF_FACTOR_TEXT, _off_samples)
# A table's farthest f in (0, 1) 1 % smaller (or a 0 read as 1).
OFF_TABLE = Mutation(OFF_FACTOR_TEXT, lambda answers, server: off_values(answers[0][1]["table"]["factor"]))


def _parent_pointer(answers, server):
    err = answers[0][1]["errors"][0]
    err["pointer"] = err["pointer"].rsplit("/", 1)[0] or "/"


def parent_named(status, pointer):
    """problem(status, pointer)'s mutation: the 4xx naming the parent of the field it should name."""
    return Mutation(f"the {status} naming the parent of {pointer}", _parent_pointer)


def _cell_off(answers, server):
    """The bolt's last cell moved 3 cells along x: off its parent (or out of the grid)."""
    a = answers[0][1]
    c = a["cells"]
    i = len(c) - len(a["grid"])
    c[i] += 3 if c[i] + 3 < a["grid"][0] else -3


CELL_OFF = Mutation("the last cell moved 3 cells along x, off its tree", _cell_off)


# ---- generic checks --------------------------------------------------------------------------------
def ok_status(status, answers):
    return all(s == status for s, _ in answers)


def statuses(answers):
    return "statuses " + ", ".join(str(s) for s, _ in answers)


def near(o, e, tol=2e-6, rel=1e-5):
    """|o − e| within tol, and within rel relative where e is above 1e-30 (so that e^−50 ×1.01 fails)."""
    return abs(o - e) <= tol and (e <= 1e-30 or abs(o / e - 1) <= rel)


def worst(observed, expected):
    return max(abs(o - e) for o, e in zip(observed, expected))


def rel_worst(observed, expected):
    return max((abs(o / e - 1) for o, e in zip(observed, expected) if e > 1e-30), default=0.0)


def message(a):
    return (a.get("errors") or [{}])[0].get("message", "") if isinstance(a, dict) else ""


def problem(status, pointer):
    """The exact 4xx naming `pointer` (its mutation: parent_named(status, pointer))."""
    def check(answers, server):
        s, a = answers[0]
        got = (a.get("errors") or [{}])[0].get("pointer") if isinstance(a, dict) else None
        return s == status and got == pointer, f"{s} at {got}: {message(a)}"
    return check


# ---- fog: request bodies and the checks fog's and the scene's rows share ----------------------------
def fog(f, **extra):
    return {"fog": {"color": [0.7, 0.75, 0.8], **f}, **extra}


HEIGHT = frozen({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0})


def fog_table(expected_f, tol=2e-6):
    """Every entry of a 1-D table against expected_f(d); HEIGHT tables: expected_f(d, dy) (the usual
    mutation: OFF_TABLE)."""
    def check(answers, server):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        t = a["table"]
        f, ds = t["factor"], distances(t)
        if t.get("elevations"):
            rows = t["elevations"]
            exp = [expected_f(d, -1 + 2 * e / (rows - 1)) for e in range(rows) for d in ds]
        else:
            exp = [expected_f(d) for d in ds]
        err, rerr = worst(f, exp), rel_worst(f, exp)
        ok = len(f) == len(exp) and all(near(o, e, tol) for o, e in zip(f, exp))
        return ok, (f"{len(f)} factors in [{min(f):.4g}, {max(f):.4g}]; max |f − closed form| {err:.2g} "
                    f"(relative {rerr:.2g} above 1e-30)")
    return check


def fog_points(name, f, points, must, mutation, camera=(0, 0, 0), regions=None, effect="fog"):
    """A row of `samples`: each point's region, f, and (ATMOSPHERIC or directional) transmittance and
    fog colour against fog_model's closed forms, within 2e-6 and 1e-5 relative above 1e-30 (the
    usual mutation: OFF_SAMPLES)."""
    body = fog(f, samples={"camera": list(camera), "points": points}, include=["samples"])
    if regions:
        body["regions"] = regions
    want = []
    for p in points:
        r = region_of(regions or [], p)
        want.append((r,) + fog_model(body["fog"] if r < 0 else regions[r]["fog"], camera, p))

    def check(answers, server):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}: {message(a)}"
        got = a["samples"]
        bad, errs, rels = [], [0.0], [0.0]
        for i, (x, (r, fe, te, ce)) in enumerate(zip(got, want)):
            pairs = [(x["factor"], fe)]
            if te is not None:
                pairs += list(zip(x.get("transmittance") or [math.nan] * 3, te))
                pairs += list(zip(x.get("fogColor") or [math.nan] * 3, ce))
            errs += [abs(o - e) for o, e in pairs]
            rels += [abs(o / e - 1) for o, e in pairs if e > 1e-30]
            if x["region"] != r or not all(near(o, e) for o, e in pairs):
                bad.append(f"point {i}: region {x['region']} (want {r}), f {x['factor']:.6g} (want {fe:.6g})")
        fs, rs = ", ".join(f"{x['factor']:.4g}" for x in got), ", ".join(str(x["region"]) for x in got)
        seen = (f"f = {fs}" + (f"; regions {rs}" if regions else "")
                + ("; T and fog colour too" if want[0][2] is not None else "")
                + f"; max |Δ| {max(errs):.2g}, relative {max(rels):.2g}")
        ok = len(got) == len(want) and not bad
        return ok, seen if ok else seen + "; " + "; ".join(bad[:3])
    return case(effect, name, "fog", body, check, must, mutation)


# ---- lightning: request bodies and the tree check lightning's and the scene's rows share ------------
def bolt(n, **extra):
    return {"grid": {"width": n, "height": n}, "start": [n // 2, 0], "targets": [[n // 2, n - 1]],
            "include": ["cells", "tree", "stats"], **extra}


def cells_of(a):
    c, dims = a["cells"], len(a["grid"])
    return [tuple(c[i:i + dims]) for i in range(0, len(c), dims)]


def tree_problems(body, a, cells):
    """Every cell inside the grid, none twice, each a neighbour of its parent (2-D or 3-D), the
    tree rooted at the start with parents grown before their children, and the main channel the
    parent chain from the root to a target."""
    grid, tree = a["grid"], a["tree"]
    parent = tree["parent"]
    hood = body.get("neighbourhood", 26 if len(grid) == 3 else 8)
    problems = []
    if len(parent) != len(cells) or not cells or list(cells[0]) != list(body["start"]) or parent[0] != -1:
        problems.append("not a tree rooted at the start")
        return problems
    if any(not all(0 <= c[k] < grid[k] for k in range(len(grid))) for c in cells):
        problems.append("a cell outside the grid")
    if len(set(cells)) != len(cells):
        problems.append("a cell twice")
    for i, q in enumerate(parent[1:], 1):
        if not 0 <= q < i:
            problems.append(f"cell {i}'s parent {q} grew after it")
            break
        d = [abs(cells[i][k] - cells[q][k]) for k in range(len(grid))]
        if max(d) != 1 or (hood in (4, 6) and sum(d) != 1):
            problems.append(f"cell {i} is not a neighbour of its parent")
            break
    main = tree.get("mainChannel")
    if main is not None and (main[0] != 0 or any(parent[m] != p for p, m in zip(main, main[1:]))
                             or list(cells[main[-1]]) not in [list(t) for t in body["targets"]]):
        problems.append("the main channel is not the parent chain from the start to a target")
    return problems
