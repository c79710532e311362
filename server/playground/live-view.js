// The live WebGL2 view: each effect drawn in this browser from the service's own answer, the
// way a game client would draw it.
//   lightning  the polylines as glowing ribbons; with a timeline, the strike played as
//              docs/effects.md §1 says a client plays it (leader, return stroke, re-strikes)
//   fog        the preview's scene (its quads, camera and backdrop) fogged per pixel from the
//              answer's table
//   bubble     the answer's mesh with its own GLSL ES 3.00, uniforms, thin-film table and
//              thickness texture, in the draw order and blend the answer names
//   tangents   the mesh with each vertex's tangent (red), bitangent (green) and normal (blue)
// Drag to turn the 3-D views.

const bytesOf = (b64) => Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));

// Column-major 4x4 matrices, as glm builds them.
const sub = (a, b) => a.map((x, i) => x - b[i]);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const normalize = (a) => a.map((x) => x / (Math.hypot(...a) || 1));
function lookAt(eye, target) {
  const f = normalize(sub(target, eye)), s = normalize(cross(f, [0, 1, 0])), u = cross(s, f);
  return [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0, -dot(s, eye), -dot(u, eye), dot(f, eye), 1];
}
function perspective(fovY, near, far) {
  const t = 1 / Math.tan((fovY * Math.PI) / 360);
  return [t, 0, 0, 0, 0, t, 0, 0, 0, 0, -(far + near) / (far - near), -1, 0, 0, -(2 * far * near) / (far - near), 0];
}
function multiply(a, b) {
  const m = new Array(16).fill(0);
  for (let c = 0; c < 4; ++c)
    for (let r = 0; r < 4; ++r)
      for (let k = 0; k < 4; ++k) m[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return m;
}

// Linear interpolation in keyframes (t ascending), clamped at both ends.
function sample(ts, vs, t) {
  if (t <= ts[0]) return vs[0];
  if (t >= ts[ts.length - 1]) return vs[vs.length - 1];
  let lo = 0, hi = ts.length - 1;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (ts[mid] <= t) lo = mid; else hi = mid;
  }
  const w = (t - ts[lo]) / (ts[hi] - ts[lo] || 1);
  return vs[lo] + (vs[hi] - vs[lo]) * w;
}

// Sky colour by direction, as scene.json documents the renderer's environment (render::skyAt).
const SKY = { zenith: [0.35, 0.6, 1.0], horizon: [1.0, 0.98, 0.95], ground: [0.16, 0.18, 0.12] };
function skyAt(d) {
  const mix = (a, b, w) => a.map((x, i) => x + (b[i] - x) * w);
  return d[1] >= 0 ? mix(SKY.horizon, SKY.zenith, Math.sqrt(d[1])) : mix(SKY.horizon, SKY.ground, Math.sqrt(Math.min(-4 * d[1], 1)));
}

const BOLT_VS = `#version 300 es
in vec2 aPosition; in vec2 aAcross; in float aSide; in float aBrightness; in float aWidth;
uniform vec2 uScale; uniform float uWidthScale;
out float vSide; out float vBrightness;
void main() {
  vSide = aSide; vBrightness = aBrightness;
  gl_Position = vec4((aPosition + aAcross * aSide * aWidth * uWidthScale) * uScale, 0.0, 1.0);
}`;
const BOLT_FS = `#version 300 es
precision highp float;
in float vSide; in float vBrightness; uniform float uFalloff; uniform float uGain; uniform vec3 uColor;
out vec4 color;
void main() {
  float a = exp(-uFalloff * vSide * vSide) * vBrightness * uGain;
  color = vec4(mix(uColor, vec3(1.0), clamp(a - 0.6, 0.0, 1.0)) * a, 1.0);
}`;

// The fog scene is the preview's (its quads, camera and backdrop), each fragment fogged from the
// answer's table by its distance (and, with elevations, its ray's direction y), composed as the
// renderer does: colour * f + S.
const FOG_VS = `#version 300 es
in vec3 aPosition; in vec3 aColor; uniform mat4 uViewProjection; out vec3 vWorld; out vec3 vColor;
void main() { vWorld = aPosition; vColor = aColor; gl_Position = uViewProjection * vec4(aPosition, 1.0); }`;
const FOG_FS = `#version 300 es
precision highp float;
in vec3 vWorld; in vec3 vColor;
uniform sampler2D uTable; uniform vec2 uRange; uniform vec2 uTexels; uniform float uRows;
uniform float uCutoff; uniform vec3 uEye;
out vec4 color;
void main() {
  vec3 ray = vWorld - uEye;
  float d = length(ray);
  vec4 fog = vec4(0.0, 0.0, 0.0, 1.0);
  if (d < uCutoff) {
    float R = uRange.y;
    float u = clamp((min(d, R) - uRange.x) / (R - uRange.x), 0.0, 1.0);
    float v = uRows > 1.0 ? (ray.y / max(d, 1e-6) + 1.0) * 0.5 : 0.5;
    fog = texture(uTable, vec2((u * (uTexels.x - 1.0) + 0.5) / uTexels.x, (v * (uTexels.y - 1.0) + 0.5) / uTexels.y));
  }
  color = vec4(vColor * fog.a + fog.rgb, 1.0);
}`;

// Two triangles per quad, its corners as the renderer places them (scene.json's quads: normal
// towards the viewer, up, size, colour).
function quadTriangles(quads) {
  const position = [], colour = [];
  for (const q of quads) {
    const n = normalize(q.normal || [0, 0, 1]);
    let up = q.up || [0, 1, 0];
    up = sub(up, n.map((x) => x * dot(up, n)));
    if (Math.hypot(...up) < 1e-9) up = Math.abs(n[1]) < 0.9 ? sub([0, 1, 0], n.map((x) => x * n[1])) : sub([1, 0, 0], n.map((x) => x * n[0]));
    up = normalize(up).map((x) => x * 0.5 * q.size[1]);
    const right = normalize(cross(up, n)).map((x) => x * 0.5 * q.size[0]);
    const corner = (a, b) => q.center.map((c, k) => c + a * right[k] + b * up[k]);
    for (const [a, b] of [[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]]) {
      position.push(...corner(a, b));
      colour.push(...(q.color || [0.5, 0.5, 0.5]));
    }
  }
  return { position: new Float32Array(position), colour: new Float32Array(colour) };
}

const MESH_VS = `#version 300 es
in vec3 aPosition; in vec3 aColor; uniform mat4 uViewProjection; out vec3 vColor;
void main() { vColor = aColor; gl_Position = uViewProjection * vec4(aPosition, 1.0); }`;
const MESH_FS = `#version 300 es
precision highp float; in vec3 vColor; out vec4 color; void main() { color = vec4(vColor, 1.0); }`;

export class LiveView {
  constructor(canvas, player) {
    this.canvas = canvas;
    this.player = player;  // {box, play, scrub, clock}
    this.gl = canvas.getContext('webgl2', { antialias: true, preserveDrawingBuffer: true });
    this.programs = new Map();
    this.resources = [];
    this.yaw = 0.6;
    this.pitch = 0.25;
    this.playing = false;
    this.t = 0;
    this.last = performance.now();
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      this.yaw += (e.clientX - drag[0]) * 0.01;
      this.pitch = Math.max(-1.4, Math.min(1.4, this.pitch + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY];
      this.dirty = true;
    });
    player.play.addEventListener('click', () => {
      this.playing = !this.playing;
      player.play.textContent = this.playing ? 'pause' : 'play';
    });
    player.scrub.addEventListener('input', () => {
      this.t = (player.scrub.value / 1000) * (this.duration || 0);
      this.playing = false;
      player.play.textContent = 'play';
      this.dirty = true;
    });
    const tick = (now) => {
      const dt = (now - this.last) / 1000;
      this.last = now;
      if (this.draw && this.duration && this.playing) {
        // Strikes last a second or two of game time; play at that speed, with a pause to loop.
        this.t = (this.t + dt) % (this.duration + 0.5);
        this.player.scrub.value = Math.min(1000, (this.t / this.duration) * 1000);
        this.dirty = true;
      }
      if (this.draw && this.dirty) {
        this.dirty = false;
        this.draw();
      }
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }

  program(vs, fs) {
    const key = vs + fs;
    if (this.programs.has(key)) return this.programs.get(key);
    const gl = this.gl;
    const compile = (type, src) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`shader: ${gl.getShaderInfoLog(s)}`);
      return s;
    };
    const p = gl.createProgram();
    gl.attachShader(p, compile(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, compile(gl.FRAGMENT_SHADER, fs));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`link: ${gl.getProgramInfoLog(p)}`);
    this.programs.set(key, p);
    return p;
  }

  // Drops the last effect's buffers and textures and stops its animation.
  reset() {
    const gl = this.gl;
    for (const r of this.resources) {
      if (r instanceof WebGLBuffer) gl.deleteBuffer(r);
      else if (r instanceof WebGLTexture) gl.deleteTexture(r);
      else if (r instanceof WebGLVertexArrayObject) gl.deleteVertexArray(r);
    }
    this.resources = [];
    this.boltBuffers = [];
    this.draw = null;
    this.duration = 0;
    this.player.box.hidden = true;
    gl.disable(gl.BLEND);
    gl.disable(gl.CULL_FACE);
    gl.disable(gl.DEPTH_TEST);
    gl.depthMask(true);
  }

  clear() {
    this.reset();
    const gl = this.gl;
    gl.viewport(0, 0, this.canvas.width, this.canvas.height);
    gl.clearColor(0, 0, 0, 1);
    gl.clear(gl.COLOR_BUFFER_BIT);
  }

  buffer(target, data) {
    const gl = this.gl, b = gl.createBuffer();
    gl.bindBuffer(target, b);
    gl.bufferData(target, data, gl.STATIC_DRAW);
    this.resources.push(b);
    return b;
  }

  attribute(prog, name, data, size) {
    const gl = this.gl, loc = gl.getAttribLocation(prog, name);
    const b = this.buffer(gl.ARRAY_BUFFER, data);
    if (loc >= 0) {
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0);
    }
    return b;
  }

  texture(unit, kind) {
    const gl = this.gl, tex = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(kind, tex);
    gl.texParameteri(kind, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(kind, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(kind, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(kind, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    this.resources.push(tex);
    return tex;
  }

  // An orbit camera around `center` at `distance`, turned by dragging.
  orbit(center, distance, fovY = 45) {
    const eye = [center[0] + distance * Math.cos(this.pitch) * Math.sin(this.yaw), center[1] + distance * Math.sin(this.pitch),
                 center[2] + distance * Math.cos(this.pitch) * Math.cos(this.yaw)];
    return { eye, viewProjection: multiply(perspective(fovY, distance * 0.01, distance * 100), lookAt(eye, center)) };
  }

  // answer: /v1/lightning with polylines (and a timeline when it has one). A 2-D bolt is drawn
  // in its grid; a 3-D one (grid [w, h, d], points x, y, z) through the orbit camera, its
  // ribbons rebuilt from the projected points whenever the view changes.
  showLightning(answer) {
    this.reset();
    const gl = this.gl, prog = this.program(BOLT_VS, BOLT_FS);
    const volume = answer.grid.length === 3;
    const dims = volume ? 3 : 2;
    const lines = answer.polylines || [];
    const timeline = answer.timeline;
    const first = [];  // each polyline's first vertex in the flat vertex list
    let vertices = 0;
    for (const line of lines) first.push(vertices), vertices += line.points.length / dims;
    let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity], widest = 0;
    for (const line of lines) {
      widest = Math.max(widest, line.width);
      for (let i = 0; i < line.points.length; i += dims)
        for (let k = 0; k < dims; ++k) lo[k] = Math.min(lo[k], line.points[i + k]), hi[k] = Math.max(hi[k], line.points[i + k]);
    }
    const [w, h] = answer.grid;
    const center = lo.map((x, k) => (x + hi[k]) / 2), size = Math.hypot(...sub(hi.slice(0, dims), lo.slice(0, dims))) || 1;
    // Points to the plane the ribbons are built in: grid cells from the centre (y down) in 2-D,
    // normalised device coordinates in 3-D.
    const flat2d = (p, i) => [p[i] - w / 2, p[i + 1] - h / 2];
    const vertexOf = [];
    let vao = null, bright = null, count = 0, perQuad = new Float32Array(0);
    const build = (project, widthOf) => {
      const pos = [], across = [], side = [], width = [];
      vertexOf.length = 0;
      lines.forEach((line, li) => {
        const p = line.points, n = p.length / dims;
        const wl = widthOf(line.width);
        for (let i = 0; i + 1 < n; ++i) {
          const a = project(p, i * dims), b = project(p, (i + 1) * dims);
          if (!a || !b) continue;
          const len = Math.hypot(b[0] - a[0], b[1] - a[1]) || 1, nx = -(b[1] - a[1]) / len, ny = (b[0] - a[0]) / len;
          // Extend each segment by half a width so joints close.
          const ex = ((b[0] - a[0]) / len) * wl * 0.5, ey = ((b[1] - a[1]) / len) * wl * 0.5;
          const A = [a[0] - ex, a[1] - ey], B = [b[0] + ex, b[1] + ey];
          for (const [q, sd, v] of [[A, -1, i], [B, -1, i + 1], [B, 1, i + 1], [A, -1, i], [B, 1, i + 1], [A, 1, i]]) {
            pos.push(q[0], q[1]);
            across.push(nx, ny);
            side.push(sd);
            width.push(wl);
            vertexOf.push(first[li] + v);
          }
        }
      });
      // The previous projection's buffers go (a 3-D view rebuilds on every draw).
      const old = new Set([vao, ...(this.boltBuffers || [])]);
      for (const r of old) if (r) r instanceof WebGLVertexArrayObject ? gl.deleteVertexArray(r) : gl.deleteBuffer(r);
      this.resources = this.resources.filter((r) => !old.has(r));
      vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      perQuad = new Float32Array(vertexOf.length);
      this.boltBuffers = [this.attribute(prog, 'aPosition', new Float32Array(pos), 2), this.attribute(prog, 'aAcross', new Float32Array(across), 2),
                          this.attribute(prog, 'aSide', new Float32Array(side), 1), this.attribute(prog, 'aWidth', new Float32Array(width), 1)];
      bright = this.attribute(prog, 'aBrightness', perQuad, 1);
      this.boltBuffers.push(bright);
      this.resources.push(vao);
      gl.bindVertexArray(null);
      count = vertexOf.length;
    };
    if (!volume) build(flat2d, (x) => x);

    const brightness = new Float32Array(vertices);
    const k = timeline && timeline.keyframes;
    const light = (t) => {
      lines.forEach((line, li) => {
        const tl = timeline && timeline.polylines[li];
        const channel = line.channel === 'main' ? k && k.main : k && k.branches;
        for (let i = 0; i < line.intensity.length; ++i) {
          let b = 1;
          if (tl) {  // docs/effects.md §1: how a client plays the strike
            const leader = tl.leader[i], delay = tl.strokeDelay[i];
            if (t < leader || leader > timeline.connect) b = 0;
            else if (t < timeline.connect + delay) b = sample(k.t, k.leader, t);
            else b = sample(k.t, channel, t - delay);
          }
          brightness[first[li] + i] = b * line.intensity[i];
        }
      });
      for (let i = 0; i < vertexOf.length; ++i) perQuad[i] = brightness[vertexOf[i]];
      gl.bindBuffer(gl.ARRAY_BUFFER, bright);
      gl.bufferSubData(gl.ARRAY_BUFFER, 0, perQuad);
    };
    if (timeline) {  // a new bolt waits, lit as at its first stroke, until played
      this.duration = timeline.duration;
      this.t = this.playing ? Math.min(this.t, this.duration) : timeline.strokes[0].t;
      this.player.scrub.value = (this.t / this.duration) * 1000;
      this.player.box.hidden = false;
    }
    const scale = 1.9 / Math.max(w, h);
    this.draw = () => {
      if (volume) {  // project through the orbit camera; the widest line is 3 px at the middle
        const { viewProjection: m } = this.orbit(center, size * 1.3);
        const px = 2 / this.canvas.width;
        build((p, i) => {
          const x = p[i], y = p[i + 1], z = p[i + 2];
          const cw = m[3] * x + m[7] * y + m[11] * z + m[15];
          if (cw < 1e-3 * size) return null;
          return [(m[0] * x + m[4] * y + m[8] * z + m[12]) / cw, (m[1] * x + m[5] * y + m[9] * z + m[13]) / cw];
        }, (lw) => (lw / (widest || 1)) * 3 * px / 0.45);
      }
      light(timeline ? this.t : 0);
      if (timeline) this.player.clock.textContent = `${(this.t * 1000).toFixed(1)} ms of ${(this.duration * 1000).toFixed(0)} ms`;
      gl.viewport(0, 0, this.canvas.width, this.canvas.height);
      gl.clearColor(0.03, 0.03, 0.07, 1);
      gl.clear(gl.COLOR_BUFFER_BIT);
      gl.useProgram(prog);
      gl.bindVertexArray(vao);
      gl.uniform2f(gl.getUniformLocation(prog, 'uScale'), volume ? 1 : scale, volume ? 1 : -scale);
      gl.uniform3f(gl.getUniformLocation(prog, 'uColor'), 0.55, 0.65, 1.0);
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.ONE, gl.ONE);
      for (const [widthScale, falloff, gain] of [[4, 3, 0.1], [0.45, 3, 1.8]]) {  // glow, then core
        gl.uniform1f(gl.getUniformLocation(prog, 'uWidthScale'), widthScale);
        gl.uniform1f(gl.getUniformLocation(prog, 'uFalloff'), falloff);
        gl.uniform1f(gl.getUniformLocation(prog, 'uGain'), gain);
        gl.drawArrays(gl.TRIANGLES, 0, count);
      }
      gl.bindVertexArray(null);
    };
    this.dirty = true;
  }

  // answer: /v1/fog with an rgba16f table.
  showFog(answer, stage) {
    this.reset();
    const table = answer.table;
    if (!table || table.encoding !== 'rgba16f') throw new Error('the answer has no rgba16f table');
    const gl = this.gl, prog = this.program(FOG_VS, FOG_FS);
    let cols = table.size, rows = table.elevations || 1;
    let texels = new Uint16Array(bytesOf(table.data).buffer);
    const max = gl.getParameter(gl.MAX_TEXTURE_SIZE);
    if (cols > max || rows > max) {  // keep every k-th entry so the table fits a texture
      const kc = Math.ceil(cols / max), kr = Math.ceil(rows / max);
      const c2 = Math.ceil(cols / kc), r2 = Math.ceil(rows / kr), out = new Uint16Array(c2 * r2 * 4);
      for (let r = 0; r < r2; ++r)
        for (let c = 0; c < c2; ++c) out.set(texels.subarray(((r * kr) * cols + c * kc) * 4, ((r * kr) * cols + c * kc) * 4 + 4), (r * c2 + c) * 4);
      texels = out, cols = c2, rows = r2;
    }
    const vao = gl.createVertexArray();
    this.resources.push(vao);
    gl.bindVertexArray(vao);
    const { position, colour } = quadTriangles(stage.quads);
    this.attribute(prog, 'aPosition', position, 3);
    this.attribute(prog, 'aColor', colour, 3);
    gl.bindVertexArray(null);
    this.texture(0, gl.TEXTURE_2D);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA16F, cols, rows, 0, gl.RGBA, gl.HALF_FLOAT, texels);
    const { position: eye, target, fovY } = stage.camera;
    this.draw = () => {
      // The preview's camera; dragging turns it about the vertical through the eye.
      const turn = this.yaw - 0.6, look = sub(target, eye);
      const turned = [Math.cos(turn) * look[0] + Math.sin(turn) * look[2], look[1], -Math.sin(turn) * look[0] + Math.cos(turn) * look[2]];
      const viewProjection = multiply(perspective(fovY, 0.05, 1000), lookAt(eye, eye.map((x, k) => x + turned[k])));
      gl.viewport(0, 0, this.canvas.width, this.canvas.height);
      gl.clearColor(...stage.background.color.slice(0, 3), 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      gl.enable(gl.DEPTH_TEST);
      gl.useProgram(prog);
      gl.bindVertexArray(vao);
      gl.activeTexture(gl.TEXTURE0);
      const at = (n) => gl.getUniformLocation(prog, n);
      gl.uniformMatrix4fv(at('uViewProjection'), false, viewProjection);
      gl.uniform3fv(at('uEye'), eye);
      gl.uniform1i(at('uTable'), 0);
      gl.uniform2f(at('uRange'), table.range[0], table.range[1]);
      gl.uniform2f(at('uTexels'), cols, rows);
      gl.uniform1f(at('uRows'), rows);
      gl.uniform1f(at('uCutoff'), table.cutoffDistance ?? 1e38);
      gl.drawArrays(gl.TRIANGLES, 0, position.length / 3);
      gl.bindVertexArray(null);
      gl.disable(gl.DEPTH_TEST);
    };
    this.dirty = true;
  }

  // answer: /v1/bubble with mesh, uniforms, shader (GLSL ES 3.00), thinFilm (rgba16f) and
  // thickness (r32f) for the film model; mesh, uniforms and shader for the paper's.
  showBubble(answer) {
    this.reset();
    const gl = this.gl, b = answer, prog = this.program(b.shader.vertex, b.shader.fragment);
    const vao = gl.createVertexArray();
    this.resources.push(vao);
    gl.bindVertexArray(vao);
    const attribute = { aPosition: [b.mesh.positions, 3], aNormal: [b.mesh.normals, 3], aUv: [b.mesh.uvs, 2] };
    b.shader.attributes.forEach((name) => this.attribute(prog, name, new Float32Array(attribute[name][0]), attribute[name][1]));
    this.buffer(gl.ELEMENT_ARRAY_BUFFER, new Uint32Array(b.mesh.indices));
    gl.bindVertexArray(null);

    // The sky's cube map.
    this.texture(0, gl.TEXTURE_CUBE_MAP);
    const n = 64;
    for (let face = 0; face < 6; ++face) {
      const px = new Float32Array(n * n * 4);
      for (let j = 0; j < n; ++j)
        for (let i = 0; i < n; ++i) {
          const s = (2 * (i + 0.5)) / n - 1, t = (2 * (j + 0.5)) / n - 1;
          const dir = normalize([[1, -t, -s], [-1, -t, s], [s, 1, t], [s, -1, -t], [s, -t, 1], [-s, -t, -1]][face]);
          px.set([...skyAt(dir), 1], (j * n + i) * 4);
        }
      gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, gl.RGBA16F, n, n, 0, gl.RGBA, gl.FLOAT, px);
    }
    // The paper's flow texture (eqn 9): a soft pattern, as the renderer's default.
    this.texture(1, gl.TEXTURE_2D);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.REPEAT);
    const flow = new Uint8Array(64 * 64 * 4);
    for (let y = 0; y < 64; ++y)
      for (let x = 0; x < 64; ++x) {
        const v = 0.8 + 0.2 * Math.sin((x / 64) * 6 * Math.PI + 2 * Math.sin((y / 64) * 4 * Math.PI));
        flow.set([v * 255, (0.9 + 0.1 * Math.cos((y / 64) * 8 * Math.PI)) * 255, 255, 255], (y * 64 + x) * 4);
      }
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 64, 64, 0, gl.RGBA, gl.UNSIGNED_BYTE, flow);
    if (b.thinFilm) {
      this.texture(2, gl.TEXTURE_2D);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA16F, b.thinFilm.width, b.thinFilm.height, 0, gl.RGBA, gl.HALF_FLOAT,
                    new Uint16Array(bytesOf(b.thinFilm.data).buffer));
    }
    if (b.thickness) {
      this.texture(3, gl.TEXTURE_2D);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.R16F, b.thickness.width, b.thickness.height, 0, gl.RED, gl.FLOAT,
                    new Float32Array(bytesOf(b.thickness.data).buffer));
    }
    const film = /uPass/.test(b.shader.fragment);
    const ints = new Set(['uPass', 'uLightCount']);
    const count = b.mesh.indices.length;
    this.draw = () => {
      const { eye, viewProjection } = this.orbit([0, 0, 0], 4);
      gl.viewport(0, 0, this.canvas.width, this.canvas.height);
      gl.clearColor(0.1, 0.12, 0.1, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      gl.useProgram(prog);
      gl.bindVertexArray(vao);
      const at = (name) => gl.getUniformLocation(prog, name);
      gl.uniformMatrix4fv(at('uModel'), false, [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
      gl.uniformMatrix4fv(at('uViewProjection'), false, viewProjection);
      gl.uniform3fv(at('uCameraPosition'), eye);
      gl.uniform4f(at('uBaseColor'), 1, 1, 1, 1);
      for (const [name, value] of Object.entries(b.uniforms || {})) {
        const flat = [value].flat(2);
        if (ints.has(name)) gl.uniform1i(at(name), value);
        else if (Array.isArray(value) && Array.isArray(value[0])) gl.uniform3fv(at(name), flat);
        else if (Array.isArray(value) && value.length === 2) gl.uniform2fv(at(name), flat);
        else if (Array.isArray(value)) gl.uniform1fv(at(name), flat);
        else gl.uniform1f(at(name), value);
      }
      gl.uniform1i(at('uEnvironment'), 0);
      gl.uniform1i(at('uFlowTexture'), 1);
      gl.uniform1i(at('uThinFilm'), 2);
      gl.uniform1i(at('uThicknessField'), 3);
      gl.enable(gl.BLEND);
      gl.enable(gl.CULL_FACE);
      if (film) {  // far side, then near side; each transmittance, then reflection
        for (const cull of [gl.FRONT, gl.BACK]) {
          gl.cullFace(cull);
          gl.uniform1i(at('uPass'), 0);
          gl.blendFuncSeparate(gl.ZERO, gl.SRC_COLOR, gl.ZERO, gl.SRC_ALPHA);
          gl.drawElements(gl.TRIANGLES, count, gl.UNSIGNED_INT, 0);
          gl.uniform1i(at('uPass'), 1);
          gl.blendFunc(gl.ONE, gl.ONE);
          gl.drawElements(gl.TRIANGLES, count, gl.UNSIGNED_INT, 0);
        }
      } else {  // the paper's model: front faces, alpha blended
        gl.cullFace(gl.BACK);
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
        gl.drawElements(gl.TRIANGLES, count, gl.UNSIGNED_INT, 0);
      }
      gl.bindVertexArray(null);
    };
    this.dirty = true;
  }

  // mesh: {positions, normals (optional), tangents (xyzw per vertex), indices}.
  showTangents(mesh) {
    this.reset();
    const gl = this.gl, prog = this.program(MESH_VS, MESH_FS);
    const P = mesh.positions, T = mesh.tangents, I = mesh.indices, nv = P.length / 3;
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < nv; ++i)
      for (let k = 0; k < 3; ++k) lo[k] = Math.min(lo[k], P[3 * i + k]), hi[k] = Math.max(hi[k], P[3 * i + k]);
    const center = lo.map((x, k) => (x + hi[k]) / 2), size = Math.hypot(...sub(hi, lo)) || 1;
    // Vertex normals: the mesh's own, else area-weighted from the faces.
    let N = mesh.normals;
    if (!N) {
      N = new Float32Array(nv * 3);
      for (let f = 0; f + 2 < I.length; f += 3) {
        const [a, b, c] = [I[f], I[f + 1], I[f + 2]];
        const pa = P.slice(3 * a, 3 * a + 3), pb = P.slice(3 * b, 3 * b + 3), pc = P.slice(3 * c, 3 * c + 3);
        const fn = cross(sub(pb, pa), sub(pc, pa));
        for (const v of [a, b, c]) for (let k = 0; k < 3; ++k) N[3 * v + k] += fn[k];
      }
    }
    const tri = [], triColor = [], lines = [], lineColor = [];
    const light = normalize([0.4, 0.8, 0.5]);
    for (let f = 0; f + 2 < I.length; f += 3) {
      const v = [I[f], I[f + 1], I[f + 2]].map((i) => P.slice(3 * i, 3 * i + 3));
      const fn = normalize(cross(sub(v[1], v[0]), sub(v[2], v[0])));
      const shade = 0.25 + 0.35 * Math.abs(dot(fn, light));
      for (const p of v) tri.push(...p), triColor.push(shade, shade, shade * 1.05);
    }
    const len = size * 0.06;
    for (let i = 0; i < nv; ++i) {
      const p = P.slice(3 * i, 3 * i + 3), n = normalize(N.slice(3 * i, 3 * i + 3)), t = T.slice(4 * i, 4 * i + 3);
      const bt = cross(n, t).map((x) => x * (T[4 * i + 3] < 0 ? -1 : 1));
      for (const [d, c] of [[t, [1, 0.25, 0.2]], [bt, [0.3, 1, 0.3]], [n, [0.35, 0.5, 1]]]) {
        lines.push(...p, ...p.map((x, k) => x + d[k] * len));
        lineColor.push(...c, ...c);
      }
    }
    const vaos = [[tri, triColor], [lines, lineColor]].map(([p, c]) => {
      const vao = gl.createVertexArray();
      this.resources.push(vao);
      gl.bindVertexArray(vao);
      this.attribute(prog, 'aPosition', new Float32Array(p), 3);
      this.attribute(prog, 'aColor', new Float32Array(c), 3);
      gl.bindVertexArray(null);
      return [vao, p.length / 3];
    });
    this.draw = () => {
      const { viewProjection } = this.orbit(center, size * 1.4);
      gl.viewport(0, 0, this.canvas.width, this.canvas.height);
      gl.clearColor(0.08, 0.09, 0.11, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      gl.enable(gl.DEPTH_TEST);
      gl.useProgram(prog);
      gl.uniformMatrix4fv(gl.getUniformLocation(prog, 'uViewProjection'), false, viewProjection);
      gl.bindVertexArray(vaos[0][0]);
      gl.drawArrays(gl.TRIANGLES, 0, vaos[0][1]);
      gl.bindVertexArray(vaos[1][0]);
      gl.drawArrays(gl.LINES, 0, vaos[1][1]);
      gl.bindVertexArray(null);
    };
    this.dirty = true;
  }
}
