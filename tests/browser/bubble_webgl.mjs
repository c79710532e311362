// The proof that a browser client gets the picture the preview shows: headless chromium
// (Debian's, WebGL2 on SwiftShader) draws the soap-film bubble from /v1/bubble's own mesh,
// GLSL ES 3.00, uniforms, thin-film table and thickness texture, with the draw order and blend
// functions the answer names, and the result is compared with /v1/render of the same scene.
// The page builds what a client builds itself: the camera matrices, the backdrop colour and
// the sky's cube map (render::skyAt, as scene.json documents it).
// Usage: node bubble_webgl.mjs EFFECTD_BINARY [CHROMIUM]
import fs from 'node:fs';
import { launchWebGl2Chromium } from './chromium.mjs';
import { servePages } from './page_server.mjs';
import { check, results, startEffectd } from '../node/effectd.mjs';

const [binary, chromium = '/usr/bin/chromium'] = process.argv.slice(2);

const { origin, close: closePages } = await servePages('effectd bubble in WebGL2', ['gl', 'png']);
const { url: api, process: server } = await startEffectd(binary, ['--cors-origins', origin]);

const browser = await launchWebGl2Chromium(chromium);
try {
  const page = await browser.newPage();
  page.on('console', (m) => console.log(`  page: ${m.text()}`));
  await page.goto(`${origin}/`);
  const r = await page.evaluate(async (api) => {
    const out = {};
    try {
      const size = 128, time = 3;
      const eye = [0, 0.3, 4], target = [0, 0, 0], fovY = 45;
      const backdrop = [0.1, 0.12, 0.1, 1];
      const sky = { zenith: [0.35, 0.6, 1.0], horizon: [1.0, 0.98, 0.95], ground: [0.16, 0.18, 0.12] };
      const bubble = { mesh: { level: 4 }, features: { wobble: false } };
      const json = { 'Content-Type': 'application/json' };
      const post = (route, body) => fetch(`${api}${route}`, { method: 'POST', headers: json, body: JSON.stringify(body) });

      // The preview.
      const scene = { width: size, height: size, time, camera: { position: eye, target, fovY },
                      background: { color: backdrop }, environment: sky, bubble };
      const png = await post('/v1/render', scene);
      out.render = png.status;
      const bitmap = await createImageBitmap(await png.blob());
      const c2 = document.getElementById('png');
      c2.width = c2.height = size;
      const ctx = c2.getContext('2d');
      ctx.drawImage(bitmap, 0, 0);
      const expected = ctx.getImageData(0, 0, size, size).data;

      // The service's own data for the same bubble.
      const res = await post('/v1/bubble', { ...bubble, time, thinFilm: { encoding: 'rgba16f' }, film: { encoding: 'r32f' },
                                              include: ['mesh', 'uniforms', 'shader', 'thinFilm', 'thickness'] });
      out.bubble = res.status;
      const b = await res.json();
      const bytes = (s) => Uint8Array.from(atob(s), (ch) => ch.charCodeAt(0));

      const canvas = document.getElementById('gl');
      canvas.width = canvas.height = size;
      const gl = canvas.getContext('webgl2', { antialias: false, premultipliedAlpha: true, preserveDrawingBuffer: true });
      if (!gl) throw new Error('no WebGL2');
      const info = gl.getExtension('WEBGL_debug_renderer_info');
      out.renderer = info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);

      // Program.
      const compile = (type, src) => {
        const s = gl.createShader(type);
        gl.shaderSource(s, src);
        gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
        return s;
      };
      const prog = gl.createProgram();
      gl.attachShader(prog, compile(gl.VERTEX_SHADER, b.shader.vertex));
      gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, b.shader.fragment));
      gl.linkProgram(prog);
      if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
      gl.useProgram(prog);

      // Mesh: one buffer per attribute, at the locations the answer lists.
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      const attribute = { aPosition: [b.mesh.positions, 3], aNormal: [b.mesh.normals, 3], aUv: [b.mesh.uvs, 2] };
      b.shader.attributes.forEach((name, location) => {
        const [data, n] = attribute[name];
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
        gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(data), gl.STATIC_DRAW);
        gl.enableVertexAttribArray(location);
        gl.vertexAttribPointer(location, n, gl.FLOAT, false, 0, 0);
      });
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(b.mesh.indices), gl.STATIC_DRAW);

      // Camera: glm::lookAt and glm::perspective (column-major).
      const sub = (a, c) => a.map((x, i) => x - c[i]);
      const cross = (a, c) => [a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2], a[0] * c[1] - a[1] * c[0]];
      const dot = (a, c) => a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
      const norm = (a) => a.map((x) => x / Math.hypot(...a));
      const f = norm(sub(target, eye)), s = norm(cross(f, [0, 1, 0])), u = cross(s, f);
      const view = [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0, -dot(s, eye), -dot(u, eye), dot(f, eye), 1];
      const near = 0.05, far = 1000, t = 1 / Math.tan((fovY * Math.PI) / 360);
      const proj = [t, 0, 0, 0, 0, t, 0, 0, 0, 0, -(far + near) / (far - near), -1, 0, 0, -(2 * far * near) / (far - near), 0];
      const mul = (a, c) => {
        const m = new Array(16).fill(0);
        for (let col = 0; col < 4; ++col)
          for (let row = 0; row < 4; ++row)
            for (let k = 0; k < 4; ++k) m[col * 4 + row] += a[k * 4 + row] * c[col * 4 + k];
        return m;
      };
      const at = (name) => gl.getUniformLocation(prog, name);
      gl.uniformMatrix4fv(at('uModel'), false, [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
      gl.uniformMatrix4fv(at('uViewProjection'), false, mul(proj, view));
      gl.uniform3fv(at('uCameraPosition'), eye);

      // The CPU-owned uniforms exactly as the answer gives them.
      const ints = new Set(['uPass', 'uLightCount']);
      for (const [name, value] of Object.entries(b.uniforms)) {
        const flat = [value].flat(2);
        if (ints.has(name)) gl.uniform1i(at(name), value);
        else if (Array.isArray(value) && Array.isArray(value[0])) gl.uniform3fv(at(name), flat);
        else if (Array.isArray(value) && value.length === 2) gl.uniform2fv(at(name), flat);
        else if (Array.isArray(value)) gl.uniform1fv(at(name), flat);
        else gl.uniform1f(at(name), value);
      }

      const texture = (unit, kind) => {
        gl.activeTexture(gl.TEXTURE0 + unit);
        const tex = gl.createTexture();
        gl.bindTexture(kind, tex);
        gl.texParameteri(kind, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
        gl.texParameteri(kind, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
        return tex;
      };
      // The sky's cube map, as the renderer's environment pass evaluates it (render::skyAt).
      texture(0, gl.TEXTURE_CUBE_MAP);
      const n = 256;
      const { skyCubeFaces } = await import('/page_helpers.mjs');
      skyCubeFaces(sky, n).forEach((px, face) =>
        gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, gl.RGBA16F, n, n, 0, gl.RGBA, gl.FLOAT, px));
      gl.uniform1i(at('uEnvironment'), 0);
      // The thin-film table (RGBA16F as sent) and the thickness texture (nm).
      texture(2, gl.TEXTURE_2D);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA16F, b.thinFilm.width, b.thinFilm.height, 0, gl.RGBA, gl.HALF_FLOAT,
                    new Uint16Array(bytes(b.thinFilm.data).buffer));
      gl.uniform1i(at('uThinFilm'), 2);
      texture(3, gl.TEXTURE_2D);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.R16F, b.thickness.width, b.thickness.height, 0, gl.RED, gl.FLOAT,
                    new Float32Array(bytes(b.thickness.data).buffer));
      gl.uniform1i(at('uThicknessField'), 3);

      // Backdrop, then the draws the answer names: far side, near side, each transmittance then reflection.
      gl.viewport(0, 0, size, size);
      gl.clearColor(...backdrop);
      gl.clear(gl.COLOR_BUFFER_BIT);
      gl.enable(gl.BLEND);
      gl.enable(gl.CULL_FACE);
      out.draw = b.shader.draw;
      for (const cull of [gl.FRONT, gl.BACK]) {
        gl.cullFace(cull);
        gl.uniform1i(at('uPass'), 0);
        gl.blendFuncSeparate(gl.ZERO, gl.SRC_COLOR, gl.ZERO, gl.SRC_ALPHA);
        gl.drawElements(gl.TRIANGLES, b.mesh.indices.length, gl.UNSIGNED_INT, 0);
        gl.uniform1i(at('uPass'), 1);
        gl.blendFunc(gl.ONE, gl.ONE);
        gl.drawElements(gl.TRIANGLES, b.mesh.indices.length, gl.UNSIGNED_INT, 0);
      }
      out.glError = gl.getError();
      const got = new Uint8Array(size * size * 4);
      gl.readPixels(0, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE, got);

      // Compare (WebGL rows from the bottom, the PNG's from the top), over the bubble's pixels.
      let sum = 0, count = 0, worst = 0, over = 0, changed = 0;
      const diffs = [];
      for (let y = 0; y < size; ++y)
        for (let x = 0; x < size; ++x) {
          const a = (y * size + x) * 4, g = ((size - 1 - y) * size + x) * 4;
          let d = 0, fromBackdrop = 0;
          for (let k = 0; k < 3; ++k) {
            d = Math.max(d, Math.abs(expected[a + k] - got[g + k]));
            fromBackdrop = Math.max(fromBackdrop, Math.abs(expected[a + k] - Math.round(backdrop[k] * 255)));
          }
          if (fromBackdrop <= 2) continue;  // outside the bubble (or where it shows nothing)
          ++changed;
          sum += d, ++count, worst = Math.max(worst, d), over += d > 12;
          diffs.push(d);
        }
      diffs.sort((p, q) => p - q);
      out.picture = canvas.toDataURL('image/png');

      // Every GLSL ES 3.00 variant the service hands out compiles and links in this browser:
      // the paper model's 64 feature sets and the film's 16.
      const sets = [];
      const paper = ['reflection', 'refraction', 'rim', 'textureFlow', 'wobble', 'iridescence'];
      for (let m = 0; m < 64; ++m) sets.push({ shading: 'paper', features: Object.fromEntries(paper.map((k, i) => [k, !!(m & (1 << i))])) });
      const film = ['wobble', 'thickness', 'backFace', 'highlight'];
      for (let m = 0; m < 16; ++m) sets.push({ shading: 'film', features: Object.fromEntries(film.map((k, i) => [k, !!(m & (1 << i))])) });
      out.variants = 0;
      out.variantFailures = [];
      for (const set of sets) {
        const v = await (await post('/v1/bubble', { ...set, include: ['shader'] })).json();
        const p = gl.createProgram();
        try {
          gl.attachShader(p, compile(gl.VERTEX_SHADER, v.shader.vertex));
          gl.attachShader(p, compile(gl.FRAGMENT_SHADER, v.shader.fragment));
          gl.linkProgram(p);
          if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
          ++out.variants;
        } catch (e) {
          out.variantFailures.push(`${JSON.stringify(set)}: ${e.message}`);
        }
      }
      Object.assign(out, { pixels: count, mean: sum / Math.max(1, count), p99: diffs[Math.floor(0.99 * (diffs.length - 1))],
                           worst, over, changed });
    } catch (e) {
      out.error = `${e.name}: ${e.message}`;
    }
    return out;
  }, api);

  check(!r.error, 'the page drew the bubble from the service\'s data', r.error);
  check(r.render === 200 && r.bubble === 200, '/v1/render and /v1/bubble answered', [r.render, r.bubble]);
  check(/SwiftShader|swiftshader/i.test(r.renderer ?? ''), `WebGL2 on ${r.renderer}`, r.renderer);
  check(r.glError === 0, 'no GL error', r.glError);
  check(r.variants === 80, `${r.variants} of 80 GLSL ES variants compile and link in the browser`, r.variantFailures);
  check(r.pixels > 3000, `the bubble covers ${r.pixels} pixels of the preview`, r.pixels);
  check(r.mean < 2.0, `mean difference ${r.mean?.toFixed(2)}/255 over the bubble (tolerance 2)`, r);
  check(r.p99 <= 12, `99th percentile ${r.p99}/255 (tolerance 12)`, r);
  console.log(`  browser vs preview: mean ${r.mean?.toFixed(3)}, p99 ${r.p99}, worst ${r.worst}, over 12: ${r.over} of ${r.pixels}`);
  if (process.env.EFFECTD_WEBGL_PNG && r.picture)  // the browser's frame, to look at
    fs.writeFileSync(process.env.EFFECTD_WEBGL_PNG, Buffer.from(r.picture.split(',')[1], 'base64'));
} finally {
  await browser.close();
  server.kill('SIGTERM');
  closePages();
}
console.log(results.failures ? `${results.failures} check(s) failed` : 'all WebGL2 checks passed');
process.exit(results.failures ? 1 : 0);
