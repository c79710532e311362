// Served to the test pages as /page_helpers.mjs: what a client computes the same way in each
// of them.

// The sky as effectd's renderer evaluates it (render::skyAt, as scene.json documents it) in
// unit direction d.
export function skyAt(sky, d) {
  const y = d[1];
  const mix = (a, c, w) => a.map((x, i) => x + (c[i] - x) * w);
  return y >= 0 ? mix(sky.horizon, sky.zenith, Math.sqrt(y)) : mix(sky.horizon, sky.ground, Math.sqrt(Math.min(-4 * y, 1)));
}

// The sky's cube map: six faces (+x, -x, +y, -y, +z, -z) of n x n RGBA floats.
export function skyCubeFaces(sky, n) {
  const faces = [];
  for (let face = 0; face < 6; ++face) {
    const px = new Float32Array(n * n * 4);
    for (let j = 0; j < n; ++j)
      for (let i = 0; i < n; ++i) {
        const s1 = (2 * (i + 0.5)) / n - 1, t1 = (2 * (j + 0.5)) / n - 1;
        const d = [[1, -t1, -s1], [-1, -t1, s1], [s1, 1, t1], [s1, -1, -t1], [s1, -t1, 1], [-s1, -t1, -1]][face];
        const l = Math.hypot(...d);
        px.set([...skyAt(sky, d.map((x) => x / l)), 1], (j * n + i) * 4);
      }
    faces.push(px);
  }
  return faces;
}

// The pixels of a size x size RGBA frame inside the disc of radius rPx about its centre (the
// disc is symmetric top to bottom, so a frame read bottom-up selects the same pixels).
function* discPixels(size, rPx) {
  for (let y = 0; y < size; ++y)
    for (let x = 0; x < size; ++x)
      if (Math.hypot(x + 0.5 - size / 2, y + 0.5 - size / 2) <= rPx) yield (y * size + x) * 4;
}

// The share of the disc whose colour has chroma (max - min channel) above 8/255, and its mean.
export function colouredShare(px, size, rPx) {
  let n = 0, coloured = 0;
  const sum = [0, 0, 0];
  for (const i of discPixels(size, rPx)) {
    const c = [px[i], px[i + 1], px[i + 2]];
    ++n, coloured += Math.max(...c) - Math.min(...c) > 8;
    for (let k = 0; k < 3; ++k) sum[k] += c[k];
  }
  return { share: coloured / n, mean: sum.map((s) => s / n) };
}

// CIE L*a*b* (D65) of an 8-bit sRGB colour.
function lab(r8, g8, b8) {
  const lin = (c) => (c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4);
  const [r, g, b] = [r8, g8, b8].map((c) => lin(c / 255));
  const xyz = [(0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047, 0.2126 * r + 0.7152 * g + 0.0722 * b,
               (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883];
  const f = xyz.map((t) => (t > 216 / 24389 ? Math.cbrt(t) : (24389 / 27 * t + 16) / 116));
  return [116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])];
}

// The mean ΔE*ab (CIE76) over the disc between two frames with their rows in the same order.
export function meanDeltaE(px, reference, size, rPx) {
  let sum = 0, n = 0;
  for (const i of discPixels(size, rPx)) {
    const a = lab(px[i], px[i + 1], px[i + 2]), b = lab(reference[i], reference[i + 1], reference[i + 2]);
    sum += Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]), ++n;
  }
  return sum / n;
}

// How much a part of the picture changes the disc: the mean per channel of |on - off| over it,
// with the share coloured either way, and with a `reference` frame (rows in the frames' order)
// the mean ΔE*ab from it either way. setOn(bool) switches the part; frame() renders and reads.
export async function partChange(setOn, frame, size, rPx, reference = null) {
  setOn(true);
  const on = await frame();
  setOn(false);
  const off = await frame();
  let diff = 0, n = 0;
  for (const i of discPixels(size, rPx)) {
    for (let k = 0; k < 3; ++k) diff += Math.abs(on[i + k] - off[i + k]);
    n += 3;
  }
  const out = { change: diff / n, on: colouredShare(on, size, rPx), off: colouredShare(off, size, rPx) };
  if (reference) out.deltaE = { on: meanDeltaE(on, reference, size, rPx), off: meanDeltaE(off, reference, size, rPx) };
  return out;
}

// A size x size RGBA frame with its rows in the other order (GL reads bottom-up, images top-down).
export function flipRows(px, size) {
  const out = new Uint8Array(size * size * 4);
  for (let y = 0; y < size; ++y) out.set(px.subarray((size - 1 - y) * size * 4, (size - y) * size * 4), y * size * 4);
  return out;
}

// The WebGL context's size x size frame as RGBA bytes, rows from the top.
export function readTopDown(gl, size) {
  const px = new Uint8Array(size * size * 4);
  gl.readPixels(0, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE, px);
  return flipRows(px, size);
}

// 1 per pixel whose largest channel is above 48/255 (lit), else 0.
export function litMask(px, size) {
  const m = new Uint8Array(size * size);
  for (let i = 0; i < size * size; ++i) m[i] = Math.max(px[4 * i], px[4 * i + 1], px[4 * i + 2]) > 48;
  return m;
}

// Of mask a's lit pixels, how many have a lit pixel of mask b within one pixel: {lit, share}.
export function foundWithinAPixel(a, b, size) {
  const near = (x, y) => {
    for (let dy = -1; dy <= 1; ++dy)
      for (let dx = -1; dx <= 1; ++dx) {
        const u = x + dx, v = y + dy;
        if (u >= 0 && v >= 0 && u < size && v < size && b[v * size + u]) return true;
      }
    return false;
  };
  let n = 0, hit = 0;
  for (let y = 0; y < size; ++y) for (let x = 0; x < size; ++x) if (a[y * size + x]) ++n, hit += near(x, y);
  return { lit: n, share: hit / Math.max(n, 1) };
}
