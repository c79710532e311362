"""The stability report as tests: one file per effect (fog.py, lightning.py, bubble.py, tangents.py,
scene.py, render.py, glow.py), each with cases(quick) returning its rows (common.Case: named fields,
each row's mutation beside it); run.py runs them against effectd, writes docs/stability/<effect>.json
and renders docs/stability.md. See run.py's docstring."""
