"""/v1/render's previews against the CPU reference renderer: the bubble on the sphere's closed-form
silhouette in both, and the preview's colours within 5/255 of the reference's over it, at sizes
from 1e-6 to 1e6 and depth ranges of 1e14. The preview is GPU work (llvmpipe on a machine without
a GPU): its numbers are compared with the looser render tolerance (docs/stability.md)."""
from stability.closed_forms import delta_e, sphere_pixels
from stability.common import Mutation, case, ok_status, statuses
from stability.pngio import png_decode, png_encode, rgb_pixels

RENDER_BOUND = 5 / 255  # mean |preview − reference| per channel over the sphere's pixels
GPU = True  # run.py compares this effect's numbers with the render tolerance


def _geometry(scene):
    disk = sphere_pixels(scene)
    w, h = scene["width"], scene["height"]
    edge = [any(disk[yy * w + xx] != disk[y * w + x] for yy in range(max(0, y - 1), min(h, y + 2))
                for xx in range(max(0, x - 1), min(w, x + 2))) for y in range(h) for x in range(w)]
    inside = [i for i in range(w * h) if disk[i]]
    return disk, edge, inside


def render_matches_reference(scene):
    """Bodies: the preview (/v1/render), the reference (reference: true) and the backdrop alone (the
    scene without its bubble). Silhouette: where each image differs from the backdrop (by 1.5/255 or
    more on a channel) is the sphere's closed-form silhouette, but for pixels on its edge (a 3 × 3
    neighbourhood that straddles it: the mesh's polygon outline). Colour: the mean |preview −
    reference| per channel over the sphere's pixels at most RENDER_BOUND (5/255)."""
    disk, edge, inside = _geometry(scene)
    w, h = scene["width"], scene["height"]

    def check(answers, server):
        if not ok_status(200, answers) or not all(isinstance(a, bytes) for _, a in answers):
            return False, statuses(answers)
        (pw, ph, pre), (rw, rh, ref), (_, _, bg) = (rgb_pixels(a) for _, a in answers)
        if (pw, ph, rw, rh) != (w, h, w, h):
            return False, f"{pw} × {ph} and {rw} × {rh} pixels, {w} × {h} asked for"
        masks = [[max(abs(p - q) for p, q in zip(img[i], bg[i])) >= 1.5 / 255 for i in range(w * h)] for img in (pre, ref)]
        off = [sum(1 for i in range(w * h) if m[i] != disk[i] and not edge[i]) for m in masks]
        apart = sum(1 for a, b in zip(*masks) if a != b)
        mad = sum(abs(p - q) for i in inside for p, q in zip(pre[i], ref[i])) / (3 * len(inside))
        de = sum(delta_e(pre[i], ref[i]) for i in inside) / len(inside)
        ok = off == [0, 0] and 0 < mad <= RENDER_BOUND
        return ok, (f"{len(inside)} pixels in the sphere's silhouette (closed form): preview and reference differ from "
                    f"the backdrop there, off it {off[0]} and {off[1]} pixels away from its edge, {apart} apart (on the "
                    f"edge); mean |preview − reference| {mad * 255:.2f}/255 per channel (bound "
                    f"{RENDER_BOUND * 255:g}), mean ΔE*ab {de:.2f}")
    return check


def _edit(text, fn):
    """A mutation that edits the preview's decoded pixels and encodes them back."""
    def change(answers, server):
        pw, ph, c, depth, rows = png_decode(answers[0][1])
        fn(pw, ph, c, rows)
        answers[0] = (answers[0][0], png_encode(pw, ph, c, depth, rows))
    return Mutation(text, change)


def brighter(scene):
    """The preview's bubble 20 % brighter over the sphere's pixels."""
    _, _, inside = _geometry(scene)

    def fn(pw, ph, c, rows):
        for i in inside:
            y, x = divmod(i, pw)
            rows[y][x * c:x * c + 3] = [min(1.0, 1.2 * v) for v in rows[y][x * c:x * c + 3]]
    return _edit("the preview's bubble ×1.2 brighter", fn)


def shifted(moved):
    def fn(pw, ph, c, rows):
        for r in rows:
            r[moved * c:] = r[:len(r) - moved * c]
    return _edit(f"the preview moved {moved} pixels right", fn)


def bubble_scene(radius=1.0, near=None, far=None, depth=8):
    cam = {"position": [0, 0.3 * radius, 4 * radius], "target": [0, 0, 0], "fovY": 45}
    if near:
        cam.update(near=near, far=far)
    return {"width": 96, "height": 96, "bitDepth": depth, "time": 7, "camera": cam,
            "background": {"gradient": {"top": [0.18, 0.24, 0.2], "bottom": [0.08, 0.1, 0.07]}},
            "environment": {"zenith": [0.35, 0.6, 1.0], "horizon": [1.0, 0.98, 0.95], "ground": [0.16, 0.18, 0.12]},
            "bubble": {"mesh": {"level": 4, "radius": radius}, "film": {"seed": 3}, "features": {"wobble": False}}}


MUST = ("the bubble on the sphere's closed-form silhouette in both (all but its edge pixels); mean |preview − reference| "
        "≤ 5/255 per channel over it (measured 3.2; docs/error-vs-time.md: mean ΔE*ab about 3 for this shading, about 1 "
        "level of 255 per ΔE here; a 1-pixel shift gives 6.2)")


def row(name, scene, mutation):
    backdrop = {k: v for k, v in scene.items() if k != "bubble"}
    return case("render", f"preview against the reference: {name}", "render", [scene, {**scene, "reference": True}, backdrop],
                check=render_matches_reference(scene), must=MUST, mutation=mutation)


def cases(quick):
    small, large = bubble_scene(1e-6, 1e-7, 1e-5, 16), bubble_scene(1e6, 1e5, 1e7)
    deep, plain = bubble_scene(1, 1e-7, 1e7), bubble_scene()
    return [
        row("examples/03's bubble, 96 × 96", plain, mutation=brighter(plain)),
        row("radius 1e-6 seen from 4e-6 (near 1e-7, far 1e-5), 16-bit PNG", small, mutation=shifted(3)),
        row("radius 1e6 seen from 4e6 (near 1e5, far 1e7)", large, mutation=shifted(3)),
        row("radius 1 seen from 4, near 1e-7 and far 1e7 (a depth range of 1e14)", deep, mutation=shifted(3)),
    ]
