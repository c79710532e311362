#!/usr/bin/env python3
"""The glow sheet (docs/rendering.md "The bolt in fog"): examples/09's bolt seen from 3 distances
(rows: the camera at 0.75, 1.5 and 3 times its distance, the same field of view) through GL_EXP
fog of 3 densities (columns 2-4: 0.02, 0.06, 0.15 per unit), beside today's Gaussian glow in clear
air (column 1). Each tile is a /v1/render of a running effectd; its X-Glow header is printed.

    scripts/glow-sheet.py build/server/effectd [docs/glow/sheet.png]
"""
import http.client, json, os, struct, sys, zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
from effectd_process import start  # noqa: E402

from stability.pngio import png_decode  # noqa: E402  (the stability checks' PNG decoder)

TILE = 192
DISTANCES = (0.75, 1.5, 3.0)
DENSITIES = (0.02, 0.06, 0.15)


def png_encode(width, height, rows):
    raw = b"".join(b"\0" + bytes(r) for r in rows)
    chunk = lambda kind, data: struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    binary = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "docs", "glow", "sheet.png")
    base = json.load(open(os.path.join(ROOT, "examples", "09-bolt-3d.json")))
    base["width"] = base["height"] = TILE
    proc, port = start(binary, "--access-log", "0")
    try:
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
        sheet = [[0] * (4 * TILE * 3) for _ in range(3 * TILE)]
        for r, k in enumerate(DISTANCES):
            for c, density in enumerate((None,) + DENSITIES):
                scene = json.loads(json.dumps(base))
                cam = scene["camera"]
                cam["position"] = [t + k * (p - t) for p, t in zip(cam["position"], cam["target"])]
                if density is None:
                    del scene["fog"]
                else:
                    scene["fog"] = {"fog": {"fogType": "GL_EXP", "color": [0.1, 0.1, 0.15], "density": density}}
                conn.request("POST", "/v1/render", json.dumps(scene), {"Content-Type": "application/json"})
                resp = conn.getresponse()
                body = resp.read()
                if resp.status != 200:
                    sys.exit(f"glow-sheet: {resp.status} {body[:300]!r}")
                print(f"distance x{k}, density {density or 'none (clear air)'}: {resp.getheader('X-Glow')}")
                w, h, ch, _, rows = png_decode(body)
                for y in range(h):
                    for x in range(w):
                        for i in range(3):
                            sheet[r * TILE + y][(c * TILE + x) * 3 + i] = round(rows[y][x * ch + i] * 255)
        with open(out, "wb") as f:
            f.write(png_encode(4 * TILE, 3 * TILE, sheet))
        print(f"wrote {out}")
    finally:
        proc.terminate()
        proc.wait()


if __name__ == "__main__":
    main()
