// REACT3D scene viewer: plain WebGL2, no dependencies, so one HTML file works offline.
// Reads window.REACT3D_SCENE (built by react3d_core.viewer.payload.scene_payload).
(function () {
  "use strict";
  const P = window.REACT3D_SCENE;
  const canvas = document.getElementById("r3d-canvas");
  const gl = canvas.getContext("webgl2", { preserveDrawingBuffer: true, antialias: true });
  const status = document.getElementById("r3d-status");
  if (!gl) { status.textContent = "WebGL2 is not available in this browser."; return; }

  // ---------- small matrix library (column-major, like GL) ----------
  const M = {
    ident() { const m = new Float32Array(16); m[0] = m[5] = m[10] = m[15] = 1; return m; },
    mul(a, b) {
      const o = new Float32Array(16);
      for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) {
        let s = 0; for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k]; o[c * 4 + r] = s;
      }
      return o;
    },
    persp(fovy, aspect, n, f) {
      const t = 1 / Math.tan(fovy / 2), o = new Float32Array(16);
      o[0] = t / aspect; o[5] = t; o[10] = (f + n) / (n - f); o[11] = -1; o[14] = 2 * f * n / (n - f); return o;
    },
    lookAt(e, c, u) {
      let z = norm(sub(e, c)), x = norm(cross(u, z)), y = cross(z, x);
      const o = M.ident();
      o[0] = x[0]; o[4] = x[1]; o[8] = x[2];
      o[1] = y[0]; o[5] = y[1]; o[9] = y[2];
      o[2] = z[0]; o[6] = z[1]; o[10] = z[2];
      o[12] = -dot(x, e); o[13] = -dot(y, e); o[14] = -dot(z, e); return o;
    },
    apply(m, p) {
      const w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
      return [(m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12]) / w,
              (m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13]) / w,
              (m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14]) / w];
    },
  };
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function add(a, b) { return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]; }
  function scl(a, s) { return [a[0] * s, a[1] * s, a[2] * s]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function norm(a) { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }

  // Joint transform: revolute x' = R(a,q)(x-o)+o, prismatic x' = x + q a (same as Articulation.transform).
  function jointMatrix(j, q) {
    const m = M.ident(), a = norm(j.axis);
    if (j.type === "prismatic") { m[12] = q * a[0]; m[13] = q * a[1]; m[14] = q * a[2]; return m; }
    const c = Math.cos(q), s = Math.sin(q), C = 1 - c, [x, y, z] = a;
    const R = [c + x * x * C, x * y * C - z * s, x * z * C + y * s,
               y * x * C + z * s, c + y * y * C, y * z * C - x * s,
               z * x * C - y * s, z * y * C + x * s, c + z * z * C];
    for (let r = 0; r < 3; r++) for (let k = 0; k < 3; k++) m[k * 4 + r] = R[r * 3 + k];
    const o = j.origin;
    for (let r = 0; r < 3; r++) m[12 + r] = o[r] - (R[r * 3] * o[0] + R[r * 3 + 1] * o[1] + R[r * 3 + 2] * o[2]);
    return m;
  }

  // ---------- GL set-up ----------
  const VS = `#version 300 es
  in vec3 aPos; in vec3 aNrm; in vec3 aCol;
  uniform mat4 uProj, uView, uModel; out vec3 vCol; out vec3 vN; out vec3 vP;
  void main() { vec4 w = uModel * vec4(aPos, 1.0); vP = w.xyz; vN = mat3(uModel) * aNrm; vCol = aCol;
    gl_Position = uProj * uView * w; }`;
  const FS = `#version 300 es
  precision highp float; in vec3 vCol; in vec3 vN; in vec3 vP; uniform vec3 uEye; uniform float uLit;
  uniform vec4 uTint; out vec4 o;
  void main() { vec3 n = normalize(vN); vec3 l = normalize(uEye - vP);
    float d = abs(dot(n, l)); vec3 c = mix(vCol, uTint.rgb, uTint.a);
    o = vec4(uLit > 0.5 ? c * (0.35 + 0.65 * d) : c, 1.0); }`;
  function shader(type, src) {
    const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }
  const prog = gl.createProgram();
  gl.attachShader(prog, shader(gl.VERTEX_SHADER, VS)); gl.attachShader(prog, shader(gl.FRAGMENT_SHADER, FS));
  gl.linkProgram(prog); gl.useProgram(prog);
  const loc = {
    pos: gl.getAttribLocation(prog, "aPos"), nrm: gl.getAttribLocation(prog, "aNrm"), col: gl.getAttribLocation(prog, "aCol"),
    proj: gl.getUniformLocation(prog, "uProj"), view: gl.getUniformLocation(prog, "uView"), model: gl.getUniformLocation(prog, "uModel"),
    eye: gl.getUniformLocation(prog, "uEye"), lit: gl.getUniformLocation(prog, "uLit"), tint: gl.getUniformLocation(prog, "uTint"),
  };

  function decode(s, T) {
    const bin = atob(s), u8 = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) u8[i] = bin.charCodeAt(i);
    return new T(u8.buffer);
  }
  function upload(mp) {
    const vao = gl.createVertexArray(); gl.bindVertexArray(vao);
    const buf = (data, attr, size, type, normalized) => {
      const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.enableVertexAttribArray(attr); gl.vertexAttribPointer(attr, size, type, normalized, 0, 0);
    };
    const pos = decode(mp.positions, Float32Array);
    buf(pos, loc.pos, 3, gl.FLOAT, false);
    buf(decode(mp.normals, Int8Array), loc.nrm, 3, gl.BYTE, true);
    buf(decode(mp.colors, Uint8Array), loc.col, 3, gl.UNSIGNED_BYTE, true);
    const idx = decode(mp.indices, Uint32Array), ib = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib); gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    gl.bindVertexArray(null);
    return { vao, count: idx.length, positions: pos };
  }
  function lineMesh(points, rgb) {
    const vao = gl.createVertexArray(); gl.bindVertexArray(vao);
    const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(points.flat()), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc.pos); gl.vertexAttribPointer(loc.pos, 3, gl.FLOAT, false, 0, 0);
    gl.disableVertexAttribArray(loc.nrm); gl.disableVertexAttribArray(loc.col);
    gl.bindVertexArray(null);
    return { vao, count: points.length, rgb };
  }

  const bg = upload(P.background);
  const objects = P.objects.map((o) => {
    const j = o.joint, ext = o.obb.extents, len = Math.max(ext[0], ext[1]) * 0.75 + 0.05;
    const a = norm(j.axis), c = j.type === "revolute" ? j.origin : o.obb.center;
    return {
      src: o, q: 0,
      part: o.meshes.part ? upload(o.meshes.part) : null,
      base: o.meshes.base ? upload(o.meshes.base) : null,
      inner: o.meshes.inner ? upload(o.meshes.inner) : null,
      axis: lineMesh([sub(c, scl(a, len)), add(c, scl(a, len))], j.type === "revolute" ? [0.9, 0.1, 0.1] : [0.1, 0.3, 0.95]),
    };
  });
  const byId = Object.fromEntries(objects.map((o) => [o.src.id, o]));

  // ---------- camera ----------
  const lo = P.bounds[0], hi = P.bounds[1];
  const cam = { target: scl(add(lo, hi), 0.5), yaw: -2.2, pitch: 0.55, dist: 1.1 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) };
  if (P.objects.length) {
    // start inside the room, in front of the objects: look along their mean front normal (into the cavities)
    const cs = P.objects.map((o) => o.obb.center), n = P.objects.length;
    const t = [0, 1, 2].map((k) => cs.reduce((s, c) => s + c[k], 0) / n);
    let d = [0, 1].map((k) => P.objects.reduce((s, o) => s - (o.front_normal ? o.front_normal[k] : 0), 0));
    const dl = Math.hypot(d[0], d[1]);
    if (dl > 1e-6) {
      d = [d[0] / dl, d[1] / dl];
      const span = Math.max(...cs.map((c) => Math.hypot(c[0] - t[0], c[1] - t[1], c[2] - t[2])));
      let room = Infinity;  // free distance from the objects to the scene bounds along d
      for (let k = 0; k < 2; k++) {
        if (d[k] > 1e-6) room = Math.min(room, (hi[k] - t[k]) / d[k]);
        if (d[k] < -1e-6) room = Math.min(room, (lo[k] - t[k]) / d[k]);
      }
      const dist = Math.max(1.0, Math.min(2.2 * span + 1.5, room - 0.2));
      cam.target = t; cam.dist = dist; cam.yaw = Math.atan2(d[1], d[0]);
      cam.pitch = Math.max(0.1, Math.min(0.7, Math.asin(Math.max(-1, Math.min(1, (Math.min(hi[2] - 0.3, 1.8) - t[2]) / dist)))));
    }
  }
  const show = { background: true, cavities: true, axes: true, labels: true };
  let selected = null, dirty = false;
  function eye() {
    return add(cam.target, scl([Math.cos(cam.pitch) * Math.cos(cam.yaw), Math.cos(cam.pitch) * Math.sin(cam.yaw), Math.sin(cam.pitch)], cam.dist));
  }
  function matrices() {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    const proj = M.persp(50 * Math.PI / 180, w / h, 0.02, 200), view = M.lookAt(eye(), cam.target, [0, 0, 1]);
    return { proj, view, vp: M.mul(proj, view), w, h };
  }

  // ---------- drawing ----------
  function draw() {
    dirty = false;
    const dpr = window.devicePixelRatio || 1, W = Math.round(canvas.clientWidth * dpr), H = Math.round(canvas.clientHeight * dpr);
    if (canvas.width !== W || canvas.height !== H) { canvas.width = W; canvas.height = H; }
    gl.viewport(0, 0, W, H); gl.clearColor(0.96, 0.96, 0.97, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    const m = matrices();
    gl.uniformMatrix4fv(loc.proj, false, m.proj); gl.uniformMatrix4fv(loc.view, false, m.view);
    gl.uniform3fv(loc.eye, eye()); gl.uniform1f(loc.lit, 1);
    const drawMesh = (g, model, tint) => {
      if (!g) return;
      gl.uniformMatrix4fv(loc.model, false, model); gl.uniform4fv(loc.tint, tint || [0, 0, 0, 0]);
      gl.bindVertexArray(g.vao); gl.drawElements(gl.TRIANGLES, g.count, gl.UNSIGNED_INT, 0);
    };
    if (show.background) drawMesh(bg, M.ident());
    for (const o of objects) {
      const jm = jointMatrix(o.src.joint, o.q), tint = o === selected ? [1.0, 0.75, 0.1, 0.35] : null;
      drawMesh(o.part, jm, tint);
      if (show.cavities) { drawMesh(o.base, M.ident()); drawMesh(o.inner, jm); }
    }
    if (show.axes) {
      gl.uniform1f(loc.lit, 0); gl.uniform4fv(loc.tint, [0, 0, 0, 0]); gl.disable(gl.DEPTH_TEST);
      for (const o of objects) {
        gl.uniformMatrix4fv(loc.model, false, o.src.joint.type === "prismatic" ? jointMatrix(o.src.joint, o.q) : M.ident());
        gl.bindVertexArray(o.axis.vao); gl.vertexAttrib3f(loc.nrm, 0, 0, 1); gl.vertexAttrib3fv(loc.col, o.axis.rgb);
        gl.drawArrays(gl.LINES, 0, o.axis.count);
      }
      gl.enable(gl.DEPTH_TEST);
    }
    gl.bindVertexArray(null);
    placeLabels(m);
  }
  function requestDraw() { if (!dirty) { dirty = true; requestAnimationFrame(draw); } }

  // ---------- labels & picking ----------
  const labelLayer = document.getElementById("r3d-labels");
  for (const o of objects) {
    const d = document.createElement("div"); d.className = "r3d-label"; d.textContent = o.src.id; labelLayer.appendChild(d); o.labelEl = d;
  }
  function toScreen(m, p) { const c = M.apply(m.vp, p); return [(c[0] * 0.5 + 0.5) * m.w, (1 - (c[1] * 0.5 + 0.5)) * m.h, c[2]]; }
  function placeLabels(m) {
    for (const o of objects) {
      const s = toScreen(m, M.apply(jointMatrix(o.src.joint, o.q), o.src.obb.center));
      const vis = show.labels && s[2] < 1 && s[2] > -1;
      o.labelEl.style.display = vis ? "block" : "none";
      o.labelEl.style.left = s[0] + "px"; o.labelEl.style.top = s[1] + "px";
    }
  }
  function obbCorners(src) {
    const out = [], c = src.obb.center, A = src.obb.axes, e = src.obb.extents;
    for (const i of [-1, 1]) for (const j of [-1, 1]) for (const k of [-1, 1])
      out.push(add(add(add(c, scl(A[0], i * e[0] / 2)), scl(A[1], j * e[1] / 2)), scl(A[2], k * e[2] / 2)));
    return out;
  }
  // Screen box of an object's part at joint value q (test hook and picking aid).
  function screenBox(id, q) {
    const o = byId[id], m = matrices(), jm = jointMatrix(o.src.joint, q === undefined ? o.q : q);
    const pts = o.part ? [] : obbCorners(o.src);
    if (o.part) { const p = o.part.positions; for (let i = 0; i < p.length; i += 3) pts.push(M.apply(jm, [p[i], p[i + 1], p[i + 2]])); }
    else for (let i = 0; i < pts.length; i++) pts[i] = M.apply(jm, pts[i]);
    let x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
    for (const p of pts) { const s = toScreen(m, p); x0 = Math.min(x0, s[0]); y0 = Math.min(y0, s[1]); x1 = Math.max(x1, s[0]); y1 = Math.max(y1, s[1]); }
    return [x0, y0, x1, y1];
  }
  function pick(ev) {
    const r = canvas.getBoundingClientRect(), m = matrices();
    const nx = ((ev.clientX - r.left) / r.width) * 2 - 1, ny = 1 - ((ev.clientY - r.top) / r.height) * 2;
    // Ray through the pixel: unproject near/far points with the inverse of view-projection.
    const inv = invert4(m.vp), p0 = M.apply(inv, [nx, ny, -1]), p1 = M.apply(inv, [nx, ny, 1]), d = norm(sub(p1, p0));
    let best = null, bestT = Infinity;
    for (const o of objects) {
      const t = rayObb(p0, d, o); if (t < bestT) { bestT = t; best = o; }
    }
    select(best);
  }
  function rayObb(p, d, o) {
    // Move the ray into the closed state of the part, then slab-test against the closed OBB.
    const im = invert4(jointMatrix(o.src.joint, o.q)), q0 = M.apply(im, p), q1 = M.apply(im, add(p, d)), dd = sub(q1, q0);
    const c = o.src.obb.center, A = o.src.obb.axes, e = o.src.obb.extents;
    let tmin = -Infinity, tmax = Infinity; const rel = sub(q0, c);
    for (let k = 0; k < 3; k++) {
      const po = dot(rel, A[k]), dv = dot(dd, A[k]), h = e[k] / 2 + 0.01;
      if (Math.abs(dv) < 1e-12) { if (Math.abs(po) > h) return Infinity; continue; }
      let t1 = (-h - po) / dv, t2 = (h - po) / dv; if (t1 > t2) [t1, t2] = [t2, t1];
      tmin = Math.max(tmin, t1); tmax = Math.min(tmax, t2); if (tmin > tmax) return Infinity;
    }
    return tmax < 0 ? Infinity : Math.max(tmin, 0);
  }
  function invert4(m) {
    const inv = new Float32Array(16), a = m;
    inv[0] = a[5] * a[10] * a[15] - a[5] * a[11] * a[14] - a[9] * a[6] * a[15] + a[9] * a[7] * a[14] + a[13] * a[6] * a[11] - a[13] * a[7] * a[10];
    inv[4] = -a[4] * a[10] * a[15] + a[4] * a[11] * a[14] + a[8] * a[6] * a[15] - a[8] * a[7] * a[14] - a[12] * a[6] * a[11] + a[12] * a[7] * a[10];
    inv[8] = a[4] * a[9] * a[15] - a[4] * a[11] * a[13] - a[8] * a[5] * a[15] + a[8] * a[7] * a[13] + a[12] * a[5] * a[11] - a[12] * a[7] * a[9];
    inv[12] = -a[4] * a[9] * a[14] + a[4] * a[10] * a[13] + a[8] * a[5] * a[14] - a[8] * a[6] * a[13] - a[12] * a[5] * a[10] + a[12] * a[6] * a[9];
    inv[1] = -a[1] * a[10] * a[15] + a[1] * a[11] * a[14] + a[9] * a[2] * a[15] - a[9] * a[3] * a[14] - a[13] * a[2] * a[11] + a[13] * a[3] * a[10];
    inv[5] = a[0] * a[10] * a[15] - a[0] * a[11] * a[14] - a[8] * a[2] * a[15] + a[8] * a[3] * a[14] + a[12] * a[2] * a[11] - a[12] * a[3] * a[10];
    inv[9] = -a[0] * a[9] * a[15] + a[0] * a[11] * a[13] + a[8] * a[1] * a[15] - a[8] * a[3] * a[13] - a[12] * a[1] * a[11] + a[12] * a[3] * a[9];
    inv[13] = a[0] * a[9] * a[14] - a[0] * a[10] * a[13] - a[8] * a[1] * a[14] + a[8] * a[2] * a[13] + a[12] * a[1] * a[10] - a[12] * a[2] * a[9];
    inv[2] = a[1] * a[6] * a[15] - a[1] * a[7] * a[14] - a[5] * a[2] * a[15] + a[5] * a[3] * a[14] + a[13] * a[2] * a[7] - a[13] * a[3] * a[6];
    inv[6] = -a[0] * a[6] * a[15] + a[0] * a[7] * a[14] + a[4] * a[2] * a[15] - a[4] * a[3] * a[14] - a[12] * a[2] * a[7] + a[12] * a[3] * a[6];
    inv[10] = a[0] * a[5] * a[15] - a[0] * a[7] * a[13] - a[4] * a[1] * a[15] + a[4] * a[3] * a[13] + a[12] * a[1] * a[7] - a[12] * a[3] * a[5];
    inv[14] = -a[0] * a[5] * a[14] + a[0] * a[6] * a[13] + a[4] * a[1] * a[14] - a[4] * a[2] * a[13] - a[12] * a[1] * a[6] + a[12] * a[2] * a[5];
    inv[3] = -a[1] * a[6] * a[11] + a[1] * a[7] * a[10] + a[5] * a[2] * a[11] - a[5] * a[3] * a[10] - a[9] * a[2] * a[7] + a[9] * a[3] * a[6];
    inv[7] = a[0] * a[6] * a[11] - a[0] * a[7] * a[10] - a[4] * a[2] * a[11] + a[4] * a[3] * a[10] + a[8] * a[2] * a[7] - a[8] * a[3] * a[6];
    inv[11] = -a[0] * a[5] * a[11] + a[0] * a[7] * a[9] + a[4] * a[1] * a[11] - a[4] * a[3] * a[9] - a[8] * a[1] * a[7] + a[8] * a[3] * a[5];
    inv[15] = a[0] * a[5] * a[10] - a[0] * a[6] * a[9] - a[4] * a[1] * a[10] + a[4] * a[2] * a[9] + a[8] * a[1] * a[6] - a[8] * a[2] * a[5];
    let det = a[0] * inv[0] + a[1] * inv[4] + a[2] * inv[8] + a[3] * inv[12]; det = 1 / det;
    for (let i = 0; i < 16; i++) inv[i] *= det;
    return inv;
  }

  // ---------- UI ----------
  const info = document.getElementById("r3d-info");
  const fmt = (x, d) => (x === null || x === undefined ? "–" : Number(x).toFixed(d));
  // Everything shown here comes from the manifest (labels, frame ids, limit sources): text nodes only,
  // never innerHTML, so a frame file named `frame<img onerror=...>` stays text.
  function el(tag, text) { const e = document.createElement(tag); if (text !== undefined) e.textContent = String(text); return e; }
  function select(o) {
    selected = o;
    info.replaceChildren();
    if (!o) { info.append(el("em", "Click an object to see its joint.")); requestDraw(); return; }
    const s = o.src, j = s.joint, deg = j.type === "revolute";
    const lim = deg ? `${fmt(j.lower * 180 / Math.PI, 1)}° … ${fmt(j.upper * 180 / Math.PI, 1)}°` : `${fmt(j.lower, 3)} … ${fmt(j.upper, 3)} m`;
    const views = (s.top_views || []).map((v) => `${v.frame_id} (IoU ${fmt(v.iou, 2)})`).join(", ") || "–";
    const thumbs = (window.REACT3D_THUMBS && window.REACT3D_THUMBS[s.id]) || [];
    info.append(
      el("b", s.id), ` · ${s.label}`, el("br"),
      "type: ", el("b", j.type), `, limits ${lim} (${j.limit_source})`, el("br"),
      `axis [${j.axis.map((v) => fmt(v, 3)).join(", ")}], origin [${j.origin.map((v) => fmt(v, 3)).join(", ")}]`, el("br"),
      `confidence ${fmt(s.score, 2)} · cavity ${fmt(s.cavity_depth, 3)} m (${s.cavity_depth_source || "–"})`, el("br"),
      `source views: ${views}`);
    for (const t of thumbs) {
      if (typeof t !== "string" || !t.startsWith("data:image/")) continue;  // thumbnails are inline images only
      const img = el("img"); img.className = "r3d-thumb"; img.src = t; info.append(img);
    }
    requestDraw();
  }
  const list = document.getElementById("r3d-joints");
  for (const o of objects) {
    const j = o.src.joint, row = document.createElement("div"); row.className = "r3d-row";
    const name = document.createElement("button"); name.className = "r3d-name"; name.textContent = `${o.src.id} ${j.type === "revolute" ? "⟳" : "⇥"}`;
    name.onclick = () => select(o);
    const sl = document.createElement("input"); sl.type = "range"; sl.id = "slider-" + o.src.id; sl.dataset.object = o.src.id;
    sl.min = j.lower; sl.max = j.upper; sl.step = (j.upper - j.lower) / 200 || 0.01; sl.value = 0;
    sl.oninput = () => { o.q = parseFloat(sl.value); requestDraw(); };
    o.slider = sl; row.append(name, sl); list.appendChild(row);
  }
  function setJoint(id, q) { const o = byId[id]; o.q = Math.min(Math.max(q, o.src.joint.lower), o.src.joint.upper); o.slider.value = o.q; requestDraw(); }
  function openAll() { for (const o of objects) setJoint(o.src.id, Math.abs(o.src.joint.upper) >= Math.abs(o.src.joint.lower) ? o.src.joint.upper : o.src.joint.lower); }
  function closeAll() { for (const o of objects) setJoint(o.src.id, 0); }
  document.getElementById("r3d-open").onclick = openAll;
  document.getElementById("r3d-close").onclick = closeAll;
  for (const k of Object.keys(show)) {
    const cb = document.getElementById("r3d-show-" + k);
    cb.checked = show[k]; cb.onchange = () => { show[k] = cb.checked; requestDraw(); };
  }

  // orbit: drag rotates, shift/right-drag pans, wheel zooms; a click without drag picks.
  let drag = null;
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("pointerdown", (e) => { drag = { x: e.clientX, y: e.clientY, moved: false, pan: e.shiftKey || e.button === 2 }; });
  window.addEventListener("pointerup", (e) => { if (drag && !drag.moved && e.target === canvas) pick(e); drag = null; });
  window.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y; if (Math.abs(dx) + Math.abs(dy) > 2) drag.moved = true;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      const f = cam.dist * 0.0015, fw = norm(sub(cam.target, eye())), right = norm(cross(fw, [0, 0, 1])), up = cross(right, fw);
      cam.target = add(cam.target, add(scl(right, -dx * f), scl(up, dy * f)));
    } else { cam.yaw -= dx * 0.006; cam.pitch = Math.max(-1.5, Math.min(1.5, cam.pitch + dy * 0.006)); }
    requestDraw();
  });
  canvas.addEventListener("wheel", (e) => { e.preventDefault(); cam.dist *= Math.exp(e.deltaY * 0.001); requestDraw(); }, { passive: false });
  window.addEventListener("resize", requestDraw);

  select(null);
  requestDraw();
  status.textContent = `${objects.length} objects · background ${P.background.n_faces} faces`;
  window.react3d = { setJoint, openAll, closeAll, screenBox, select: (id) => select(byId[id]), objectIds: objects.map((o) => o.src.id), camera: cam, redraw: requestDraw, ready: true };
})();
