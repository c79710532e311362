"""/v1/scene's stiff case: a scene of a stiff fog, a bolt at η 50 and a bubble of radius 1e-6 at
t = 1e9, each part equal to what its own endpoint answers for the same body."""
from stability.common import (HEIGHT, OFF_SAMPLES, Mutation, bolt, case, cells_of, fog_points, ok_status, statuses,
                              tree_problems)


def scene_parts(scene_body, parts, fog_check):
    """The scene's answer holds exactly the parts asked for, each equal (as parsed JSON) to the
    standalone endpoint's answer for the same body; the fog part also against its closed form, the
    bolt a connected tree to its target. Its mutation: scene_bubble_nudged(scene_body)."""
    def check(answers, server):
        if not ok_status(200, answers):
            return False, statuses(answers)
        scene = answers[0][1]
        probs = [] if set(scene) == set(parts) else [f"parts {sorted(scene)}, asked for {sorted(parts)}"]
        probs += [f"the scene's {p} differs from /v1/{p}'s" for p, (_, a) in zip(parts, answers[1:]) if scene.get(p) != a]
        ok_fog, seen_fog = fog_check([(200, scene.get("fog", {}))], server)
        if not ok_fog:
            probs.append("fog against its closed form: " + seen_fog)
        probs += tree_problems(scene_body["lightning"], scene["lightning"], cells_of(scene["lightning"]))
        m = scene["bubble"]["mesh"]
        seen = (f"fog, lightning ({len(cells_of(scene['lightning']))} cells) and bubble ({len(m['positions']) // 3} "
                f"vertices) equal to /v1/fog's, /v1/lightning's and /v1/bubble's; fog: {seen_fog}")
        return not probs, seen if not probs else "; ".join(probs[:3])
    return check


def scene_bubble_nudged(scene_body):
    radius = scene_body["bubble"]["mesh"]["radius"]

    def nudge(answers, server):
        answers[0][1]["bubble"]["mesh"]["positions"][0] += 1e-6 * radius
    return Mutation("the scene's bubble: one vertex nudged by 1e-6 of its radius", nudge)


def cases(quick):
    fr = fog_points("", {**HEIGHT, "density": 1e300, "heightFalloff": 1e300},
                    [[3e-300, 5e-300, 0], [3e-300, -3e-300, 0], [5e-300, 1e-300, 0]], "", camera=(0, 1e-300, 0),
                    mutation=OFF_SAMPLES)
    scene = {"fog": fr.bodies[0], "lightning": {**bolt(48, eta=50, seed=7), "include": ["cells", "tree"]},
             "bubble": {"time": 1e9, "mesh": {"level": 2, "radius": 1e-6}, "include": ["mesh"]}}
    parts = ["fog", "lightning", "bubble"]
    return [case("scene", "fog 1e300 over 5e-300, bolt at η 50, bubble of radius 1e-6 at t = 1e9", ["scene"] + parts,
                 [scene] + [scene[p] for p in parts], check=scene_parts(scene, parts, fr.check),
                 must="each part of the scene's answer equal (as parsed JSON) to its endpoint's answer for the same body; "
                 "the fog's f = height_f (0.64, 2e-11, 0.16); the bolt a connected tree to its target",
                 mutation=scene_bubble_nudged(scene))]
