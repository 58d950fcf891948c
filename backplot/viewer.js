/* nctrans backplot viewer: a small WebGL renderer for one typed-array line buffer per program.
 *
 * The page is one file that works offline: the data (toolpath vertices as base64 typed arrays,
 * per-move kind/tool/line/file, the source text, markers, findings, differences) is the JSON in
 * #nc-data, written by nctrans/backplot/html.py. Moves are polylines in program order, so the
 * moves before the slider are one draw call and the rest another; a highlighted move is a draw
 * call over its own range. Picking projects segment end points on the CPU (a click, not a frame).
 * window.ncViewer exposes the state and a few helpers (tests drive the page through them).
 */
(function () {
  "use strict";
  const D = JSON.parse(document.getElementById("nc-data").textContent);
  const $ = (id) => document.getElementById(id);
  const canvas = $("canvas");
  const t0 = performance.now();

  function decode(b64, Type) {
    const bin = atob(b64);
    const n = bin.length;
    const bytes = new Uint8Array(n);
    for (let i = 0; i < n; i++) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }
  function rgb(hex) {
    return [parseInt(hex.slice(1, 3), 16), parseInt(hex.slice(3, 5), 16), parseInt(hex.slice(5, 7), 16)];
  }

  // ------------------------------------------------------------------ programs (A, and B for --compare)
  const KIND_RAPID = 0;
  const programs = D.programs.map((P, pi) => {
    const pts = decode(P.pts, Float32Array);        // x y z per vertex, relative to D.origin
    const mstart = decode(P.mstart, Uint32Array);   // first vertex of each move, n+1 entries
    const kind = decode(P.kind, Uint8Array);
    const tool = decode(P.tool, Int32Array);
    const line = decode(P.line, Uint32Array);
    const file = decode(P.file, Uint16Array);
    const n = kind.length;
    let segs = 0;
    for (let i = 0; i < n; i++) segs += Math.max(mstart[i + 1] - mstart[i] - 1, 0);
    const pos = new Float32Array(segs * 6);
    const col = new Uint8Array(segs * 8);
    const dist = new Float32Array(segs * 2);
    const sstart = new Uint32Array(n + 1);        // first segment of each move
    const toolColour = {};
    P.tools.forEach((t, k) => { toolColour[t] = rgb(P.colours[k]); });
    let s = 0;
    for (let i = 0; i < n; i++) {
      sstart[i] = s;
      const c = toolColour[tool[i]] || [80, 80, 80];
      const rapid = kind[i] === KIND_RAPID;
      let d = 0;
      for (let v = mstart[i]; v < mstart[i + 1] - 1; v++, s++) {
        for (let e = 0; e < 2; e++) {
          const src = (v + e) * 3, dst = (s * 2 + e) * 3;
          pos[dst] = pts[src]; pos[dst + 1] = pts[src + 1]; pos[dst + 2] = pts[src + 2];
          const cd = (s * 2 + e) * 4;
          col[cd] = c[0]; col[cd + 1] = c[1]; col[cd + 2] = c[2]; col[cd + 3] = rapid ? 170 : 255;
        }
        const len = Math.hypot(pts[v * 3 + 3] - pts[v * 3], pts[v * 3 + 4] - pts[v * 3 + 1], pts[v * 3 + 5] - pts[v * 3 + 2]);
        dist[s * 2] = rapid ? d : -1;
        dist[s * 2 + 1] = rapid ? d + len : -1;
        d += len;
      }
    }
    sstart[n] = s;
    const byLine = new Map();                    // "file:line" -> move indices
    for (let i = 0; i < n; i++) {
      const key = P.files[file[i]] + ":" + line[i];
      let a = byLine.get(key);
      if (!a) byLine.set(key, a = []);
      a.push(i);
    }
    return { index: pi, label: P.label, files: P.files, pts, mstart, kind, tool, line, file, n, segs,
             pos, col, dist, sstart, byLine, tools: P.tools, colours: P.colours };
  });
  const A = programs[0];

  // ------------------------------------------------------------------ WebGL
  // Multisampling costs several times the frame on a software renderer (a browser without a GPU,
  // headless Chromium): large programs, whose lines are dense anyway, are drawn without it.
  const totalSegs = programs.reduce((a, P) => a + P.segs, 0);
  const GL_OPTIONS = { antialias: totalSegs < 50000, depth: false };
  const gl = canvas.getContext("webgl2", GL_OPTIONS) || canvas.getContext("webgl", GL_OPTIONS);
  if (!gl) {
    $("plot").innerHTML = '<p id="nogl">This browser gives the page no WebGL: the plot cannot be drawn.</p>';
    return;
  }
  function shader(type, src) {
    const sh = gl.createShader(type);
    gl.shaderSource(sh, src);
    gl.compileShader(sh);
    if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
    return sh;
  }
  function program(vs, fs) {
    const p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return p;
  }
  const lineProg = program(
    "attribute vec3 aPos; attribute vec4 aCol; attribute float aDist; uniform mat4 uMVP;" +
    "varying vec4 vCol; varying float vDist;" +
    "void main(){ gl_Position = uMVP * vec4(aPos, 1.0); vCol = aCol; vDist = aDist; }",
    "precision highp float; varying vec4 vCol; varying float vDist; uniform float uPx; uniform float uDim;" +
    "uniform vec4 uOver;" +
    "void main(){ if (vDist >= 0.0 && mod(vDist / uPx, 9.0) > 5.0) discard;" +
    " vec4 c = uOver.a > 0.0 ? uOver : vCol; vec3 rgb = mix(c.rgb, vec3(1.0), uDim);" +
    " gl_FragColor = vec4(rgb, 1.0); }");
  const pointProg = program(
    "attribute vec3 aPos; attribute vec4 aCol; attribute float aSize; uniform mat4 uMVP; varying vec4 vCol;" +
    "void main(){ gl_Position = uMVP * vec4(aPos, 1.0); gl_PointSize = aSize; vCol = aCol; }",
    "precision mediump float; varying vec4 vCol;" +
    "void main(){ vec2 d = gl_PointCoord - vec2(0.5); float r = length(d); if (r > 0.5) discard;" +
    " gl_FragColor = r > 0.36 ? vec4(1.0) : vCol; }");
  const L = {
    pos: gl.getAttribLocation(lineProg, "aPos"), col: gl.getAttribLocation(lineProg, "aCol"),
    dist: gl.getAttribLocation(lineProg, "aDist"), mvp: gl.getUniformLocation(lineProg, "uMVP"),
    px: gl.getUniformLocation(lineProg, "uPx"), dim: gl.getUniformLocation(lineProg, "uDim"),
    over: gl.getUniformLocation(lineProg, "uOver"),
  };
  const Pt = {
    pos: gl.getAttribLocation(pointProg, "aPos"), col: gl.getAttribLocation(pointProg, "aCol"),
    size: gl.getAttribLocation(pointProg, "aSize"), mvp: gl.getUniformLocation(pointProg, "uMVP"),
  };
  function buffer(data) {
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    return b;
  }
  for (const P of programs) {
    P.bPos = buffer(P.pos); P.bCol = buffer(P.col); P.bDist = buffer(P.dist);
  }
  if (D.compare) {        // A and B each in one colour, so the overlay reads
    D.compare.colours.forEach((hex, k) => {
      const P = programs[k];
      if (!P) return;
      const c = rgb(hex);
      for (let i = 0; i < P.col.length; i += 4) { P.col[i] = c[0]; P.col[i + 1] = c[1]; P.col[i + 2] = c[2]; }
      gl.bindBuffer(gl.ARRAY_BUFFER, P.bCol);
      gl.bufferData(gl.ARRAY_BUFFER, P.col, gl.STATIC_DRAW);
    });
  }

  // points: markers, findings, differences, and the tool at the slider position
  const points = [];   // {p:[x,y,z], c:[r,g,b], size, kind, ...}
  const SEV = { error: [208, 0, 0], warning: [224, 160, 0], info: [32, 128, 208] };
  for (const m of D.markers) points.push({ p: m.p, c: m.kind === "start" ? [0, 170, 0] : [255, 204, 0], size: 12, what: m });
  for (const f of D.findings) points.push({ p: f.p, c: SEV[f.severity] || [128, 128, 128], size: 11, what: f });
  for (const d of (D.differences || [])) {
    for (const side of [d.a, d.b]) if (side) points.push({ p: side.p, c: [208, 0, 0], size: 16, what: d });
  }
  const toolPoint = { p: [0, 0, 0], c: [0, 0, 0], size: 9 };
  points.push(toolPoint);
  const ptPos = new Float32Array(points.length * 3), ptCol = new Uint8Array(points.length * 4),
        ptSize = new Float32Array(points.length);
  const bPtPos = gl.createBuffer(), bPtCol = gl.createBuffer(), bPtSize = gl.createBuffer();
  function uploadPoints() {
    points.forEach((q, i) => {
      ptPos.set(q.p, i * 3); ptCol.set([q.c[0], q.c[1], q.c[2], 255], i * 4); ptSize[i] = q.size;
    });
    gl.bindBuffer(gl.ARRAY_BUFFER, bPtPos); gl.bufferData(gl.ARRAY_BUFFER, ptPos, gl.DYNAMIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, bPtCol); gl.bufferData(gl.ARRAY_BUFFER, ptCol, gl.DYNAMIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, bPtSize); gl.bufferData(gl.ARRAY_BUFFER, ptSize, gl.DYNAMIC_DRAW);
  }

  // ------------------------------------------------------------------ camera (orthographic)
  const VIEWS = { top: [-90, 90], front: [-90, 0], side: [0, 0], iso: [-45, 35.264] };   // yaw, pitch (deg)
  const cam = { yaw: -90, pitch: 90, c: [0, 0, 0], s: 1 };    // s: world mm per CSS pixel
  function basis() {
    const y = cam.yaw * Math.PI / 180, p = cam.pitch * Math.PI / 180;
    const d = [Math.cos(p) * Math.cos(y), Math.cos(p) * Math.sin(y), Math.sin(p)];
    const r = [-Math.sin(y), Math.cos(y), 0];
    const u = [d[1] * r[2] - d[2] * r[1], d[2] * r[0] - d[0] * r[2], d[0] * r[1] - d[1] * r[0]];
    return { r, u, d };
  }
  const BB = D.bounds;          // [[x,y,z],[x,y,z]] relative to D.origin
  const radius = Math.max(Math.hypot(BB[1][0] - BB[0][0], BB[1][1] - BB[0][1], BB[1][2] - BB[0][2]) / 2, 1e-3);
  function fit() {
    const { r, u } = basis();
    let u0 = Infinity, u1 = -Infinity, v0 = Infinity, v1 = -Infinity;
    for (const x of [BB[0][0], BB[1][0]]) for (const y of [BB[0][1], BB[1][1]]) for (const z of [BB[0][2], BB[1][2]]) {
      const a = x * r[0] + y * r[1] + z * r[2], b = x * u[0] + y * u[1] + z * u[2];
      u0 = Math.min(u0, a); u1 = Math.max(u1, a); v0 = Math.min(v0, b); v1 = Math.max(v1, b);
    }
    const cu = (u0 + u1) / 2, cv = (v0 + v1) / 2;
    const cx = (BB[0][0] + BB[1][0]) / 2, cy = (BB[0][1] + BB[1][1]) / 2, cz = (BB[0][2] + BB[1][2]) / 2;
    const { d } = basis();
    const cd = cx * d[0] + cy * d[1] + cz * d[2];
    cam.c = [cu * r[0] + cv * u[0] + cd * d[0], cu * r[1] + cv * u[1] + cd * d[1], cu * r[2] + cv * u[2] + cd * d[2]];
    const w = canvas.clientWidth || 1, h = canvas.clientHeight || 1;
    cam.s = Math.max((u1 - u0) / (w * 0.9), (v1 - v0) / (h * 0.9), 1e-6);
    draw();
  }
  function setView(name) {
    const v = VIEWS[name] || VIEWS.top;
    cam.yaw = v[0]; cam.pitch = v[1];
    fit();
  }
  function mvp() {
    const { r, u, d } = basis();
    const w = canvas.clientWidth || 1, h = canvas.clientHeight || 1;
    const sx = 2 / (w * cam.s), sy = 2 / (h * cam.s), sz = -1 / (radius * 4);
    const c = cam.c;
    const tx = -(r[0] * c[0] + r[1] * c[1] + r[2] * c[2]) * sx;
    const ty = -(u[0] * c[0] + u[1] * c[1] + u[2] * c[2]) * sy;
    const tz = -(d[0] * c[0] + d[1] * c[1] + d[2] * c[2]) * sz;
    return new Float32Array([   // column-major
      r[0] * sx, u[0] * sy, d[0] * sz, 0,
      r[1] * sx, u[1] * sy, d[1] * sz, 0,
      r[2] * sx, u[2] * sy, d[2] * sz, 0,
      tx, ty, tz, 1]);
  }
  // CSS-pixel position of a point (relative to D.origin) in the canvas
  function toScreen(p, b) {
    b = b || basis();
    const w = canvas.clientWidth, h = canvas.clientHeight, c = cam.c;
    const x = (p[0] - c[0]) * b.r[0] + (p[1] - c[1]) * b.r[1] + (p[2] - c[2]) * b.r[2];
    const y = (p[0] - c[0]) * b.u[0] + (p[1] - c[1]) * b.u[1] + (p[2] - c[2]) * b.u[2];
    return [w / 2 + x / cam.s, h / 2 - y / cam.s];
  }

  // ------------------------------------------------------------------ state and drawing
  const state = { step: A.n, selected: null, highlight: [], frames: 0, lastDrawMs: 0, loadMs: 0 };
  let pending = false;
  function draw() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => { pending = false; drawNow(); });
  }
  function bindLines(P) {
    gl.bindBuffer(gl.ARRAY_BUFFER, P.bPos); gl.enableVertexAttribArray(L.pos);
    gl.vertexAttribPointer(L.pos, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, P.bCol); gl.enableVertexAttribArray(L.col);
    gl.vertexAttribPointer(L.col, 4, gl.UNSIGNED_BYTE, true, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, P.bDist); gl.enableVertexAttribArray(L.dist);
    gl.vertexAttribPointer(L.dist, 1, gl.FLOAT, false, 0, 0);
  }
  function drawNow() {
    const t = performance.now();
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    gl.viewport(0, 0, w, h);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.disable(gl.DEPTH_TEST);
    const M = mvp();
    gl.useProgram(lineProg);
    gl.uniformMatrix4fv(L.mvp, false, M);
    gl.uniform1f(L.px, cam.s);
    programs.forEach((P, k) => {
      bindLines(P);
      const step = k === 0 ? state.step : P.n;
      const done = P.sstart[Math.min(step, P.n)];
      gl.uniform4f(L.over, 0, 0, 0, 0);
      if (done < P.segs) { gl.uniform1f(L.dim, 0.85); gl.drawArrays(gl.LINES, done * 2, (P.segs - done) * 2); }
      gl.uniform1f(L.dim, 0);
      if (done > 0) gl.drawArrays(gl.LINES, 0, done * 2);
    });
    // highlighted moves on top
    gl.uniform1f(L.dim, 0);
    gl.uniform4f(L.over, 0.9, 0.0, 0.6, 1.0);
    for (const h of state.highlight) {
      const P = programs[h.program];
      bindLines(P);
      for (const i of h.moves.slice(0, 20000)) {
        const a = P.sstart[i], b = P.sstart[i + 1];
        if (b > a) gl.drawArrays(gl.LINES, a * 2, (b - a) * 2);
      }
    }
    // points
    if (state.step > 0 && state.step <= A.n) {
      const v = A.mstart[state.step] - 1;
      toolPoint.p = [A.pts[v * 3], A.pts[v * 3 + 1], A.pts[v * 3 + 2]];
    }
    uploadPoints();
    gl.useProgram(pointProg);
    gl.uniformMatrix4fv(Pt.mvp, false, M);
    gl.bindBuffer(gl.ARRAY_BUFFER, bPtPos); gl.enableVertexAttribArray(Pt.pos);
    gl.vertexAttribPointer(Pt.pos, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, bPtCol); gl.enableVertexAttribArray(Pt.col);
    gl.vertexAttribPointer(Pt.col, 4, gl.UNSIGNED_BYTE, true, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, bPtSize); gl.enableVertexAttribArray(Pt.size);
    gl.vertexAttribPointer(Pt.size, 1, gl.FLOAT, false, 0, 0);
    gl.drawArrays(gl.POINTS, 0, points.length);
    gl.disableVertexAttribArray(Pt.size);
    drawOverlay();
    state.frames++;
    state.lastDrawMs = performance.now() - t;
  }
  function drawOverlay() {
    // scale bar: a round length near 120 px
    const target = 120 * cam.s, e = Math.pow(10, Math.floor(Math.log10(target)));
    const len = [5, 2, 1].map((f) => f * e).find((v) => v <= target) || e;
    const bar = document.querySelector("#scalebar .bar");
    bar.style.width = (len / cam.s).toFixed(0) + "px";
    document.querySelector("#scalebar span").textContent = (+len.toPrecision(3)) + " mm";
    const tc = $("triad"), ctx = tc.getContext("2d"), b = basis();
    ctx.clearRect(0, 0, 70, 70);
    const axes = [["X", [1, 0, 0], "#d62728"], ["Y", [0, 1, 0], "#2ca02c"], ["Z", [0, 0, 1], "#1f77b4"]];
    ctx.font = "11px sans-serif";
    ctx.lineWidth = 2;
    for (const [name, v, colour] of axes) {
      const dx = v[0] * b.r[0] + v[1] * b.r[1] + v[2] * b.r[2], dy = -(v[0] * b.u[0] + v[1] * b.u[1] + v[2] * b.u[2]);
      if (Math.hypot(dx, dy) < 0.1) continue;
      ctx.strokeStyle = ctx.fillStyle = colour;
      ctx.beginPath(); ctx.moveTo(35, 35); ctx.lineTo(35 + dx * 24, 35 + dy * 24); ctx.stroke();
      ctx.fillText(name, 32 + dx * 31, 39 + dy * 31);
    }
  }

  // ------------------------------------------------------------------ picking
  /** Squared page distance from (mx, my) to each segment [from, to) of P: calls visit(segment, d2). */
  function scanSegments(P, from, to, mx, my, visit) {
    const { r, u } = basis();
    const w2 = canvas.clientWidth / 2, h2 = canvas.clientHeight / 2, c = cam.c, k = 1 / cam.s;
    // screen x = w2 + (p - c).r / s, y = h2 - (p - c).u / s, written out: no allocation per point
    const ox = w2 - (c[0] * r[0] + c[1] * r[1] + c[2] * r[2]) * k, oy = h2 + (c[0] * u[0] + c[1] * u[1] + c[2] * u[2]) * k;
    const rx = r[0] * k, ry = r[1] * k, rz = r[2] * k, ux = u[0] * k, uy = u[1] * k, uz = u[2] * k;
    const pos = P.pos;
    for (let s = from; s < to; s++) {
      const o = s * 6;
      const ax = ox + pos[o] * rx + pos[o + 1] * ry + pos[o + 2] * rz;
      const ay = oy - (pos[o] * ux + pos[o + 1] * uy + pos[o + 2] * uz);
      const vx = ox + pos[o + 3] * rx + pos[o + 4] * ry + pos[o + 5] * rz - ax;
      const vy = oy - (pos[o + 3] * ux + pos[o + 4] * uy + pos[o + 5] * uz) - ay;
      const l2 = vx * vx + vy * vy;
      let t = l2 > 0 ? ((mx - ax) * vx + (my - ay) * vy) / l2 : 0;
      t = t < 0 ? 0 : t > 1 ? 1 : t;
      const dx = ax + t * vx - mx, dy = ay + t * vy - my;
      visit(s, dx * dx + dy * dy);
    }
  }
  function moveOfSegment(P, seg) {
    let lo = 0, hi = P.n - 1;
    while (lo < hi) { const mid = (lo + hi + 1) >> 1; if (P.sstart[mid] <= seg) lo = mid; else hi = mid - 1; }
    return lo;
  }
  function pick(mx, my) {
    let best = null, bestD = 8 * 8;
    programs.forEach((P, q) => {
      const last = P.sstart[Math.min(q === 0 ? state.step : P.n, P.n)];
      scanSegments(P, 0, last, mx, my, (s, dd) => { if (dd < bestD) { bestD = dd; best = { program: q, segment: s }; } });
    });
    if (!best) return null;
    return { program: best.program, move: moveOfSegment(programs[best.program], best.segment) };
  }
  function selectMove(k, i, scroll) {
    const P = programs[k];
    const file = P.files[P.file[i]], line = P.line[i];
    state.selected = { program: k, move: i, file, line, kind: ["rapid", "linear", "arc"][P.kind[i]] };
    state.highlight = [{ program: k, moves: [i] }];
    showSource(file, line, scroll !== false);
    $("info").textContent = `${P.label}: move ${i + 1} (${state.selected.kind}, T${P.tool[i] < 0 ? "?" : P.tool[i]}) at ${file}:${line}`;
    draw();
  }
  function selectLine(file, line, scroll) {
    state.highlight = [];
    let count = 0;
    programs.forEach((P, k) => {
      const moves = P.byLine.get(file + ":" + line);
      if (moves) { state.highlight.push({ program: k, moves }); count += moves.length; }
    });
    state.selected = { file, line, moves: count };
    showSource(file, line, scroll);
    $("info").textContent = `${file}:${line}: ${count} move${count === 1 ? "" : "s"}`;
    draw();
  }

  // ------------------------------------------------------------------ source panel (virtual list)
  const LH = 18;
  const sources = {};
  for (const name of Object.keys(D.sources)) sources[name] = D.sources[name].split("\n");
  const lineClass = {};             // file -> Map(line -> class) for findings
  const RANK = { info: 1, warning: 2, error: 3 };
  for (const f of D.findings) {
    const m = lineClass[f.file] || (lineClass[f.file] = new Map());
    const old = m.get(f.line);
    if (!old || RANK[f.severity] > RANK[old]) m.set(f.line, f.severity);
  }
  const fileSel = $("file");
  for (const name of Object.keys(sources)) {
    const o = document.createElement("option");
    o.value = o.textContent = name;
    fileSel.appendChild(o);
  }
  const view = { file: Object.keys(sources)[0] || "", hl: 0, cur: 0 };
  const src = $("src"), spacer = $("src-spacer");
  function renderSource() {
    const lines = sources[view.file] || [];
    spacer.style.height = (lines.length * LH) + "px";
    const first = Math.max(0, Math.floor(src.scrollTop / LH) - 10);
    const last = Math.min(lines.length, Math.ceil((src.scrollTop + src.clientHeight) / LH) + 10);
    const cls = lineClass[view.file];
    const parts = [];
    for (let i = first; i < last; i++) {
      const n = i + 1;
      let c = "src-line";
      if (cls && cls.has(n)) c += " " + cls.get(n);
      if (n === view.cur) c += " cur";
      if (n === view.hl) c += " hl";
      const text = lines[i].replace(/&/g, "&amp;").replace(/</g, "&lt;");
      parts.push(`<div class="${c}" data-line="${n}" style="top:${i * LH}px"><span class="ln">${n}</span>${text}</div>`);
    }
    spacer.innerHTML = parts.join("");
  }
  function showSource(file, line, scroll) {
    if (file in sources && file !== view.file) { view.file = file; fileSel.value = file; }
    view.hl = line;
    if (scroll) {
      const top = (line - 1) * LH;
      if (top < src.scrollTop || top > src.scrollTop + src.clientHeight - LH) src.scrollTop = Math.max(0, top - src.clientHeight / 3);
    }
    renderSource();
  }
  src.addEventListener("scroll", renderSource);
  fileSel.addEventListener("change", () => { view.file = fileSel.value; src.scrollTop = 0; renderSource(); });
  spacer.addEventListener("click", (ev) => {
    const row = ev.target.closest(".src-line");
    if (row) selectLine(view.file, +row.dataset.line, false);
  });

  // ------------------------------------------------------------------ lists: findings, differences
  function listSection(title, rows) {
    if (!rows.length) return;
    const box = $("lists");
    const h = document.createElement("h3");
    h.textContent = title;
    box.appendChild(h);
    for (const [cls, text, onclick] of rows.slice(0, 2000)) {
      const d = document.createElement("div");
      d.className = "row " + cls;
      d.textContent = text;
      d.title = text;
      d.addEventListener("click", onclick);
      box.appendChild(d);
    }
  }
  listSection(`Findings (${D.findings.length})`, D.findings.map((f) =>
    [f.severity, `${f.file}:${f.line}: ${f.severity}[${f.code}] ${f.message}`, () => selectLine(f.file, f.line, true)]));
  if (D.compare) {
    listSection(D.differences.length ? `Differences (${D.differences.length}${D.compare.truncated ? "+" : ""})`
                                     : "Differences: none (equivalent within tolerance)",
      D.differences.map((d) => ["diff", d.message, () => {
        state.highlight = [];
        for (const [k, side] of [[0, d.a], [1, d.b]]) if (side) state.highlight.push({ program: k, moves: [side.move] });
        if (d.a) showSource(d.a.file, d.a.line, true);
        $("info").textContent = d.message;
        draw();
      }]));
  }

  // ------------------------------------------------------------------ slider
  const slider = $("slider");
  slider.max = String(A.n);
  function setStep(k) {
    state.step = Math.max(0, Math.min(A.n, k | 0));
    slider.value = String(state.step);
    if (state.step > 0) {
      const i = state.step - 1;
      const file = A.files[A.file[i]], line = A.line[i];
      $("step").textContent = `move ${state.step} / ${A.n} · line ${line}`;
      view.cur = line;
      if (file in sources && file !== view.file) { view.file = file; fileSel.value = file; }
      const top = (line - 1) * LH;
      if (top < src.scrollTop || top > src.scrollTop + src.clientHeight - LH) src.scrollTop = Math.max(0, top - src.clientHeight / 3);
      renderSource();
    } else {
      $("step").textContent = `move 0 / ${A.n}`;
    }
    draw();
  }
  slider.addEventListener("input", () => setStep(+slider.value));
  $("prev").addEventListener("click", () => setStep(state.step - 1));
  $("next").addEventListener("click", () => setStep(state.step + 1));
  let timer = null;
  $("play").addEventListener("click", () => {
    if (timer) { clearInterval(timer); timer = null; return; }
    if (state.step >= A.n) setStep(0);
    const per = Math.max(1, Math.round(A.n / 600));
    timer = setInterval(() => { if (state.step >= A.n) { clearInterval(timer); timer = null; } else setStep(state.step + per); }, 16);
  });

  // ------------------------------------------------------------------ mouse
  let drag = null;
  canvas.addEventListener("contextmenu", (ev) => ev.preventDefault());
  canvas.addEventListener("mousedown", (ev) => {
    canvas.focus();
    drag = { x: ev.clientX, y: ev.clientY, x0: ev.clientX, y0: ev.clientY, pan: ev.button !== 0 || ev.shiftKey };
  });
  window.addEventListener("mousemove", (ev) => {
    if (!drag) return;
    const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
    drag.x = ev.clientX; drag.y = ev.clientY;
    if (drag.pan) {
      const { r, u } = basis();
      for (let k = 0; k < 3; k++) cam.c[k] -= (r[k] * dx - u[k] * dy) * cam.s;
    } else {
      cam.yaw -= dx * 0.4;
      cam.pitch = Math.max(-90, Math.min(90, cam.pitch + dy * 0.4));
    }
    draw();
  });
  window.addEventListener("mouseup", (ev) => {
    if (!drag) return;
    const moved = Math.hypot(ev.clientX - drag.x0, ev.clientY - drag.y0);
    drag = null;
    if (moved < 4 && ev.target === canvas) {
      const rect = canvas.getBoundingClientRect();
      const hit = pick(ev.clientX - rect.left, ev.clientY - rect.top);
      if (hit) selectMove(hit.program, hit.move);
    }
  });
  canvas.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    const rect = canvas.getBoundingClientRect();
    const mx = ev.clientX - rect.left - rect.width / 2, my = rect.height / 2 - (ev.clientY - rect.top);
    const { r, u } = basis();
    const f = Math.exp(Math.max(-5, Math.min(5, ev.deltaY * 0.0015)));
    for (let k = 0; k < 3; k++) cam.c[k] += (r[k] * mx + u[k] * my) * cam.s * (1 - f);
    cam.s *= f;
    draw();
  }, { passive: false });
  document.querySelectorAll("#toolbar button[data-view]").forEach((b) =>
    b.addEventListener("click", () => setView(b.dataset.view)));
  $("fit").addEventListener("click", fit);
  canvas.addEventListener("keydown", (ev) => {       // arrows step through the program, Home/End jump
    const k = { ArrowLeft: -1, ArrowRight: 1, ArrowDown: -10, ArrowUp: 10 }[ev.key];
    if (k) setStep(state.step + k);
    else if (ev.key === "Home") setStep(0);
    else if (ev.key === "End") setStep(A.n);
    else return;
    ev.preventDefault();
  });
  window.addEventListener("resize", draw);

  // ------------------------------------------------------------------ header, legend, start
  $("title").textContent = D.title;
  const legend = $("legend");
  const items = D.compare ? D.compare.colours.map((c, k) => [c, (k ? "B " : "A ") + programs[k].label])
                          : A.tools.map((t, k) => [A.colours[k], t < 0 ? "no tool" : "T" + t]);
  for (const [c, text] of items) {
    const s = document.createElement("span");
    s.className = "item";
    s.innerHTML = `<span class="swatch" style="background:${c}"></span>`;
    s.appendChild(document.createTextNode(text));
    legend.appendChild(s);
  }
  const dashed = document.createElement("span");
  dashed.className = "item";
  dashed.textContent = "dashed: rapid";
  legend.appendChild(dashed);
  $("notes").textContent = (D.warnings || []).join(" · ");
  renderSource();
  setStep(A.n);
  setView(D.view);
  state.loadMs = performance.now() - t0;

  function midpoint(k, i) {
    const P = programs[k];
    const a = P.mstart[i], b = P.mstart[i + 1] - 1;
    const v = a + Math.floor((b - a) / 2);
    if (b - a >= 2) return [P.pts[v * 3 + 3], P.pts[v * 3 + 4], P.pts[v * 3 + 5]];
    return [(P.pts[a * 3] + P.pts[b * 3]) / 2, (P.pts[a * 3 + 1] + P.pts[b * 3 + 1]) / 2, (P.pts[a * 3 + 2] + P.pts[b * 3 + 2]) / 2];
  }

  window.ncViewer = {
    state, programs, cam, setView, setStep, selectMove, selectLine, fit, drawNow, pick,
    /** Mean milliseconds per frame over n orbiting frames, waiting for the GPU each time. */
    timeFrames(n) {
      const px = new Uint8Array(4), t = performance.now();
      for (let i = 0; i < n; i++) {
        cam.yaw += 360 / n;
        drawNow();
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
      }
      return (performance.now() - t) / n;
    },
    /** Smallest page distance (CSS px) from move i's screen point to a segment of a move on another line. */
    clearance(k, i) {
      const [x, y] = this.screenOfMove(k, i), rect = canvas.getBoundingClientRect();
      const mx = x - rect.left, my = y - rect.top;
      const f0 = programs[k].file[i], l0 = programs[k].line[i];
      let best = Infinity;
      programs.forEach((P, q) => {
        scanSegments(P, 0, P.segs, mx, my, (s, dd) => {
          if (dd >= best) return;
          const m = moveOfSegment(P, s);
          if (!(q === k && P.file[m] === f0 && P.line[m] === l0)) best = dd;
        });
      });
      return Math.sqrt(best);
    },
    /** CSS-pixel point (page coordinates) in the middle of a move's drawn polyline. */
    screenOfMove(k, i) {
      const s = toScreen(midpoint(k, i)), rect = canvas.getBoundingClientRect();
      return [rect.left + s[0], rect.top + s[1]];
    },
    /** Centre the view on a move and zoom in by `factor`. */
    focusMove(k, i, factor) {
      cam.c = midpoint(k, i);
      cam.s /= factor || 1;
      drawNow();
    },
  };
})();
