"""Lightning's stiff and extreme cases: bolts checked cell by cell (a tree rooted at the start, each
cell a grid neighbour of its parent, the target reached), invariances between methods, lengths
and η, and the exact 4xx. Most rows' mutation moves the bolt's last cell off its tree (CELL_OFF)."""
import math

from stability.common import (CELL_OFF, Mutation, bolt, case, cells_of, ok_status, parent_named, problem, statuses,
                              tree_problems)


# ---- request bodies ------------------------------------------------------------------------------
def channel(width, length, seed, **extra):
    return {"grid": {"width": width, "height": length}, "start": [width // 2, 0], "targets": [[width // 2, length - 1]],
            "method": "dbm", "seed": seed, "include": ["stats"], **extra}


def tube(length, seed):
    return {"grid": {"width": 3, "height": 3, "depth": length}, "start": [1, 1, 0], "targets": [[1, 1, length - 1]],
            "method": "dbm", "neighbourhood": 6, "seed": seed, "include": ["stats"]}


def walled(n):
    rects = [[n // 2 - 2, n // 2 - 2, 5, 1], [n // 2 - 2, n // 2 + 2, 5, 1], [n // 2 - 2, n // 2 - 2, 1, 5],
             [n // 2 + 2, n // 2 - 2, 1, 5]]
    return {"grid": {"width": n, "height": n}, "start": [n // 2, 0], "targets": [[n // 2, n // 2]],
            "obstacles": {"rects": rects}}


def corridor(n):
    rows = [{"y": y, "runs": [[0, n // 2], [n // 2 + 1, n - n // 2 - 1]]} for y in range(n)]
    return {"grid": {"width": n, "height": n}, "start": [n // 2, 0], "targets": [[n // 2, n - 1]],
            "obstacles": {"rows": rows}, "method": "dbm", "include": ["cells", "tree", "stats"]}


# ---- checks --------------------------------------------------------------------------------------
def bolt_ok(body, pred=None):
    """Inside the grid, a tree rooted at the start, each cell next to its parent, the target reached;
    then pred(answer). The usual mutation: CELL_OFF."""
    def check(answers, server):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        cells = cells_of(a)
        problems = tree_problems(body, a, cells)
        if tuple(body["targets"][-1]) not in cells:
            problems.append("target not reached")
        seen = "; ".join(problems) or f"{len(cells)} cells, a connected tree, the target reached"
        ok2, seen2 = pred(a) if pred else (True, "")
        return not problems and ok2, seen + ("; " + seen2 if seen2 else "")
    return check


def bolts_equal(bodies, text):
    """Every bolt a tree rooted at the start that reaches the target, and all the same, cell for cell."""
    def check(answers, server):
        if not ok_status(200, answers):
            return False, statuses(answers)
        probs = [p for b, (_, a) in zip(bodies, answers) for p in tree_problems(b, a, cells_of(a))]
        probs += ["target not reached" for b, (_, a) in zip(bodies, answers) if tuple(b["targets"][-1]) not in cells_of(a)]
        same = all(a["cells"] == answers[0][1]["cells"] for _, a in answers[1:])
        return not probs and same, (probs[0] if probs else f"{len(cells_of(answers[0][1]))} cells, a connected tree; "
                                    + (text if same else "NOT " + text))
    return check


def per_row(lengths_seeds, tol=0.12, filled=None):
    """Invariance along a channel: cells per row (cells / length) the same at every length (its
    mutation: longest_fuller(lengths_seeds))."""
    def check(answers, server):
        if not ok_status(200, answers):
            return False, statuses(answers)
        by_length = {}
        for (length, _), (_, a) in zip(lengths_seeds, answers):
            by_length.setdefault(length, []).append(a["stats"]["counters"]["cells"] / length)
        means = {L: sum(v) / len(v) for L, v in by_length.items()}
        short, long_ = means[min(means)], means[max(means)]
        ratio = long_ / short
        ok = abs(ratio - 1) <= tol and (filled is None or long_ < filled)
        stages = max(a["stats"]["counters"].get("deepestStage", 0) for _, a in answers)
        return ok, (f"cells per row {short:.3f} at length {min(means)}, {long_:.3f} at {max(means)} (ratio {ratio:.3f}; "
                    f"deepest stage {stages:g})")
    return check


def same_fill(runs):
    """Cells per row at eta 1e-6 against eta 0, per length (its mutation: tiny_eta_thinner(runs))."""
    def check(answers, server):
        if not ok_status(200, answers):
            return False, statuses(answers)
        sums = {}
        for (length, eta, _), (_, a) in zip(runs, answers):
            sums.setdefault((length, eta), []).append(a["stats"]["counters"]["cells"] / length)
        seen, ok = [], True
        for length in sorted({L for L, _, _ in runs}):
            zero = sum(sums[(length, 0)]) / len(sums[(length, 0)])
            tiny = sum(sums[(length, 1e-6)]) / len(sums[(length, 1e-6)])
            ok = ok and abs(tiny / zero - 1) <= 0.05
            seen.append(f"length {length}: {zero:.3f} at η 0, {tiny:.3f} at η 1e-6")
        return ok, "; ".join(seen)
    return check


# ---- mutations -----------------------------------------------------------------------------------
def scale_cells(answers, runs, pick, k):
    for run, (_, a) in zip(runs, answers):
        if pick(run):
            a["stats"]["counters"]["cells"] *= k


def longest_fuller(lengths_seeds):
    longest = max(L for L, _ in lengths_seeds)
    return Mutation("the longest bolts 25 % fuller (the far field lost: growth fills behind the tip)",
                    lambda answers, server: scale_cells(answers, lengths_seeds, lambda r: r[0] == longest, 1.25))


def tiny_eta_thinner(runs):
    return Mutation("the η 1e-6 bolts 10 % thinner (underflowed candidates never drawn)",
                    lambda answers, server: scale_cells(answers, runs, lambda r: r[1] == 1e-6, 0.9))


def side_branch(answers, server):
    """Ten cells grown sideways from the fast bolt's middle cell, each a child of the one before."""
    a = answers[0][1]
    cells, parent = a["cells"], a["tree"]["parent"]
    n = len(cells) // 2
    x, y = cells[n // 2 * 2], cells[n // 2 * 2 + 1]
    for k in range(1, 11):
        cells += [x + k if x + 10 < a["grid"][0] else x - k, y]
        parent.append(n // 2 if k == 1 else n + k - 2)


def regrown(body, text):
    """A mutation that asks the server for the bolt a plausible mistake would give."""
    def change(answers, server):
        s, a, _ = server.post("/v1/lightning", body)
        answers[0] = (s, a if isinstance(a, dict) else {})
    return Mutation(text, change)


def residual_up(answers, server):
    c = answers[0][1]["stats"]["counters"]
    c.update(residual=100 * c["residual"])


def cases(quick):
    channel_long = 512 if quick else 4096  # 3 x 65536 (the grid limit) would take about 25 min a bolt
    seeds_long = 1 if quick else 2
    charges_power = 5.2 * 2 ** 0.7 * (64 / 128) ** 0.2  # the calibration's law (docs/effects.md §1.3)
    uniform = [bolt(64, eta=0, method=m) for m in ("fast", "dbm", "charges")]
    charges_pair = [bolt(64, method="charges"), bolt(64, method="charges", variant="paper", eta=charges_power)]
    big = bolt(1024 if quick else 4096)
    tight = bolt(48, method="dbm", solver="mgpcg", tolerance=1e-12)
    loose = bolt(48, method="dbm", solver="mgpcg", tolerance=0.1)
    cube = {"grid": {"width": 64, "height": 64, "depth": 64}, "start": [32, 0, 32], "targets": [[32, 63, 32]],
            "include": ["cells", "tree", "stats"]}
    out = [
        case("lightning", "η = 0 (uniform growth), 64², fast, dbm and charges", "lightning", uniform,
             check=bolts_equal(uniform, "the same bolt from fast, dbm and charges"),
             must="η = 0 weighs every candidate alike whatever the field (0⁰ = 1, even where Φ underflows): the three "
             "methods grow the same bolt, cell for cell, a connected tree inside the grid that reaches the target",
             mutation=CELL_OFF),
        case("lightning", "η = 50, 64², fast and dbm", "lightning", [bolt(64, eta=50), bolt(64, eta=50, method="dbm")],
             check=lambda answers, server: (
                 ok_status(200, answers) and all(len(cells_of(a)) <= 70 and not tree_problems(bolt(64), a, cells_of(a))
                                                 for _, a in answers),
                 "cells " + ", ".join(str(len(cells_of(a))) for _, a in answers) + " (64 is the straight line)"),
             must="weights in log space: an almost straight bolt (≤ 70 cells, a tree rooted at the start) from both methods",
             mutation=Mutation("a 10-cell side branch on the fast bolt (η weakened)", side_branch)),
        case("lightning", "3 × 3 grid, start next to the target", "lightning",
             {"grid": {"width": 3, "height": 3}, "start": [1, 0], "targets": [[1, 1]], "include": ["cells"]},
             check=lambda answers, server: (answers[0][0] == 200 and answers[0][1]["cells"] == [1, 0, 1, 1],
                                            f"cells {answers[0][1].get('cells')}"),
             must="the bolt is exactly the two cells",
             mutation=Mutation("the second cell one step diagonal of the target",
                               lambda answers, server: answers[0][1]["cells"].__setitem__(2, 0))),
        case("lightning", f"{1024 if quick else 4096}², fast", "lightning", big, check=bolt_ok(big),
             must="a connected tree that reaches the target", mutation=CELL_OFF),
        case("lightning", "walled-in target", "lightning", walled(32), check=problem(422, "/targets/0"),
             must="A* proves it unreachable first: a 422 naming the target", mutation=parent_named(422, "/targets/0")),
        case("lightning", "one-cell corridor, dbm", "lightning", corridor(48),
             check=lambda answers, server: (answers[0][0] == 200 and cells_of(answers[0][1]) == [(24, y) for y in range(48)]
                                            and not tree_problems(corridor(48), answers[0][1], cells_of(answers[0][1])),
                                            f"{len(cells_of(answers[0][1]))} cells"),
             must="the bolt is the corridor, cell for cell: x = 24, y = 0 … 47 in order, a tree",
             mutation=Mutation("the last cell missing (a bolt one short)",
                               lambda answers, server: answers[0][1]["cells"].__delitem__(slice(-2, None)))),
        case("lightning", "dbm at tolerance 1e-12 (its limit), 48²", "lightning", tight,
             check=bolt_ok(tight, lambda a: (a["stats"]["counters"]["residual"] <= 1e-12,
                                             f"residual {a['stats']['counters']['residual']:.2g}")),
             must="the relative residual reached ≤ 1e-12; a connected tree to the target",
             mutation=Mutation("the residual ×100 (a solve stopped early)", residual_up)),
        case("lightning", "dbm at tolerance 0.1 (its limit), 48²", "lightning", loose, check=bolt_ok(loose),
             must="a loose solve still grows a connected tree to the target", mutation=CELL_OFF),
        case("lightning", "charges, 64², η 2", "lightning", charges_pair,
             check=bolts_equal(charges_pair, f"the paper variant's bolt at η = {charges_power:.4f}"),
             must=f"a connected tree, the same cell for cell as the paper variant's (power = η) at η = "
             f"5.2·2^0.7·(64/128)^0.2 = {charges_power:.4f} with the same seed: the calibration's power law ran",
             mutation=regrown(bolt(64, method="charges", variant="paper"), "the bolt at power η = 2 (the calibration not applied)")),
        case("lightning", "3-D, fast, 64³", "lightning", cube, check=bolt_ok(cube),
             must="a connected 26-neighbour tree that reaches the target", mutation=CELL_OFF),
    ]
    for width in (3, 5, 7, 9):
        runs = [(64, s) for s in range(1, 5)] + [(channel_long, s) for s in range(1, seeds_long + 1)]
        out.append(case("lightning", f"dbm in a {width}-wide channel, length 64 and {channel_long}", "lightning",
                        [channel(width, L, s) for L, s in runs], check=per_row(runs, filled=0.5 * width),
                        must="cells per row independent of the length (±12 %), the channel not filled: the field ahead of "
                        "the bolt (down to 1e-" + str(int(math.pi * channel_long / (width + 1) / math.log(10))) +
                        ") resolved by DeepField", mutation=longest_fuller(runs)))
    eden = [(length, eta, s) for length in (64, 600) for eta in (0, 1e-6) for s in (1, 2, 3)]
    out.append(case("lightning", "dbm at η = 1e-6 against η = 0 in a 3-wide channel, length 64 and 600", "lightning",
                    [channel(3, L, s, eta=eta) for L, eta, s in eden], check=same_fill(eden),
                    must="η → 0 is uniform growth: the same cells per row as η 0 (±5 %), every candidate weighed, even "
                    "where its potential underflows", mutation=tiny_eta_thinner(eden)))
    tube_runs = [(48, s) for s in range(1, 5)] + [(240 if quick else 960, s) for s in range(1, 3)]
    out.append(case("lightning", f"3-D dbm in a 3 × 3 tube, length 48 and {tube_runs[-1][0]}", "lightning",
                    [tube(L, s) for L, s in tube_runs], check=per_row(tube_runs, filled=3.0),
                    must="voxels per unit length independent of the length (±12 %), under 3 of the tube's 9 per slice",
                    mutation=longest_fuller(tube_runs)))
    return out
