// dicephys's throw viewer: plays the trace's own frames (positions and quaternions, no physics
// here) with three.js where WebGL is to be had, else on a 2D canvas, the same camera for both.
// State for readers and tests is kept on <body>: data-ready, data-renderer, data-t,
// data-final-face (the face throw 0's last frame shows), data-outcome (what trace said),
// data-centre (throw 0's centre of mass on the screen now, CSS px from the page's top left).
// data-load-ms (from the page's start to its first frame drawn).
// The URL's hash: #t=0.5 (or #t=end) opens paused at that time; #2d draws on a 2D canvas.

const THREE = await import(URL.createObjectURL(new Blob(
  [document.getElementById("three-src").textContent], { type: "text/javascript" })));
const D = JSON.parse(document.getElementById("data").textContent);
const COLOURS = ["#c8281e", "#1f6fb4", "#2a9d3c", "#d98a00", "#7d3cb5", "#0f9a9a", "#b5367a", "#6b6b12", "#555555", "#e05a00"];
const body = document.body;
const canvas = document.getElementById("view");
const hash = new URLSearchParams(location.hash.slice(1));

// ---- the throws' frames -------------------------------------------------------------------

const throws = D.throws.map((th, i) => ({ ...th, colour: COLOURS[i % COLOURS.length], n: th.frames.t.length }));
const END = Math.max(...throws.map((th) => th.frames.t[th.n - 1]));

/// The frame before or at time t, and how far to the next (0…1).
function locate(th, t) {
  const ts = th.frames.t;
  if (t <= ts[0]) return [0, 0];
  if (t >= ts[th.n - 1]) return [th.n - 1, 0];
  let lo = 0, hi = th.n - 1;
  while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (ts[mid] <= t) lo = mid; else hi = mid; }
  return [lo, (t - ts[lo]) / (ts[hi] - ts[lo])];
}

function position(th, i) { const p = th.frames.p; return new THREE.Vector3(p[3 * i], p[3 * i + 1], p[3 * i + 2]); }
function quaternion(th, i) { const q = th.frames.q; return new THREE.Quaternion(q[4 * i + 1], q[4 * i + 2], q[4 * i + 3], q[4 * i]); }

/// The die's pose at time t: between frames, the position interpolated, the turn slerped.
function pose(th, t) {
  const [i, f] = locate(th, t);
  const p = position(th, i), q = quaternion(th, i);
  if (f > 0) { p.lerp(position(th, i + 1), f); q.slerp(quaternion(th, i + 1), f); }
  return [p, q];
}

/// The outcome a die turned by q rests on: the face whose resting normal points most nearly
/// down (a cylinder's side, normal zero: the radial part of down).
function faceOf(q) {
  const down = new THREE.Vector3(0, -1, 0).applyQuaternion(q.clone().invert());
  let best = null, score = -Infinity;
  for (const o of D.die.outcomes) {
    const [x, y, z] = o.normal;
    const s = (x === 0 && y === 0 && z === 0) ? Math.hypot(down.x, down.y) : x * down.x + y * down.y + z * down.z;
    if (s > score) { score = s; best = o.label; }
  }
  return best;
}

// ---- where each die is drawn: overlaid, or side by side ---------------------------------

const spread = (() => {
  let w = 0;
  for (const th of throws) for (let i = 0; i < th.n; i++) w = Math.max(w, Math.abs(th.frames.p[3 * i + 2]));
  return 2 * w + 4 * D.die.reach;
})();
function offset(k) {
  return document.getElementById("side").checked ? new THREE.Vector3(0, 0, (k - (throws.length - 1) / 2) * spread) : new THREE.Vector3();
}

// ---- the camera: follows the dice, turned by dragging, zoomed by the wheel ---------------

const camera = new THREE.PerspectiveCamera(35, 1, D.die.reach / 10, 1000);
const view = { azimuth: -0.6, elevation: 0.45, zoom: 1 };
const start = throws.map((th) => position(th, 0));
function aim(t) {
  const centre = new THREE.Vector3();
  let extent = 0;
  const follow = document.getElementById("follow").checked;
  const at = throws.map((th, k) => (follow ? pose(th, t)[0] : start[k].clone()).add(offset(k)));
  for (const p of at) centre.add(p);
  centre.divideScalar(at.length);
  for (const p of at) extent = Math.max(extent, p.distanceTo(centre));
  if (!follow) for (const th of throws) for (let i = 0; i < th.n; i += 8) extent = Math.max(extent, position(th, i).distanceTo(centre));
  const r = Math.max(14 * D.die.reach, 2.6 * extent) * view.zoom;
  const ce = Math.cos(view.elevation);
  camera.position.set(centre.x + r * ce * Math.sin(view.azimuth), centre.y + r * Math.sin(view.elevation), centre.z + r * ce * Math.cos(view.azimuth));
  camera.lookAt(centre);
  camera.updateMatrixWorld();
  return centre;
}

let drag = null;
canvas.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
canvas.addEventListener("pointerup", () => { drag = null; });
canvas.addEventListener("pointermove", (e) => {
  if (!drag) return;
  view.azimuth -= (e.clientX - drag[0]) * 0.008;
  view.elevation = Math.min(1.5, Math.max(0.05, view.elevation + (e.clientY - drag[1]) * 0.008));
  drag = [e.clientX, e.clientY];
  draw();
});
canvas.addEventListener("wheel", (e) => { e.preventDefault(); view.zoom *= Math.exp(e.deltaY * 0.001); draw(); }, { passive: false });

// ---- the renderers ------------------------------------------------------------------------

/// A polygon's outward normal and centroid (body axes).
function facetFrame(corners) {
  const c = corners.map((p) => new THREE.Vector3(...p));
  const centroid = c.reduce((a, p) => a.add(p), new THREE.Vector3()).divideScalar(c.length);
  const n = new THREE.Vector3();
  for (let i = 0; i < c.length; i++) n.add(new THREE.Vector3().crossVectors(c[i], c[(i + 1) % c.length]));
  return { c, centroid, normal: n.normalize() };
}
const FACETS = D.die.polys.map((p) => ({ ...facetFrame(p.corners), label: p.label, pips: (p.pips || []).map((v) => new THREE.Vector3(...v)) }));
const PIP_RADIUS = D.die.pip_radius || 0;

function webgl() {
  const probe = document.createElement("canvas");
  if (hash.has("2d") || !(probe.getContext("webgl2") || probe.getContext("webgl"))) return null;
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  const scene = new THREE.Scene();
  scene.background = new THREE.Color("#dfe6ec");
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.8);
  sun.position.set(0.4, 1, 0.3);
  scene.add(sun);
  const floor = new THREE.Mesh(new THREE.PlaneGeometry(400 * D.die.reach, 400 * D.die.reach), new THREE.MeshLambertMaterial({ color: 0xc9c5b8 }));
  floor.rotation.x = -Math.PI / 2;
  scene.add(floor);
  const grid = new THREE.GridHelper(400 * D.die.reach, 200, 0x77736a, 0x8f8b80);
  grid.position.y = D.die.reach * 1e-3;
  scene.add(grid);
  const dice = throws.map((th) => { const g = dieMesh(th.colour); scene.add(g); return g; });
  const shadowMaterial = new THREE.MeshBasicMaterial({ color: 0x000000, transparent: true, opacity: 0.25, depthWrite: false });
  const shadows = throws.map(() => {
    const s = new THREE.Mesh(new THREE.CircleGeometry(0.8 * D.die.reach, 32), shadowMaterial);
    s.rotation.x = -Math.PI / 2;
    scene.add(s);
    return s;
  });
  const paths = throws.map((th) => { const l = pathLine(th); scene.add(l); return l; });
  return {
    name: "WebGL (three.js " + THREE.REVISION + ")",
    render(t, w, h) {
      renderer.setPixelRatio(window.devicePixelRatio || 1);
      renderer.setSize(w, h, false);
      throws.forEach((th, k) => {
        const [p, q] = pose(th, t);
        dice[k].position.copy(p.add(offset(k)));
        shadows[k].position.set(p.x, D.die.reach * 2e-3, p.z);
        dice[k].quaternion.copy(q);
        paths[k].position.copy(offset(k));
        paths[k].visible = document.getElementById("path").checked;
      });
      renderer.render(scene, camera);
    },
  };
}

/// A label on the die's colour, as a texture: its pips where it has them (`pips`, each at its
/// texture coordinates [u, v], `r` their radius in the same units), else its text.
function labelTexture(label, colour, pips, r) {
  const c = document.createElement("canvas");
  c.width = c.height = 128;
  const g = c.getContext("2d");
  g.fillStyle = colour;
  g.fillRect(0, 0, 128, 128);
  g.fillStyle = "#fff";
  if (pips.length) {
    // The texture's v runs up; the canvas's y down.
    for (const [u, v] of pips) { g.beginPath(); g.arc(u * 128, (1 - v) * 128, r * 128, 0, 2 * Math.PI); g.fill(); }
  } else {
    g.font = "bold " + (label.length > 2 ? 30 : 44) + "px DejaVu Sans, sans-serif";
    g.textAlign = "center";
    g.textBaseline = "middle";
    g.fillText(label, 64, 66);
  }
  const tex = new THREE.CanvasTexture(c);
  tex.colorSpace = THREE.SRGBColorSpace;
  return tex;
}

/// The die as three.js meshes: each labelled facet its own, textured with its label.
function dieMesh(colour) {
  const group = new THREE.Group();
  const plain = new THREE.MeshLambertMaterial({ color: colour });
  const rest = [];
  for (const f of FACETS) {
    if (!f.label) { for (let i = 1; i + 1 < f.c.length; i++) rest.push(f.c[0], f.c[i], f.c[i + 1]); continue; }
    const e1 = f.c[0].clone().sub(f.centroid).normalize();
    const e2 = new THREE.Vector3().crossVectors(f.normal, e1);
    const size = Math.max(...f.c.map((p) => p.distanceTo(f.centroid)));
    const uvOf = (p) => { const d = p.clone().sub(f.centroid); return [0.5 + d.dot(e1) / (2 * size), 0.5 + d.dot(e2) / (2 * size)]; };
    const uv = f.c.map(uvOf);
    const pos = [], uvs = [];
    for (let i = 1; i + 1 < f.c.length; i++) for (const j of [0, i, i + 1]) { pos.push(f.c[j].x, f.c[j].y, f.c[j].z); uvs.push(...uv[j]); }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute("position", new THREE.Float32BufferAttribute(pos, 3));
    geo.setAttribute("uv", new THREE.Float32BufferAttribute(uvs, 2));
    geo.computeVertexNormals();
    const tex = labelTexture(f.label, colour, f.pips.map(uvOf), PIP_RADIUS / (2 * size));
    group.add(new THREE.Mesh(geo, new THREE.MeshLambertMaterial({ map: tex })));
  }
  if (rest.length) {
    const geo = new THREE.BufferGeometry().setFromPoints(rest);
    geo.computeVertexNormals();
    group.add(new THREE.Mesh(geo, plain));
  }
  const edges = new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(FACETS.flatMap((f) => f.c.flatMap((p, i) => [p, f.c[(i + 1) % f.c.length]]))), new THREE.LineBasicMaterial({ color: 0x222222 }));
  if (FACETS.length < 60) group.add(edges);
  return group;
}

function pathLine(th) {
  const pts = [];
  for (let i = 0; i < th.n; i++) pts.push(position(th, i));
  return new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: th.colour }));
}

/// The 2D fallback: the same camera, the die's facets projected and painted far to near.
function flat() {
  const g = canvas.getContext("2d");
  const light = new THREE.Vector3(0.4, 1, 0.3).normalize();
  const toScreen = (v, w, h) => { const s = v.clone().project(camera); return [(s.x + 1) / 2 * w, (1 - s.y) / 2 * h, s.z]; };
  return {
    name: "2D canvas (no WebGL here)",
    render(t, w, h) {
      const ratio = window.devicePixelRatio || 1;
      canvas.width = Math.round(w * ratio); canvas.height = Math.round(h * ratio);
      g.setTransform(ratio, 0, 0, ratio, 0, 0);
      g.fillStyle = "#bdb9ad"; g.fillRect(0, 0, w, h);
      flatFloor(g, w, h, toScreen);
      const polys = [];
      throws.forEach((th, k) => {
        const [p, q] = pose(th, t);
        p.add(offset(k));
        flatShadow(g, p, w, h, toScreen);
        if (document.getElementById("path").checked) flatPath(g, th, offset(k), w, h, toScreen);
        for (const f of FACETS) {
          const n = f.normal.clone().applyQuaternion(q);
          const c = f.centroid.clone().applyQuaternion(q).add(p);
          if (n.dot(camera.position.clone().sub(c)) <= 0) continue;
          const pts = f.c.map((v) => toScreen(v.clone().applyQuaternion(q).add(p), w, h));
          const pips = f.pips.map((v) => toScreen(v.clone().applyQuaternion(q).add(p), w, h));
          polys.push({ pts, depth: c.distanceTo(camera.position), shade: 0.45 + 0.55 * Math.max(0, n.dot(light)), colour: th.colour, label: f.label, pips, pipR: f.pips.length ? PIP_RADIUS / f.c[0].distanceTo(f.centroid) : 0, at: toScreen(c, w, h) });
        }
      });
      polys.sort((a, b) => b.depth - a.depth);
      for (const p of polys) flatFacet(g, p);
    },
  };
}

function flatFloor(g, w, h, toScreen) {
  const centre = aimCentre, step = 2 * D.die.reach, n = 30;
  g.strokeStyle = "#8f8b80"; g.lineWidth = 1;
  const x0 = Math.round(centre.x / step) * step, z0 = Math.round(centre.z / step) * step;
  const at = (i, j, dir) => (dir ? new THREE.Vector3(x0 + i * step, 0, z0 + j * step) : new THREE.Vector3(x0 + j * step, 0, z0 + i * step));
  const inFront = (p) => p[2] > -1 && p[2] < 1;
  g.beginPath();
  for (let i = -n; i <= n; i++) for (const dir of [0, 1]) for (let j = -n; j < n; j++) {
    const [p, q] = [toScreen(at(i, j, dir), w, h), toScreen(at(i, j + 1, dir), w, h)];
    if (inFront(p) && inFront(q)) { g.moveTo(p[0], p[1]); g.lineTo(q[0], q[1]); }
  }
  g.stroke();
}

function flatShadow(g, p, w, h, toScreen) {
  g.fillStyle = "rgba(0,0,0,0.25)"; g.beginPath();
  for (let i = 0; i < 32; i++) {
    const a = (i / 32) * 2 * Math.PI, r = 0.8 * D.die.reach;
    const [x, y] = toScreen(new THREE.Vector3(p.x + r * Math.cos(a), 0, p.z + r * Math.sin(a)), w, h);
    if (i) g.lineTo(x, y); else g.moveTo(x, y);
  }
  g.fill();
}

function flatPath(g, th, off, w, h, toScreen) {
  g.strokeStyle = th.colour; g.lineWidth = 1.2; g.beginPath();
  for (let i = 0; i < th.n; i++) { const [x, y] = toScreen(position(th, i).add(off), w, h); if (i) g.lineTo(x, y); else g.moveTo(x, y); }
  g.stroke();
}

function shadeOf(hex, s) {
  const v = parseInt(hex.slice(1), 16);
  return "rgb(" + [(v >> 16) & 255, (v >> 8) & 255, v & 255].map((c) => Math.round(c * s)).join(",") + ")";
}

function flatFacet(g, p) {
  g.fillStyle = shadeOf(p.colour, p.shade);
  g.strokeStyle = "#222"; g.lineWidth = 0.8;
  g.beginPath();
  p.pts.forEach(([x, y], i) => (i ? g.lineTo(x, y) : g.moveTo(x, y)));
  g.closePath(); g.fill();
  // A finely divided surface (a rounded box's rims, a fine mesh) is drawn without its seams.
  if (FACETS.length < 60 || p.label) g.stroke();
  if (!p.label) return;
  const size = Math.min(...p.pts.map(([x, y]) => Math.hypot(x - p.at[0], y - p.at[1])));
  if (size < 5) return;
  if (p.pips.length) {
    // A pip's radius on screen: scaled as the face's first half diagonal is.
    const r = Math.max(1, p.pipR * Math.hypot(p.pts[0][0] - p.at[0], p.pts[0][1] - p.at[1]));
    g.fillStyle = "#fff";
    for (const [x, y] of p.pips) { g.beginPath(); g.arc(x, y, r, 0, 2 * Math.PI); g.fill(); }
    return;
  }
  g.fillStyle = "#fff"; g.font = "bold " + Math.round(size * 0.8) + "px DejaVu Sans, sans-serif";
  g.textAlign = "center"; g.textBaseline = "middle";
  g.fillText(p.label, p.at[0], p.at[1]);
}

// ---- the plots ----------------------------------------------------------------------------

/// Draws `series` (arrays of [t, value] per throw, each with colour and dash) against time,
/// with the cursor at t and each throw's early stop.
function plot(id, title, unit, series, t, zero) {
  const c = document.getElementById(id);
  const ratio = window.devicePixelRatio || 1;
  const w = c.clientWidth, h = c.clientHeight;
  c.width = Math.round(w * ratio); c.height = Math.round(h * ratio);
  const g = c.getContext("2d");
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  g.clearRect(0, 0, w, h);
  const L = 48, R = 8, T = 18, B = 22;
  let lo = Infinity, hi = -Infinity;
  for (const s of series) for (const v of s.v) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
  if (zero) lo = Math.min(0, lo);
  if (!(hi > lo)) { hi = lo + 1; }
  const X = (x) => L + (x / END) * (w - L - R), Y = (y) => h - B - ((y - lo) / (hi - lo)) * (h - T - B);
  g.font = "11px DejaVu Sans, sans-serif"; g.fillStyle = "#333"; g.strokeStyle = "#999"; g.lineWidth = 1;
  g.textAlign = "left"; g.textBaseline = "alphabetic"; g.fillText(title + " (" + unit + ")", L, 12);
  g.strokeRect(L, T, w - L - R, h - T - B);
  g.textAlign = "right";
  for (const v of [lo, (lo + hi) / 2, hi]) g.fillText(fmt(v), L - 4, Y(v) + 4);
  g.textAlign = "center";
  for (const x of [0, END / 2, END]) g.fillText(x.toFixed(2) + " s", X(x), h - 6);
  for (const s of series) {
    g.strokeStyle = s.colour; g.lineWidth = s.width || 1.3; g.setLineDash(s.dash || []);
    g.beginPath();
    s.t.forEach((x, i) => (i ? g.lineTo(X(x), Y(s.v[i])) : g.moveTo(X(x), Y(s.v[i]))));
    g.stroke();
  }
  g.setLineDash([4, 3]);
  for (const th of throws) if (th.early_stop) {
    g.strokeStyle = th.colour; g.beginPath(); g.moveTo(X(th.early_stop[0]), T); g.lineTo(X(th.early_stop[0]), h - B); g.stroke();
  }
  g.setLineDash([]); g.strokeStyle = "#000"; g.beginPath(); g.moveTo(X(t), T); g.lineTo(X(t), h - B); g.stroke();
}

function fmt(v) { return v === 0 ? "0" : Math.abs(v) >= 100 ? v.toFixed(0) : Math.abs(v) >= 1 ? v.toFixed(1) : v.toPrecision(2); }

const heights = throws.map((th) => ({ colour: th.colour, t: th.frames.t, v: th.frames.t.map((_, i) => th.frames.p[3 * i + 1] * 1e3) }));
const energies = throws.flatMap((th) => {
  const f = th.frames, k = f.k.map((x) => x * 1e3), tot = f.k.map((x, i) => (x + f.u[i]) * 1e3);
  const one = throws.length === 1;
  return [{ colour: th.colour, t: f.t, v: tot, width: 1.6 }]
    .concat(one ? [{ colour: "#1f6fb4", t: f.t, v: k, dash: [5, 3] }, { colour: "#2a9d3c", t: f.t, v: f.u.map((x) => x * 1e3), dash: [1.5, 2.5] }] : []);
});

// ---- the page: outcomes, controls, the loop -----------------------------------------------

function outcomes() {
  const box = document.getElementById("outcomes");
  for (const th of throws) {
    const last = faceOf(quaternion(th, th.n - 1));
    const d = document.createElement("div");
    const early = th.early_stop ? "; the early stop fired at " + th.early_stop[0].toFixed(3) + " s, naming " + th.early_stop[1] : "; the early stop never fired";
    d.innerHTML = '<span class="swatch"></span>';
    d.firstChild.style.background = th.colour;
    d.append(th.ending + early + "; the last frame shows " + last + ".");
    box.append(d);
  }
  document.getElementById("caption").textContent = D.die.name + ", " + D.engine + ", dt " + D.dt + " s; " +
    "height (solid) of the centre of mass; energy: total (solid)" + (throws.length === 1 ? ", kinetic (dashed), potential (dotted)" : "") +
    "; the dashed upright line is the early stop. Positions and turns are the trace's own, " + throws[0].n + " frames of throw " + throws[0].index + ".";
  body.dataset.finalFace = faceOf(quaternion(throws[0], throws[0].n - 1));
  body.dataset.outcome = throws[0].outcome ?? "";
}

let t = 0, playing = true, last = null;
let aimCentre = new THREE.Vector3();
const renderer = webgl() || flat();
document.getElementById("renderer").textContent = renderer.name;
body.dataset.renderer = renderer.name.startsWith("WebGL") ? "webgl" : "canvas2d";

function draw() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  aimCentre = aim(t);
  renderer.render(t, w, h);
  const s = pose(throws[0], t)[0].add(offset(0)).project(camera);
  const rect = canvas.getBoundingClientRect();
  body.dataset.centre = (rect.left + window.scrollX + (s.x + 1) / 2 * w).toFixed(1) + "," + (rect.top + window.scrollY + (1 - s.y) / 2 * h).toFixed(1);
  body.dataset.t = t.toFixed(4);
  body.dataset.faceNow = faceOf(pose(throws[0], t)[1]);
  document.getElementById("time").textContent = "t = " + t.toFixed(3) + " s of " + END.toFixed(3);
  document.getElementById("scrub").value = Math.round((t / END) * 1000);
  plot("plot-height", "height of the centre of mass", "mm", heights, t);
  plot("plot-energy", "energy", "mJ", energies, t, true);
}

function frame(now) {
  if (playing) {
    if (last !== null) t = Math.min(END, t + ((now - last) / 1000) * Number(document.getElementById("speed").value));
    last = now;
    if (t >= END) setPlaying(false);
    draw();
  }
  if (playing) requestAnimationFrame(frame);
}

function setPlaying(on) {
  playing = on;
  last = null;
  document.getElementById("play").textContent = on ? "Pause" : "Play";
  if (on) { if (t >= END) t = 0; requestAnimationFrame(frame); }
}

document.getElementById("play").addEventListener("click", () => setPlaying(!playing));
document.getElementById("scrub").addEventListener("input", (e) => { setPlaying(false); t = (e.target.value / 1000) * END; draw(); });
for (const id of ["side", "path", "follow"]) document.getElementById(id).addEventListener("change", draw);
window.addEventListener("resize", draw);

outcomes();
if (hash.has("t")) {
  t = hash.get("t") === "end" ? END : Math.min(END, Math.max(0, Number(hash.get("t")) || 0));
  playing = false;
  document.getElementById("play").textContent = "Play";
  draw();
} else {
  draw();
  requestAnimationFrame(frame);
}
body.dataset.loadMs = performance.now().toFixed(0);
body.dataset.ready = "1";
