// bayesgrasp page: plain JavaScript, no build step. State lives in the URL hash.
"use strict";

const API = "/api/v1";
const SVGNS = "http://www.w3.org/2000/svg";
const GRID = 20; // canvas pixels a grid cell
const UNIT = 5; // part units (mm) a grid cell
const SIZE = 400;
const TWO_PI = 2 * Math.PI;
const deg = (r) => (r * 180) / Math.PI;

const state = {
  vertices: [], // drawn or pasted [[x, y], ...] in part units
  catalogue: "",
  file: null, // {format, data_base64, name}
  name: "drawn",
  last: null, // {plan, squeeze, push}
};

const $ = (id) => document.getElementById(id);

function el(tag, attrs, parent) {
  const e = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}

function setStatus(text, error) {
  const s = $("status");
  s.textContent = text;
  s.className = error ? "error" : "";
}

// ---- drawing ---------------------------------------------------------------------------

// The canvas's view of the part's plane: part units per canvas pixel, and the point of the
// plane at the canvas's bottom-left corner (y up). The default shows 0-100 mm on a 5 mm grid;
// the wheel zooms about the pointer, shift+drag pans, Fit frames the part. A catalogue or
// uploaded part is framed when chosen (auto), until the user zooms or pans.
const DEFAULT_VIEW = { upp: UNIT / GRID, x0: 0, y0: 0 };
const view = { ...DEFAULT_VIEW, auto: true };
const toPart = (px, py) => [view.x0 + px * view.upp, view.y0 + (SIZE - py) * view.upp];
const toCanvas = (x, y) => [(x - view.x0) / view.upp, SIZE - (y - view.y0) / view.upp];

function gridStep() {
  // a round step of the grid (1, 2 or 5 times a power of ten) about 20 pixels wide
  const want = 20 * view.upp;
  const p = 10 ** Math.floor(Math.log10(want));
  return [1, 2, 5, 10].map((m) => m * p).find((step) => step >= 0.75 * want);
}

function canvasPixel(evt) {
  const r = $("canvas").getBoundingClientRect();
  return [((evt.clientX - r.left) * SIZE) / r.width, ((evt.clientY - r.top) * SIZE) / r.height];
}

function canvasPoint(evt) {
  // the part's point under the pointer, on the grid when snapping
  const step = gridStep();
  const q = $("snap").checked ? step : step / 5000;
  return toPart(...canvasPixel(evt)).map((v) => Number((Math.round(v / q) * q).toPrecision(12)));
}

function fitView(points) {
  // frame the points with a margin of 24 pixels (nothing to frame: the default view)
  if (!points || !points.length) {
    Object.assign(view, DEFAULT_VIEW);
    return;
  }
  const xs = points.map((p) => p[0]), ys = points.map((p) => p[1]);
  const [lx, hx, ly, hy] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const span = Math.max(hx - lx, hy - ly);
  if (span > 0) view.upp = span / (SIZE - 48);
  view.x0 = (lx + hx) / 2 - (SIZE / 2) * view.upp;
  view.y0 = (ly + hy) / 2 - (SIZE / 2) * view.upp;
}

function inView(points) {
  return points.every(([x, y]) => {
    const [px, py] = toCanvas(x, y);
    return px >= 0 && px <= SIZE && py >= 0 && py <= SIZE;
  });
}

function hull(points) {
  // Andrew's monotone chain (counter-clockwise); drawing only, the server computes its own.
  const p = points.map((q) => q.slice()).sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  if (p.length < 3) return p;
  const cross = (o, a, b) => (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  const lower = [];
  for (const q of p) {
    while (lower.length >= 2 && cross(lower[lower.length - 2], lower[lower.length - 1], q) <= 0)
      lower.pop();
    lower.push(q);
  }
  const upper = [];
  for (const q of p.slice().reverse()) {
    while (upper.length >= 2 && cross(upper[upper.length - 2], upper[upper.length - 1], q) <= 0)
      upper.pop();
    upper.push(q);
  }
  return lower.slice(0, -1).concat(upper.slice(0, -1));
}

let undoStack = [];
let dragging = -1;

function drawCanvas() {
  const svg = $("canvas");
  svg.replaceChildren();
  const given = (state.catalogue || state.file) && state.outline && state.outline.length >= 3;
  if (given && view.auto) fitView(state.outline);
  const step = gridStep();
  const [x0, y1] = toPart(0, 0), [x1, y0] = toPart(SIZE, SIZE);
  for (let x = Math.ceil(x0 / step) * step; x <= x1; x += step) {
    const [px] = toCanvas(x, 0);
    el("line", { x1: px, y1: 0, x2: px, y2: SIZE, class: "grid" }, svg);
  }
  for (let y = Math.ceil(y0 / step) * step; y <= y1; y += step) {
    const [, py] = toCanvas(0, y);
    el("line", { x1: 0, y1: py, x2: SIZE, y2: py, class: "grid" }, svg);
  }
  svg.dataset.grid = String(step);
  const units = !given ? "mm" : state.last ? state.last.plan.part.units || "" : "";
  $("grid-step").textContent = `${Number(step.toPrecision(6))} ${units}`.trim();
  if (given) {
    // a catalogue or uploaded part (it is not edited here)
    const pts = state.outline.map(([x, y]) => toCanvas(x, y).join(","));
    el("polygon", { points: pts.join(" "), class: "poly", id: "given-part" }, svg);
  }
  const pts = state.vertices.map((v) => toCanvas(v[0], v[1]));
  if (pts.length >= 2) el("polygon", { points: pts.map((p) => p.join(",")).join(" "), class: "poly" }, svg);
  if (pts.length >= 3) {
    const h = hull(state.vertices).map((v) => toCanvas(v[0], v[1]));
    el("polygon", { points: h.map((p) => p.join(",")).join(" "), class: "hull" }, svg);
  }
  pts.forEach((p, i) => {
    const c = el("circle", { cx: p[0], cy: p[1], r: 6, class: "vertex", "data-index": i }, svg);
    c.addEventListener("pointerdown", (evt) => {
      evt.stopPropagation();
      undoStack.push(state.vertices.map((v) => v.slice()));
      dragging = i;
      svg.setPointerCapture(evt.pointerId);
    });
  });
  const short = (x) => String(Number(x.toPrecision(6)));
  $("coords").value = state.vertices.map((v) => `${short(v[0])}, ${short(v[1])}`).join("\n");
}

let panning = null; // shift+drag: where the drag started, and the view then

function setupCanvas() {
  const svg = $("canvas");
  svg.addEventListener("pointerdown", (evt) => {
    if (evt.shiftKey || evt.button === 1) {
      const [px, py] = canvasPixel(evt);
      panning = { px, py, x0: view.x0, y0: view.y0 };
      svg.setPointerCapture(evt.pointerId);
      evt.preventDefault();
      return;
    }
    undoStack.push(state.vertices.map((v) => v.slice()));
    useVertices(state.vertices.concat([canvasPoint(evt)]), "drawn");
  });
  svg.addEventListener("pointermove", (evt) => {
    if (panning) {
      const [px, py] = canvasPixel(evt);
      view.x0 = panning.x0 - (px - panning.px) * view.upp;
      view.y0 = panning.y0 + (py - panning.py) * view.upp;
      view.auto = false;
      drawCanvas();
      return;
    }
    if (dragging < 0) return;
    state.vertices[dragging] = canvasPoint(evt);
    drawCanvas();
  });
  svg.addEventListener("pointerup", () => {
    panning = null;
    if (dragging >= 0) {
      dragging = -1;
      useVertices(state.vertices, state.name);
    }
  });
  svg.addEventListener(
    "wheel",
    (evt) => {
      // zoom about the pointer: the part's point under it stays there
      evt.preventDefault();
      const [px, py] = canvasPixel(evt);
      const [x, y] = toPart(px, py);
      view.upp *= evt.deltaY > 0 ? 1.25 : 0.8;
      view.x0 = x - px * view.upp;
      view.y0 = y - (SIZE - py) * view.upp;
      view.auto = false;
      drawCanvas();
    },
    { passive: false },
  );
  $("fit").addEventListener("click", () => {
    const given = (state.catalogue || state.file) && state.outline;
    fitView(given ? state.outline : state.vertices);
    view.auto = Boolean(given);
    drawCanvas();
  });
  $("undo").addEventListener("click", () => {
    if (undoStack.length) useVertices(undoStack.pop(), state.name);
  });
  $("clear").addEventListener("click", () => {
    undoStack.push(state.vertices.map((v) => v.slice()));
    fitView([]); // drawing starts again on the 5 mm grid
    useVertices([], "drawn");
  });
  $("use-coords").addEventListener("click", () => {
    const pts = [];
    for (const line of $("coords").value.split(/\n|;/)) {
      const nums = line.split(/[\s,]+/).filter((s) => s.length).map(Number);
      if (nums.length === 0) continue;
      if (nums.length !== 2 || nums.some((n) => !Number.isFinite(n))) {
        setStatus(`cannot read the line ${JSON.stringify(line)}: expected x, y`, true);
        return;
      }
      pts.push(nums);
    }
    undoStack.push(state.vertices.map((v) => v.slice()));
    if (!inView(pts)) fitView(pts); // pasted coordinates are always seen whole
    useVertices(pts, "pasted");
  });
}

function useVertices(vertices, name) {
  showFileName("");
  state.vertices = vertices;
  state.catalogue = "";
  state.file = null;
  state.name = name || "drawn";
  $("catalogue").value = "";
  drawCanvas();
  schedule();
}

// ---- options and the URL ---------------------------------------------------------------

function options() {
  const prior =
    $("prior-kind").value === "vonmises"
      ? `vonmises:${Number($("prior-mean").value)},${Number($("prior-kappa").value)}`
      : "uniform";
  const actions = ["squeeze", "push-grasp"].filter((a) => $(`act-${a}`).checked);
  const o = {
    prior,
    actions: actions.join(","),
    costs: Object.fromEntries(actions.map((a) => [a, Number($(`cost-${a}`).value)])),
    verify_cost: Number($("cost-verify").value),
    retry_cost: Number($("cost-retry").value),
    accuracy: Number($("accuracy").value),
    goal: $("goal").value,
    method: $("method").value,
  };
  if ($("max-actions").value) o.max_actions = Number($("max-actions").value);
  return o;
}

// the noise of the plan endpoint (the noise-aware Bayes plan); the other endpoints take none
function noise() {
  const o = {};
  if ($("turn-kind").value) o.turn_noise = `${$("turn-kind").value}:${Number($("turn-deg").value)}`;
  if ($("contact-noise").value !== "") o.contact_noise = Number($("contact-noise").value);
  const pay = $("payoff").value.trim();
  if (pay) {
    try {
      o.payoff = { payoff: JSON.parse(pay), default: 0 };
    } catch (err) {
      /* validate() reports it */
    }
  }
  return o;
}

// the gripper's opening limits (plan and policy requests, and the robot files)
function stroke() {
  const o = {};
  if ($("max-opening").value.trim() !== "") o.max_opening = Number($("max-opening").value);
  if ($("min-opening").value.trim() !== "") o.min_opening = Number($("min-opening").value);
  if ($("within-stroke").checked) o.within_stroke = true;
  return o;
}

function partBody() {
  if (state.catalogue) return { catalogue: state.catalogue };
  if (state.file) return { file: { format: state.file.format, data_base64: state.file.data_base64 }, name: state.file.name };
  return { vertices: state.vertices, name: state.name };
}

// the animation's and the simulation's settings: in the address too, but they plan nothing
const VIEW_SETTINGS = [
  ["anim-plan", "anim_plan"],
  ["anim-starts", "anim_starts"],
  ["anim-n", "anim_n"],
  ["anim-seed", "anim_seed"],
  ["sim-engine", "sim_engine"],
  ["sim-trials", "sim_trials"],
  ["sim-offset", "sim_offset"],
  ["sim-lag", "sim_lag"],
  ["sim-seed", "sim_seed"],
];

function writeHash() {
  const q = new URLSearchParams();
  if (state.catalogue) q.set("part", state.catalogue);
  else if (state.file && state.file.packed) {
    q.set("file", state.file.packed);
    q.set("format", state.file.format);
    q.set("name", state.file.name);
  } else if (state.vertices.length) q.set("v", state.vertices.map((v) => v.join(",")).join(";"));
  const o = options();
  q.set("prior", o.prior);
  q.set("actions", o.actions);
  for (const k of ["verify_cost", "retry_cost", "accuracy", "goal", "method", "max_actions"])
    if (o[k] !== undefined) q.set(k, o[k]);
  if ($("guaranteed").checked) q.set("guaranteed", "1");
  const g = stroke();
  for (const k of ["max_opening", "min_opening"]) if (g[k] !== undefined) q.set(k, g[k]);
  if (g.within_stroke) q.set("within_stroke", "1");
  q.set("squeeze_cost", $("cost-squeeze").value);
  q.set("push_grasp_cost", $("cost-push-grasp").value);
  const n = noise();
  for (const k of ["turn_noise", "contact_noise"]) if (n[k] !== undefined) q.set(k, n[k]);
  if ($("payoff").value.trim()) q.set("payoff", $("payoff").value.trim());
  q.set("sense", $("sense").value.trim() || "width");
  q.set("sense_depth", $("sense-depth").value);
  for (const [id, key] of VIEW_SETTINGS) if ($(id).value !== "") q.set(key, $(id).value);
  if (!$("sim-trials").dataset.edited) q.delete("sim_trials"); // the engine's default
  window.history.replaceState(null, "", "#" + q.toString());
}

async function readHash() {
  const q = new URLSearchParams(window.location.hash.slice(1));
  if (q.has("file")) {
    try {
      const text = await unpack(q.get("file"));
      const format = q.get("format") || "svg";
      const name = q.get("name") || "part";
      state.file = { format, data_base64: btoa(text), name, packed: q.get("file") };
      view.auto = true;
      state.catalogue = "";
      state.vertices = [];
      showFileName(`${name}.${format}`);
    } catch (err) {
      setStatus(`the file in the address cannot be read: ${err.message || err}`, true);
    }
  }
  const prior = q.get("prior") || "uniform";
  if (prior.startsWith("vonmises:")) {
    const [m, k] = prior.slice(9).split(",");
    $("prior-kind").value = "vonmises";
    $("prior-mean").value = m;
    $("prior-kappa").value = k;
  } else $("prior-kind").value = "uniform";
  const acts = (q.get("actions") || "squeeze").split(",");
  $("act-squeeze").checked = acts.includes("squeeze");
  $("act-push-grasp").checked = acts.includes("push-grasp");
  const set = (id, key) => {
    if (q.has(key)) $(id).value = q.get(key);
  };
  set("cost-verify", "verify_cost");
  set("cost-retry", "retry_cost");
  set("accuracy", "accuracy");
  set("goal", "goal");
  set("method", "method");
  set("max-actions", "max_actions");
  $("guaranteed").checked = q.get("guaranteed") === "1";
  $("max-opening").value = q.get("max_opening") || "";
  $("min-opening").value = q.get("min_opening") || "";
  $("within-stroke").checked = q.get("within_stroke") === "1";
  set("cost-squeeze", "squeeze_cost");
  set("cost-push-grasp", "push_grasp_cost");
  set("sense", "sense");
  $("payoff").value = q.get("payoff") || "";
  set("sense-depth", "sense_depth");
  const [kind, turnDeg] = (q.get("turn_noise") || "").split(":");
  $("turn-kind").value = kind === "normal" || kind === "uniform" ? kind : "";
  if ($("turn-kind").value) $("turn-deg").value = turnDeg;
  $("contact-noise").value = q.has("contact_noise") ? q.get("contact_noise") : "";
  for (const [id, key] of VIEW_SETTINGS) if (q.has(key) && id !== "anim-plan") $(id).value = q.get(key);
  if (q.has("sim_trials")) $("sim-trials").dataset.edited = "1";
  state.wantPlan = q.get("anim_plan"); // chosen once the plan's rows are known
  if (q.get("part")) {
    state.catalogue = q.get("part");
    $("catalogue").value = state.catalogue;
    state.vertices = [];
    state.file = null;
    showFileName("");
    const entry = (state.catalogueParts || []).find((p) => p.name === state.catalogue);
    state.outline = entry ? entry.outline : null;
    view.auto = true; // framed when drawn
  } else if (q.get("v")) {
    state.vertices = q.get("v").split(";").map((s) => s.split(",").map(Number));
    if (!inView(state.vertices)) fitView(state.vertices);
    state.name = "drawn";
    state.catalogue = "";
    state.file = null;
    $("catalogue").value = "";
    showFileName("");
  }
}

// ---- calls -----------------------------------------------------------------------------

async function post(path, body) {
  const r = await fetch(API + path, {
    method: "POST",
    headers: { "content-type": "application/json" },
    body: JSON.stringify(body),
  });
  const doc = await r.json();
  if (!r.ok) {
    const err = new Error(doc.detail || `HTTP ${r.status}`);
    err.status = r.status;
    throw err;
  }
  return doc;
}

// A noise-aware plan is refused at once (503, "busy") while another is at work on the server;
// the page asks again while its request is still the latest one (the previous plan finishes
// within the server's time limit).
async function postWhenFree(path, body, gen) {
  for (let i = 0; ; i++) {
    try {
      return await post(path, body);
    } catch (err) {
      const busy = err.status === 503 && /busy/.test(String(err.message));
      if (!busy || gen !== generation || i >= 80) throw err;
      setStatus("planning... (waiting for the previous noise-aware plan)");
      await new Promise((done) => setTimeout(done, 250));
    }
  }
}

let timer = null;
let generation = 0;
let planning = null; // the plan in progress, if any
function schedule() {
  clearTimeout(timer);
  timer = setTimeout(run, 150);
}

async function run() {
  clearTimeout(timer); // a click on Plan replaces the run an input change scheduled
  timer = null;
  const p = planNow();
  planning = p;
  try {
    await p;
  } finally {
    if (planning === p) planning = null;
  }
}

async function settled() {
  // An input's change plans 150 ms later; a click on Simulate, Plan the policy or Show
  // figures right after typing (the click itself ends the typing) waits for that plan, so
  // that what it shows is of the options on screen and the new plan does not clear it.
  if (timer !== null) await run();
  else if (planning) await planning;
}

async function planNow() {
  const part = partBody();
  if (!state.catalogue && !state.file && state.vertices.length < 3) {
    generation++; // a plan still on its way is of the part before
    clearResults(); // and so are the results on screen
    setStatus("add at least three vertices (or choose a part)");
    return;
  }
  if (!validate()) {
    generation++;
    clearResults();
    return;
  }
  writeHash();
  const gen = ++generation;
  clearSimulation(); // the simulation was of the previous plan
  clearPolicy(); // and the policy of the previous options
  clearFigureImages();
  clearInterval(animTimer); // its plan is being replaced
  setStatus("planning...");
  $("output").classList.add("stale");
  state.functions = null; // the figures follow the new plan, never show the previous one
  $("belief").replaceChildren();
  const o = options();
  const n = noise();
  try {
    const [plan, squeeze, push] = await Promise.all([
      postWhenFree("/plan", { part, ...o, ...n, ...stroke(), ...($("guaranteed").checked ? { guaranteed: true } : {}) }, gen),
      post("/squeeze", { part, prior: o.prior }),
      // the push-grasp function: an action, or what a squeeze becomes under contact noise
      o.actions.includes("push-grasp") || n.contact_noise > 0 ? post("/push", { part, prior: o.prior }) : Promise.resolve(null),
    ]);
    if (gen !== generation) return;
    $("output").classList.remove("stale");
    // with the options they were planned under: the animation draws those, not the inputs'
    // values while the next plan is on its way
    state.last = { plan, squeeze, push, noise: n, goal: o.goal, prior: o.prior };
    if (state.file) {
      state.outline = plan.part.vertices; // the hull of the exact model
      drawCanvas();
    }
    drawHull(plan.part);
    drawDiameter(plan.part, squeeze);
    drawTable(plan);
    fillPlanSelector(plan);
    writeHash(); // with the row the selector shows
    clearInterval(animTimer);
    drawAnimationFrame(0);
    loadFunctions(part, o, gen);
    const rows = plan.options.length;
    setStatus(`${plan.part.name}: ${plan.part.n_sides} sides, ${rows} ${rows === 1 ? "plan" : "plans"}`);
    document.body.dataset.planned = String(gen);
  } catch (err) {
    if (gen !== generation) return;
    clearResults();
    setStatus(String(err.message || err), true);
    document.body.dataset.planned = "error";
  }
}

// ---- figures (drawn from the API's data) ---------------------------------------------------

function rotate(points, theta) {
  const c = Math.cos(theta), s = Math.sin(theta);
  return points.map(([x, y]) => [c * x - s * y, s * x + c * y]);
}

function width(points, theta) {
  const xs = rotate(points, theta).map((p) => p[0]);
  return Math.max(...xs) - Math.min(...xs);
}

function fit(points, box, pad) {
  const xs = points.map((p) => p[0]), ys = points.map((p) => p[1]);
  const x0 = Math.min(...xs), x1 = Math.max(...xs), y0 = Math.min(...ys), y1 = Math.max(...ys);
  const k = (box - 2 * pad) / Math.max(x1 - x0, y1 - y0, 1e-9);
  const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  return ([x, y]) => [box / 2 + (x - cx) * k, box / 2 - (y - cy) * k];
}

function drawHull(part) {
  const svg = $("hull");
  svg.replaceChildren();
  const outline = state.vertices.length >= 3 ? state.vertices : part.vertices;
  const f = fit(outline.concat(part.vertices), 240, 16);
  el("polygon", { points: outline.map((p) => f(p).join(",")).join(" "), fill: "#9fb8d6", stroke: "#2f4b6e" }, svg);
  el("polygon", { points: part.vertices.map((p) => f(p).join(",")).join(" "), fill: "none", stroke: "#d62728", "stroke-dasharray": "4 3", id: "hull-polygon" }, svg);
}

function drawDiameter(part, squeeze) {
  const svg = $("diameter");
  svg.replaceChildren();
  const W = 480, H = 240, L = 40, R = 10, T = 10, B = 30;
  const n = 721;
  const ds = [];
  for (let i = 0; i < n; i++) ds.push(width(part.vertices, (i / (n - 1)) * TWO_PI));
  const dmax = Math.max(...ds) * 1.05;
  const X = (t) => L + ((W - L - R) * t) / TWO_PI;
  const Y = (d) => H - B - ((H - T - B) * d) / dmax;
  squeeze.basins_rad.forEach(([lo, hi], i) => {
    for (const k of [-1, 0, 1]) {
      const a = Math.max(0, lo + k * TWO_PI), b = Math.min(TWO_PI, hi + k * TWO_PI);
      if (b > a)
        el("rect", { x: X(a), y: T, width: X(b) - X(a), height: H - T - B, fill: i % 2 ? "#eef3fa" : "#f9f4ea", class: "basin" }, svg);
    }
  });
  const path = ds.map((d, i) => `${i ? "L" : "M"}${X((i / (n - 1)) * TWO_PI).toFixed(1)},${Y(d).toFixed(1)}`).join("");
  el("path", { d: path, fill: "none", stroke: "#2f4b6e", "stroke-width": 1.5, id: "diameter-curve" }, svg);
  squeeze.stable_orientations_rad.forEach((s, i) => {
    const t = ((s % TWO_PI) + TWO_PI) % TWO_PI;
    const c = el("circle", { cx: X(t), cy: Y(width(part.vertices, t)), r: 4, fill: "#d62728", class: "stable" }, svg);
    el("title", {}, c).textContent = `stable ${deg(t).toFixed(2)} deg, p = ${squeeze.probabilities[i].toFixed(4)}`;
  });
  el("line", { x1: L, y1: H - B, x2: W - R, y2: H - B, stroke: "#555" }, svg);
  for (let a = 0; a <= 360; a += 90) {
    const t = el("text", { x: X((a * Math.PI) / 180), y: H - 12, "text-anchor": "middle", "font-size": 11 }, svg);
    t.textContent = `${a}`;
  }
  const lbl = el("text", { x: 4, y: 14, "font-size": 11 }, svg);
  lbl.textContent = "d(θ)";
}

function drawTable(plan) {
  const body = $("plans").querySelector("tbody");
  body.replaceChildren();
  plan.options.forEach((o, i) => {
    const tr = document.createElement("tr");
    tr.dataset.index = i;
    if (i === plan.bayes) tr.classList.add("bayes");
    if (i === plan.most_certain) tr.classList.add("most-certain");
    const tags = o.steps.map((s) => (s.type === "squeeze" ? "S" : "P")).join("");
    const angles = o.steps.map((s) => deg(s.alpha_rad).toFixed(2)).join(", ");
    const cells = [
      [o.squeezes, `${o.squeezes} ${tags}`, "squeezes"],
      [o.steps.map((s) => s.alpha_rad).join(","), angles, "angles"],
      [o.final_orientation_rad, deg(o.final_orientation_rad).toFixed(2), "final"],
      [o.success_probability, o.success_probability.toFixed(4), "success"],
      [o.expected_cost, o.expected_cost === null ? "-" : o.expected_cost.toFixed(3), "cost"],
      [o.tolerance_rad, o.tolerance_rad === null ? "-" : deg(o.tolerance_rad).toFixed(2), "tolerance"],
    ];
    for (const [value, text, key] of cells) {
      const td = document.createElement("td");
      td.textContent = text;
      td.dataset.key = key;
      td.dataset.value = value === null ? "null" : String(value);
      tr.appendChild(td);
    }
    const mark = document.createElement("td");
    mark.className = "mark";
    mark.textContent = [i === plan.bayes ? "Bayes" : "", i === plan.most_certain ? "most certain" : ""].filter(Boolean).join(", ");
    tr.appendChild(mark);
    body.appendChild(tr);
  });
  if (plan.guaranteed) {
    // the guaranteed plan (plan --guaranteed): every start ends at its final orientation
    const g = plan.guaranteed;
    const tr = document.createElement("tr");
    tr.className = "guaranteed";
    tr.dataset.index = "guaranteed";
    const cells = [
      [g.squeezes, `${g.squeezes} ${g.steps.map((s) => (s.type === "squeeze" ? "S" : "P")).join("")}`],
      [null, g.steps.map((s) => deg(s.alpha_rad).toFixed(2)).join(", ")],
      [null, deg(g.final_orientation_rad).toFixed(2)],
      [null, g.success_probability.toFixed(4)],
      [null, g.expected_cost == null ? "-" : g.expected_cost.toFixed(3)],
      [null, g.tolerance_rad == null ? "-" : deg(g.tolerance_rad).toFixed(2)],
    ];
    for (const [, text] of cells) {
      const td = document.createElement("td");
      td.textContent = text;
      tr.appendChild(td);
    }
    const mark = document.createElement("td");
    mark.className = "mark";
    mark.textContent = "guaranteed";
    tr.appendChild(mark);
    body.appendChild(tr);
  }
}

// ---- animation of a chosen plan from starting orientations ------------------------------------

function transfer(theta, doc) {
  // the step function of a transfer document: the stable orientation of theta's basin
  const b = doc.basins_rad;
  const lo = b[0][0], span = b[b.length - 1][1] - lo;
  const k = Math.floor((theta - lo) / span);
  const t = theta - k * span;
  for (let i = 0; i < b.length; i++) if (t >= b[i][0] && t < b[i][1]) return doc.stable_orientations_rad[i] + k * span;
  return doc.stable_orientations_rad[b.length - 1] + k * span;
}

function wrap(a) {
  return a - TWO_PI * Math.round(a / TWO_PI);
}

function near(a, ref, period) {
  // the copy of a (modulo period) nearest to ref: the part turns the short way
  return a - period * Math.round((a - ref) / period);
}

function chosenPlan() {
  // the plan the selector names: a row of the table (its index) or "guaranteed"
  const { plan } = state.last;
  const v = $("anim-plan").value;
  if (v === "guaranteed" && plan.guaranteed) return plan.guaranteed;
  const i = Number(v);
  return Number.isInteger(i) && plan.options[i] ? plan.options[i] : plan.options[plan.bayes];
}

function fillPlanSelector(plan) {
  const sel = $("anim-plan");
  sel.replaceChildren();
  const add = (value, text) => {
    const o = document.createElement("option");
    o.value = value;
    o.textContent = text;
    sel.appendChild(o);
  };
  const label = (o) => {
    const n = o.steps.length;
    return `${n} ${n === 1 ? "action" : "actions"} ${o.steps.map((s) => (s.type === "squeeze" ? "S" : "P")).join("")}, p = ${o.success_probability.toFixed(3)}`;
  };
  plan.options.forEach((o, i) => {
    const marks = [i === plan.bayes ? "Bayes" : "", i === plan.most_certain ? "most certain" : ""].filter(Boolean).join(", ");
    add(String(i), marks ? `${marks}: ${label(o)}` : label(o));
  });
  if (plan.guaranteed) add("guaranteed", `guaranteed: ${label(plan.guaranteed)}`);
  sel.value = String(plan.bayes); // a new plan's rows are other plans: start from its Bayes plan
  if (state.wantPlan && [...sel.options].some((o) => o.value === state.wantPlan)) sel.value = state.wantPlan;
  state.wantPlan = null; // an address's choice holds for the plan it opens with
}

// a small seeded generator (mulberry32), so a seed gives the same starts in every browser
function rng(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

function vonMises(rand, mu, kappa) {
  // Best and Fisher (1979), "Efficient simulation of the von Mises distribution", Appl. Stat. 28
  if (kappa < 1e-8) return rand() * TWO_PI;
  const tau = 1 + Math.sqrt(1 + 4 * kappa * kappa);
  const rho = (tau - Math.sqrt(2 * tau)) / (2 * kappa);
  const r = (1 + rho * rho) / (2 * rho);
  for (;;) {
    const z = Math.cos(Math.PI * rand());
    const f = (1 + r * z) / (r + z);
    const c = kappa * (r - f);
    const u2 = rand();
    if (c * (2 - c) - u2 > 0 || Math.log(c / u2) + 1 - c >= 0) {
      const th = mu + (rand() > 0.5 ? Math.acos(f) : -Math.acos(f));
      return ((th % TWO_PI) + TWO_PI) % TWO_PI;
    }
  }
}

function startOrientations() {
  // eight evenly spaced starts, or N drawn from the prior with the seed
  if ($("anim-starts").value !== "random") {
    const starts = [];
    for (let i = 0; i < 8; i++) starts.push((i + 0.5) * (TWO_PI / 8) + 0.05);
    return starts;
  }
  const n = Math.max(1, Math.min(400, Math.floor(Number($("anim-n").value)) || 1));
  const rand = rng(Math.floor(Number($("anim-seed").value)) || 0);
  const prior = state.last.prior; // the plan's, not an input's while the next plan is on its way
  const [mean, kappa] = prior.startsWith("vonmises:") ? prior.slice(9).split(",").map(Number) : [0, 0];
  const starts = [];
  for (let i = 0; i < n; i++) starts.push(kappa > 0 ? vonMises(rand, (mean * Math.PI) / 180, kappa) : rand() * TWO_PI);
  return starts;
}

function animationNoise() {
  // the plan's turn error (radians) and contact noise, drawn as the kinematic simulator
  // draws them (bayesgrasp.sim.kinematic): every commanded angle gets its own error e (the
  // part turns by alpha + e), and a squeeze is, with probability q, a push-grasp from the
  // gripper's -x side or its +x side, equally likely (a push-grasp step is not affected)
  const n = state.last.noise;
  const [kind, a] = (n.turn_noise || "").split(":");
  return { kind, scale: n.turn_noise ? (Number(a) * Math.PI) / 180 : 0, contact: n.contact_noise || 0, payoff: n.payoff ? n.payoff.payoff : null };
}

function positivePayoff(payoff, t) {
  // whether a payoff's value at orientation t is positive: its listed orientations match a
  // stable orientation within 0.05 deg (bayesgrasp.model.payoff.MATCH_DEG); others pay 0
  const d = ((deg(t) % 360) + 360) % 360;
  return Object.entries(payoff).some(([k, v]) => v > 0 && Math.abs((((d - Number(k)) % 360) + 540) % 360 - 180) <= 0.05);
}

function trajectories() {
  // each start's segments: a turn, then a squeeze (both jaws close) or, for a push-grasp, a
  // push (one jaw turns the part to the push function's rest) and a close (the other jaw)
  const { plan, squeeze, push } = state.last;
  const o = chosenPlan();
  const order = plan.part.symmetry_order || 1;
  const goalPeriod = state.last.goal === "symmetry" ? TWO_PI / order : TWO_PI;
  const nz = animationNoise();
  // the noise's draws: a stream of their own, so that the starts are those without noise
  const rand = rng(((Math.floor(Number($("anim-seed").value)) || 0) + 0x9e3779b9) >>> 0);
  const gauss = () => Math.sqrt(-2 * Math.log(1 - rand())) * Math.cos(TWO_PI * rand()); // Box-Muller
  return startOrientations().map((t0) => {
    const segs = [];
    const errors = [];
    const contacts = [];
    let t = t0;
    for (const s of o.steps) {
      const e = nz.scale === 0 ? 0 : nz.kind === "normal" ? nz.scale * gauss() : nz.scale * (2 * rand() - 1);
      const turned = t - s.alpha_rad - e;
      errors.push(e);
      segs.push({ kind: "turn", from: t, to: turned });
      let side = s.type === "squeeze" ? null : "left";
      if (s.type === "squeeze" && nz.contact > 0) {
        const u = rand();
        side = u < nz.contact / 2 ? "left" : u < nz.contact ? "right" : null;
        contacts.push(side || "");
      } else contacts.push("");
      if (!side) {
        t = transfer(turned, squeeze);
        // under contact noise other cells push first: this one waits, so steps stay in time
        if (nz.contact > 0) segs.push({ kind: "hold", from: turned, to: turned });
        segs.push({ kind: "squeeze", from: turned, to: t });
      } else {
        // pushed by the -x jaw: the push-grasp at the part's angle; by the +x jaw: the
        // push-grasp of the part turned half a turn, turned back
        const flip = side === "left" ? 0 : Math.PI;
        const rest = near(transfer(turned - flip, push) + flip, turned, TWO_PI);
        const grasped = transfer(turned - flip, push.push_grasp) + flip;
        segs.push({ kind: "push", from: turned, to: rest, side });
        segs.push({ kind: "close", from: rest, to: near(grasped, rest, TWO_PI), side });
        t = grasped;
      }
    }
    const gap = (t - o.final_orientation_rad) / goalPeriod;
    const reached = Math.abs(gap - Math.round(gap)) * goalPeriod < 1e-6;
    // with a payoff the table's success is ending where the payoff is positive (the
    // library's goal then), except for the guaranteed plan, which is of its final orientation
    const ok = nz.payoff && o !== plan.guaranteed ? positivePayoff(nz.payoff, t) : reached;
    return { start: t0, segs, final: t, ok, errors, contacts };
  });
}

const FRAMES = 12;
const COLS = 8;
let animTimer = null;

function drawAnimationFrame(frame) {
  if (!state.last) return false;
  const svg = $("anim");
  svg.replaceChildren();
  const runs = trajectories();
  const o = chosenPlan();
  const nseg = runs[0].segs.length;
  const last = nseg * FRAMES;
  const f = Math.min(frame, last);
  const done = f >= last;
  const seg = Math.min(Math.floor(f / FRAMES), nseg - 1);
  const u = done ? 1 : (f % FRAMES) / FRAMES;
  const kind = runs[0].segs[seg].kind;
  const verts = state.last.plan.part.vertices;
  const cx = verts.reduce((a, p) => a + p[0], 0) / verts.length;
  const cy = verts.reduce((a, p) => a + p[1], 0) / verts.length;
  const centred = verts.map(([x, y]) => [x - cx, y - cy]);
  const r = Math.max(...centred.map(([x, y]) => Math.hypot(x, y)));
  const k = 30 / r;
  const rows = Math.ceil(runs.length / COLS);
  svg.setAttribute("viewBox", `0 0 640 ${rows * 160 + 10}`);
  svg.setAttribute("height", String(rows * 160 + 10));
  runs.forEach((run, i) => {
    const ox = 40 + (i % COLS) * 78, oy = 80 + Math.floor(i / COLS) * 160;
    el("rect", { x: ox - 36, y: oy - 70, width: 72, height: 150, rx: 6, class: done ? (run.ok ? "cell-ok" : "cell-fail") : "cell", "data-ok": run.ok, "data-start": run.start, "data-final": run.final, "data-errors": run.errors.join(","), "data-contacts": run.contacts.join(",") }, svg);
    const sg = done ? { kind: "end", from: run.final, to: run.final } : run.segs[seg];
    const t = sg.from + (sg.to - sg.from) * u;
    const pts = rotate(centred, t);
    const xs = pts.map((p) => p[0]);
    const lo = Math.min(...xs), hi = Math.max(...xs);
    // the jaws' gaps to the part; a push is made by the -x (left) jaw, or under contact noise
    // by either, the other closing after it
    const pushing = sg.kind === "push" || sg.kind === "close";
    const fromRight = pushing && sg.side === "right";
    let left = 8, right = 8;
    if (sg.kind === "squeeze") left = right = 8 * (1 - u);
    else if (sg.kind === "push") [left, right] = fromRight ? [8, 0] : [0, 8];
    else if (sg.kind === "close") [left, right] = fromRight ? [8 * (1 - u), 0] : [0, 8 * (1 - u)];
    else if (sg.kind === "end") left = right = 0;
    el("polygon", { points: pts.map(([x, y]) => `${ox + x * k},${oy - y * k}`).join(" "), fill: "#9fb8d6", stroke: "#2f4b6e" }, svg);
    const jaw = (x, cls) => el("line", { x1: ox + x, y1: oy - 45, x2: ox + x, y2: oy + 45, class: cls }, svg);
    const closing = sg.kind === "squeeze" || sg.kind === "close";
    jaw(lo * k - left, pushing && !fromRight ? "jaw pusher" : closing ? "jaw closing" : "jaw");
    jaw(hi * k + right, pushing && fromRight ? "jaw pusher" : closing ? "jaw closing" : "jaw");
    if (sg.kind === "push") {
      // the push: an arrow on the pushing jaw, pointing the way it moves
      const x = fromRight ? ox + hi * k + right + 4 : ox + lo * k - left - 4;
      const d = fromRight ? 1 : -1; // the arrow's tail is outside the jaw
      el("path", { d: `M${x - d * 10},${oy - 52} L${x},${oy - 52} M${x - d * 4},${oy - 56} L${x},${oy - 52} L${x - d * 4},${oy - 48}`, class: "push-arrow" }, svg);
    }
    const label = el("text", { x: ox, y: oy + 70, "text-anchor": "middle", "font-size": 11 }, svg);
    const fin = round(((deg(run.final) % 360) + 360) % 360, 0);
    label.textContent = done ? `${run.ok ? "✓" : "✗"} ${fin}°` : `${round(((deg(run.start) % 360) + 360) % 360, 0)}°`;
  });
  const ok = runs.filter((x) => x.ok).length;
  const stepOf = runs[0].segs.slice(0, seg + 1).filter((s) => s.kind === "turn").length;
  const kinds = new Set(runs.map((x) => x.segs[seg].kind));
  const words = { turn: "turn", squeeze: "squeeze", push: "push", close: "the other jaw closes", hold: "squeeze" };
  const what = kinds.size > 1 ? "the jaws close (in the cells with an arrow one jaw touches first and pushes)" : words[kind];
  const nz = animationNoise();
  const { turn_noise: turn, contact_noise: contact } = state.last.noise; // the payoff is said below
  const under = turn || contact ? noiseWords({ turn_noise: turn, contact_noise: contact }) : "";
  $("anim-status").textContent = done
    ? `${ok} of ${runs.length} oriented (${round((100 * ok) / runs.length, 1)}%; the plan's success probability ${round(100 * o.success_probability, 1)}%` +
      `${under ? ` under ${under}, drawn in every cell` : ""}` +
      `${nz.payoff && o !== state.last.plan.guaranteed ? "; oriented: at an orientation of positive payoff, as the table counts it" : ""}` +
      `${$("anim-starts").value === "even" ? "; evenly spaced starts are not weighted by the prior" : ""})`
    : `step ${stepOf} of ${o.steps.length}: ${what}`;
  svg.dataset.frame = String(f);
  svg.dataset.done = String(done);
  svg.dataset.kind = done ? "end" : kind;
  svg.dataset.steps = String(o.steps.length);
  svg.dataset.segments = runs[0].segs.map((s) => s.kind).join(",");
  svg.dataset.pushSides = [...new Set(runs.flatMap((x) => x.segs.filter((g) => g.kind === "push").map((g) => g.side)))].sort().join(",");
  svg.dataset.oriented = String(ok);
  svg.dataset.success = String(o.success_probability);
  return !done;
}

function play() {
  clearInterval(animTimer);
  let frame = 0;
  animTimer = setInterval(() => {
    if (!drawAnimationFrame(frame++)) clearInterval(animTimer);
  }, 40);
}

function clearFigureImages() {
  for (const name of ["transfer", "plan"]) $(`fig-${name}`).removeAttribute("src");
}

async function showFigures() {
  await settled();
  if (!validate()) return;
  // the plan figure is of the table's Bayes plan: under the noise, the noise-aware one
  const body = { part: partBody(), ...options(), ...noise() };
  const gen = generation; // a new plan meanwhile makes these figures of other options
  for (const name of ["transfer", "plan"]) {
    const r = await fetch(`${API}/figures/${name}.svg`, {
      method: "POST",
      headers: { "content-type": "application/json" },
      body: JSON.stringify(body),
    });
    if (gen !== generation) return;
    if (!r.ok) {
      setStatus((await r.json()).detail, true);
      return;
    }
    const img = $(`fig-${name}`);
    if (img.src) URL.revokeObjectURL(img.src);
    img.src = URL.createObjectURL(await r.blob());
  }
}

// ---- the sensing policy (POST /policy: the document of plan --sense --json) ---------------

const FOLD_BELOW = 0.01; // branches below this probability at their node are told as one line

function fixed(x, d) {
  // Python's format: an exact tie (0.125 to 2 decimals) rounds to even, where toFixed rounds
  // it up. toFixed with many digits is the double's exact expansion, and a tie's ends in "5".
  const a = Math.abs(x);
  const s = a.toFixed(Math.min(100, d + 40));
  const cut = s.indexOf(".") + 1 + d;
  if (!/^50*$/.test(s.slice(cut))) return x.toFixed(d);
  const even = Number(s[cut - 1]) % 2 === 0;
  return (x < 0 ? "-" : "") + (even ? s.slice(0, cut) : a.toFixed(d));
}

function prob(p) {
  // as policy_text: two decimals, or two significant digits below 0.01 ("4.6e-13")
  if (p >= 0.01 || p === 0) return fixed(p, 2);
  const [m, e] = p.toExponential(1).split("e");
  const n = Math.abs(Number(e));
  return `${m}e${Number(e) < 0 ? "-" : "+"}${String(n).padStart(2, "0")}`;
}

function policyLines(node, depth, first, unit, lines) {
  // the tree as policy_text prints it (bayesgrasp/planning/policy.py), small branches folded
  const pad = "  ".repeat(depth);
  const deg = (r) => `${fixed((r * 180) / Math.PI, 2)} deg`;
  const act = node.action;
  lines.push(first ? `${pad}${act.type} with the gripper at ${deg(act.alpha_rad)}` : `${pad}turn ${deg(act.alpha_rad)}, ${act.type}`);
  let folded = 0, foldedP = 0;
  for (const b of node.branches) {
    if (b.probability < FOLD_BELOW) {
      folded += 1;
      foldedP += b.probability;
      continue;
    }
    const [lo, hi] = b.reading;
    const reads =
      lo === null && hi === null ? "any width"
      : lo === null ? `the width reads below ${fixed(hi, 2)}${unit}`
      : hi === null ? `the width reads ${fixed(lo, 2)}${unit} or more`
      : `the width reads in [${fixed(lo, 2)}, ${fixed(hi, 2)})${unit}`;
    const cond = `${pad}  if ${reads} (p = ${prob(b.probability)})`;
    const n = b.next;
    if (n.action) {
      lines.push(cond + ":");
      policyLines(n, depth + 2, false, unit, lines);
    } else if (n.reject) lines.push(`${cond}: reject (back to the feeder)`);
    else {
      const what = state.policyParts > 1 ? `part '${n.declare.part}' at ` : "";
      lines.push(`${cond}: declare ${what}${deg(n.declare.orientation_rad)} (success ${fixed(n.success_probability, 2)})`);
    }
  }
  if (folded) {
    const s = folded > 1 ? "s" : "";
    lines.push(`${pad}  (${folded} more reading interval${s}, p = ${prob(foldedP)} in all, left out here; the JSON document lists every branch)`);
  }
  return lines;
}

let policyToken = 0; // the policy the panel waits for; a new plan of other options ends the wait

function clearPolicy() {
  policyToken++;
  $("policy-tree").textContent = "";
  $("policy-nodes").replaceChildren();
  $("policy-summary").textContent = "";
  $("policy-summary").classList.remove("error");
  delete document.body.dataset.policy;
}

async function showPolicy() {
  await settled();
  if (!validate()) return;
  clearPolicy();
  const token = policyToken;
  const o = options();
  const n = noise();
  const noisy = Boolean(n.turn_noise || n.contact_noise || n.payoff);
  const body = { part: partBody(), ...o, ...n, ...policyStroke(), sense: $("sense").value.trim() || "width", max_actions: Number($("sense-depth").value) || 3 };
  $("policy-summary").textContent = "planning the policy...";
  try {
    const part = partBody();
    const [doc, squeeze, push] = await Promise.all([
      post("/policy", body),
      post("/squeeze", { part, prior: o.prior }),
      o.actions.includes("push-grasp") ? post("/push", { part, prior: o.prior }) : Promise.resolve(null),
    ]);
    if (token !== policyToken) return; // the options changed meanwhile: it is of others
    state.policyParts = doc.parts.length;
    const hullVerts = squeeze.part.vertices;
    const drawn = state.vertices.length >= 3 ? state.vertices : state.outline || hullVerts;
    const [mu] = o.prior.startsWith("vonmises:") ? o.prior.slice(9).split(",").map(Number) : [0];
    // the part drawings (one part only: several parts' trees name the part at each leaf)
    // under noise the page cannot follow the belief (the drawings of actions and rejects
    // would be the noise-free model's guess): only the root and the declarations are drawn
    state.policyDraw = doc.parts.length === 1 ? { hull: hullVerts, outline: drawn, squeeze, push, mode: (mu * Math.PI) / 180, noisy } : null;
    // the units of the last plan, when it was of this part (the policy document has none)
    const last = state.last && state.last.plan ? state.last.plan.part : null;
    const units = last && last.name === doc.parts[0] ? last.units : null;
    $("policy-tree").textContent = policyLines(doc.root, 0, true, units ? ` ${units}` : "", []).join("\n");
    $("policy-nodes").replaceChildren(policyNode(doc.root, true, units ? ` ${units}` : "", []));
    const blind = doc.sensorless_cost === null ? "" : ` (sensorless Bayes plan ${doc.sensorless_cost.toFixed(4)})`;
    const under = noisy ? `; under ${noiseWords(n)}` : "";
    $("policy-summary").textContent =
      `expected cost ${doc.expected_cost.toFixed(4)}${blind}, success ${doc.success_probability.toFixed(4)} a cycle, ` +
      `${doc.expected_actions.toFixed(3)} actions a cycle${under}`;
    $("policy-summary").classList.remove("error");
    document.body.dataset.policy = "done";
  } catch (err) {
    if (token !== policyToken) return;
    $("policy-summary").textContent = String(err.message || err);
    $("policy-summary").classList.add("error");
    document.body.dataset.policy = "error";
  }
}

function noiseWords(n) {
  // the noise and payoff of a request, for people
  const words = [];
  if (n.turn_noise) words.push(`turn error ${n.turn_noise} deg`);
  if (n.contact_noise) words.push(`contact noise ${n.contact_noise}`);
  if (n.payoff) words.push("the payoff");
  return words.join(", ") || "no noise";
}

// ---- robot files (POST /export: the bytes of plan --export FILE.csv|json) ----------------

function policyStroke() {
  // a policy is checked against the stroke; "within the stroke" plans linear plans only
  const g = stroke();
  delete g.within_stroke;
  return g;
}

async function downloadRobotFile(policy) {
  await settled();
  if (!validate()) return;
  const format = $("export-format").value;
  const body = { part: partBody(), ...options(), format };
  if (policy) Object.assign(body, noise(), policyStroke(), { sense: $("sense").value.trim() || "width", max_actions: Number($("sense-depth").value) || 3 });
  else Object.assign(body, noise(), stroke(), $("guaranteed").checked ? { guaranteed: true } : {});
  const where = policy ? $("policy-summary") : $("status");
  where.textContent = "writing the robot file...";
  where.classList.remove("error");
  try {
    const r = await fetch(`${API}/export`, { method: "POST", headers: { "content-type": "application/json" }, body: JSON.stringify(body) });
    if (!r.ok) {
      let msg = `HTTP ${r.status}`;
      try {
        msg = (await r.json()).detail || msg;
      } catch (err) {
        /* not JSON */
      }
      throw new Error(msg);
    }
    const m = /filename="?([^";]+)"?/.exec(r.headers.get("content-disposition") || "");
    const a = document.createElement("a");
    a.href = URL.createObjectURL(await r.blob());
    a.download = m ? m[1] : `robot.${format}`;
    document.body.appendChild(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(a.href), 10_000);
    where.textContent = `downloaded ${a.download}`;
  } catch (err) {
    where.textContent = String(err.message || err);
    where.classList.add("error");
  }
}

// ---- the plan run many times: a simulation job on the server (POST /simulate/jobs) --------

const SIM_TRIALS = { kinematic: 100000, mujoco: 200 }; // the command line's defaults (200 MuJoCo)
const SIM_POLL_MS = 500;
let serverLimits = null; // GET /limits: the trials a job may ask, the engines the server runs
let simToken = 0; // the simulation the panel follows; clearing the panel ends its polling

async function loadLimits() {
  try {
    serverLimits = await (await fetch(`${API}/limits`)).json();
  } catch (err) {
    serverLimits = null; // the server still checks every request
  }
  const mujoco = $("sim-engine").querySelector('option[value="mujoco"]');
  if (serverLimits && !(serverLimits.engines || []).includes("mujoco")) {
    mujoco.disabled = true;
    mujoco.textContent = "MuJoCo (not installed on this server)";
    if ($("sim-engine").value === "mujoco") $("sim-engine").value = "kinematic";
  }
  simEngineChanged();
}

function simEngineChanged() {
  // the trials follow the engine's default until the user types a number of their own
  const engine = $("sim-engine").value;
  if (!$("sim-trials").dataset.edited) $("sim-trials").value = String(SIM_TRIALS[engine]);
  $("sim-offset").disabled = engine !== "mujoco";
  $("sim-lag").disabled = engine !== "mujoco";
}

function validateSimulation() {
  // each message next to its input; the server's limits from /limits
  const engine = $("sim-engine").value;
  let ok = true;
  const most = serverLimits ? (engine === "mujoco" ? serverLimits.max_mujoco_trials : serverLimits.max_trials) : Infinity;
  const whole = (id, what, lo, hi, hiText) => {
    const raw = $(id).value.trim();
    const x = Number(raw);
    let msg = "";
    if (raw === "") msg = `${what}: enter a whole number`;
    else if (!Number.isInteger(x)) msg = `${what}: a whole number`;
    else if (x < lo) msg = `${what}: must be at least ${lo}`;
    else if (x > hi) msg = `${what}: ${hiText}`;
    fieldError(id, msg);
    if (msg) ok = false;
  };
  const engineName = engine === "mujoco" ? "MuJoCo" : "kinematic";
  whole("sim-trials", "trials", 1, most, `the server runs at most ${Number(most).toLocaleString("en")} ${engineName} trials a job`);
  whole("sim-seed", "seed", 0, Number.MAX_SAFE_INTEGER, "too large");
  for (const [id, what] of [["sim-offset", "offset"], ["sim-lag", "jaw lag"]]) {
    const raw = $(id).value.trim();
    const bad = raw === "" || !Number.isFinite(Number(raw)) ? `${what}: enter a number` : Number(raw) < 0 ? `${what}: must be at least 0` : "";
    const msg = engine === "mujoco" ? bad : "";
    fieldError(id, msg);
    if (msg) ok = false;
  }
  const contact = Number($("contact-noise").value || 0) > 0;
  const refused = engine === "mujoco" && contact;
  fieldError("sim-engine", refused ? "MuJoCo: the contact noise applies to the kinematic engine only (in MuJoCo the jaws' contacts are the physics' own); clear it or choose kinematic" : "");
  if (refused) ok = false;
  return ok;
}

function simulationBody() {
  // the plan the animation's selector names, sent as it is (simulate --plan FILE.json), with
  // the problem's options and the noise it was planned under
  const engine = $("sim-engine").value;
  const n = noise();
  if (!n.contact_noise) delete n.contact_noise; // zero is no contact noise
  const body = {
    part: partBody(),
    ...options(),
    ...n,
    plan: chosenPlan(),
    engine,
    trials: Number($("sim-trials").value),
    seed: Number($("sim-seed").value),
  };
  if (engine === "mujoco" && Number($("sim-offset").value) > 0) body.offset_mm = Number($("sim-offset").value);
  if (engine === "mujoco" && Number($("sim-lag").value) > 0) body.jaw_lag_s = Number($("sim-lag").value);
  return body;
}

function clearSimulation() {
  simToken++;
  $("sim-progress").hidden = true;
  $("sim-progress").value = 0;
  $("sim-status").textContent = "";
  $("sim-status").classList.remove("error");
  $("sim-result").replaceChildren();
  $("simulate").disabled = false;
  delete document.body.dataset.sim;
}

function simFailed(token, message) {
  if (token !== simToken) return;
  $("sim-progress").hidden = true;
  $("sim-status").textContent = message;
  $("sim-status").classList.add("error");
  $("simulate").disabled = false;
  document.body.dataset.sim = "error";
}

async function simulate() {
  await settled();
  if (!state.last) {
    clearSimulation();
    simFailed(simToken, "plan a part first: the simulation runs the plan chosen above");
    return;
  }
  if (!validateSimulation() || !validate()) return;
  const body = simulationBody();
  const what = $("anim-plan").selectedOptions[0]?.textContent || "the Bayes plan";
  clearSimulation();
  const token = simToken;
  $("simulate").disabled = true;
  $("sim-progress").hidden = false;
  $("sim-status").textContent = "submitting the job...";
  document.body.dataset.sim = "running";
  let job;
  try {
    job = await post("/simulate/jobs", body);
  } catch (err) {
    simFailed(token, String(err.message || err));
    return;
  }
  for (;;) {
    if (token !== simToken) return; // a new plan, part or run replaced this one
    let doc;
    try {
      const r = await fetch(job.url);
      doc = await r.json();
      if (!r.ok) throw new Error(doc.detail || `HTTP ${r.status}`);
    } catch (err) {
      simFailed(token, `the job cannot be read: ${err.message || err}`);
      return;
    }
    if (token !== simToken) return;
    const { done, total, fraction } = doc.progress;
    $("sim-progress").value = fraction;
    $("sim-status").textContent = `${doc.status === "queued" ? "queued" : "running"}: ${done.toLocaleString("en")} of ${total.toLocaleString("en")} trials`;
    if (doc.status === "failed") {
      simFailed(token, doc.error ? doc.error.detail : "the job failed");
      return;
    }
    if (doc.status === "done") {
      $("sim-progress").hidden = true;
      $("sim-status").textContent = `done: ${total.toLocaleString("en")} trials`;
      $("simulate").disabled = false;
      drawSimulation(doc.result, what);
      document.body.dataset.sim = "done";
      return;
    }
    await new Promise((wake) => setTimeout(wake, SIM_POLL_MS));
  }
}

function verdictText(doc) {
  // the verdict line of `bayesgrasp simulate` (each prediction within its z interval)
  const claims = [["success", doc.predicted_success, doc.success_interval]];
  if (doc.payoff) claims.unshift(["E[payoff]", doc.payoff.predicted, doc.payoff.interval]);
  const said = claims
    .map(([name, v, [lo, hi]]) => `predicted ${name} ${v.toFixed(4)} ${lo - 1e-9 <= v && v <= hi + 1e-9 ? "within" : "outside"} [${lo.toFixed(4)}, ${hi.toFixed(4)}]`)
    .join("; ");
  return `verdict: ${doc.agrees ? "agrees" : "DISAGREES"}: ${said} (z = ${doc.z})`;
}

function drawSimulation(doc, what) {
  // the document of `bayesgrasp simulate --json`: the summary, then each final orientation
  const out = $("sim-result");
  out.replaceChildren();
  out.dataset.engine = doc.engine;
  out.dataset.trials = String(doc.trials);
  out.dataset.predicted = String(doc.predicted_success);
  out.dataset.observed = String(doc.observed_success);
  out.dataset.agrees = String(doc.agrees);
  const p4 = (x) => (x == null ? "-" : x.toFixed(4));
  const interval = (iv) => `[${p4(iv[0])}, ${p4(iv[1])}]`;
  const successes = Math.round(doc.observed_success * doc.trials);
  const rows = [
    ["plan", what, "plan"],
    ["engine", `${doc.engine === "mujoco" ? "MuJoCo" : "kinematic"}, ${doc.trials.toLocaleString("en")} trials in ${round(doc.seconds, 2)} s`, "engine"],
    ["predicted success", p4(doc.predicted_success), "predicted"],
    ["observed success", `${p4(doc.observed_success)} (${successes.toLocaleString("en")} of ${doc.trials.toLocaleString("en")})`, "observed"],
    ["observed, 95% interval", interval(doc.ci95), "ci95"],
  ];
  if (doc.prediction_interval95)
    rows.push([`95% of runs of ${doc.trials} trials, if the prediction is right`, interval(doc.prediction_interval95), "prediction_interval95"]);
  if (doc.success_p_value != null) rows.push(["p-value of the success (exact binomial)", doc.success_p_value.toPrecision(3), "success_p_value"]);
  rows.push(["goodness of fit over the final orientations (chi-square)", doc.p_value == null ? `n/a (${doc.p_value_unavailable || "-"})` : `p = ${doc.p_value.toPrecision(3)}`, "p_value"]);
  rows.push(["jams", `${doc.jams} (${doc.final_jams} in the last action)`, "jams"]);
  if (doc.payoff) {
    rows.push(["payoff: predicted E[payoff]", p4(doc.payoff.predicted), "payoff_predicted"]);
    rows.push(["payoff: observed mean, 95% interval", `${p4(doc.payoff.observed)} ${interval(doc.payoff.ci95)}`, "payoff_observed"]);
  }
  const table = document.createElement("table");
  table.className = "sim-summary";
  for (const [name, text, key] of rows) {
    const tr = document.createElement("tr");
    const th = document.createElement("th");
    th.textContent = name;
    const td = document.createElement("td");
    td.textContent = text;
    td.dataset.key = key;
    tr.append(th, td);
    table.appendChild(tr);
  }
  out.appendChild(table);
  for (const flag of doc.assumption_flags || []) {
    const p = document.createElement("p");
    p.className = "flags";
    p.textContent = `model assumptions break: ${flag}`;
    out.appendChild(p);
  }
  const verdict = document.createElement("p");
  verdict.className = `verdict ${doc.agrees ? "agrees" : "disagrees"}`;
  verdict.textContent = verdictText(doc);
  out.appendChild(verdict);
  const per = document.createElement("table");
  per.className = "sim-orientations";
  per.innerHTML = "<thead><tr><th>final (deg)</th><th>predicted</th><th>observed</th><th>count</th><th></th></tr></thead>";
  const tbody = document.createElement("tbody");
  for (const row of doc.per_orientation) {
    const tr = document.createElement("tr");
    const cells = [
      round(((deg(row.orientation_rad) % 360) + 360) % 360, 2),
      row.predicted.toFixed(4),
      row.observed.toFixed(4),
      row.count.toLocaleString("en"),
      row.goal ? "goal" : "",
    ];
    for (const text of cells) {
      const td = document.createElement("td");
      td.textContent = text;
      tr.appendChild(td);
    }
    tr.dataset.count = String(row.count);
    tr.dataset.predicted = String(row.predicted);
    tbody.appendChild(tr);
  }
  per.appendChild(tbody);
  out.appendChild(per);
}

// ---- catalogue, file, gallery --------------------------------------------------------------

async function loadCatalogue() {
  const r = await fetch(API + "/catalogue");
  const doc = await r.json();
  for (const p of doc.parts) {
    const o = document.createElement("option");
    o.value = p.name;
    o.textContent = p.name;
    $("catalogue").appendChild(o);
  }
  $("catalogue").value = state.catalogue;
  state.catalogueParts = doc.parts;
  const given = doc.parts.find((p) => p.name === state.catalogue);
  if (given) {
    state.outline = given.outline;
    view.auto = true; // framed when drawn
    drawCanvas();
  }
  $("catalogue").addEventListener("change", () => {
    const name = $("catalogue").value;
    if (!name) return;
    const entry = doc.parts.find((p) => p.name === name);
    undoStack.push(state.vertices.map((v) => v.slice()));
    state.catalogue = name;
    state.file = null;
    showFileName("");
    state.vertices = [];
    state.outline = entry.outline;
    view.auto = true; // framed when drawn
    drawCanvas();
    schedule();
  });
}

function setupFile() {
  $("file").addEventListener("change", async () => {
    const f = $("file").files[0];
    if (!f) return;
    const ext = f.name.split(".").pop().toLowerCase();
    const bytes = new Uint8Array(await f.arrayBuffer());
    let bin = "";
    for (let i = 0; i < bytes.length; i += 0x8000) bin += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
    state.catalogue = "";
    state.vertices = [];
    const name = f.name.replace(/\.[^.]*$/, "").replace(/[^A-Za-z0-9_. -]/g, "_").slice(0, 64) || "part";
    state.file = { format: ext, data_base64: btoa(bin), name, packed: await pack(bin) };
    state.outline = null;
    view.auto = true; // framed when drawn
    $("catalogue").value = "";
    drawCanvas();
    showFileName(f.name);
    schedule();
  });
}

let galleryPage = 1;
const PER_PAGE = 8;

function thumbnail(outline) {
  const svg = el("svg", { viewBox: "0 0 64 64", width: 64, height: 64, class: "thumb" });
  if (outline.length >= 3) {
    const f = fit(outline, 64, 4);
    el("polygon", { points: outline.map((p) => f(p).join(",")).join(" "), class: "poly" }, svg);
  }
  return svg;
}

async function loadGallery(page) {
  if (page) galleryPage = page;
  try {
    const r = await fetch(`${API}/saved?page=${galleryPage}&per_page=${PER_PAGE}`);
    const doc = await r.json();
    const ul = $("gallery");
    ul.replaceChildren();
    for (const row of doc.rows) {
      const li = document.createElement("li");
      const a = document.createElement("a");
      a.href = "#" + row.view;
      a.appendChild(thumbnail(row.outline));
      const s = row.summary || {};
      const n = s.actions;
      const text = document.createElement("span");
      text.textContent = `${row.name}: ${n === undefined ? "" : `${n} ${n === 1 ? "action" : "actions"}, `}` +
        `p = ${s.success_probability == null ? "-" : s.success_probability.toFixed(3)}, ` +
        `cost ${s.expected_cost == null ? "-" : s.expected_cost.toFixed(3)}`;
      a.appendChild(text);
      li.appendChild(a);
      ul.appendChild(li);
    }
    const pages = Math.max(1, Math.ceil(doc.total / PER_PAGE));
    $("gallery-page").textContent = doc.total ? `page ${galleryPage} of ${pages} (${doc.total} saved)` : "nothing saved yet";
    $("gallery-prev").disabled = galleryPage <= 1;
    $("gallery-next").disabled = galleryPage >= pages;
  } catch (err) {
    /* the gallery is optional */
  }
}

async function saveView() {
  if (!state.last) {
    setStatus("plan a part before saving it", true);
    return;
  }
  const { plan } = state.last;
  const o = plan.options[plan.bayes];
  const outline = state.vertices.length >= 3 ? state.vertices : state.outline || plan.part.vertices;
  const body = {
    name: plan.part.name,
    view: window.location.hash.slice(1),
    outline,
    summary: { actions: o.steps.length, success_probability: o.success_probability, expected_cost: o.expected_cost },
  };
  try {
    await post("/saved", body);
    setStatus(`saved ${plan.part.name} to the gallery`);
    loadGallery(1);
  } catch (err) {
    setStatus(String(err.message || err), true);
  }
}

// ---- start -------------------------------------------------------------------------------

function start() {
  setupCanvas();
  setupFile();
  const ready = readHash();
  drawCanvas();
  $("plan").addEventListener("click", run);
  $("play").addEventListener("click", play);
  for (const id of ["anim-plan", "anim-starts", "anim-n", "anim-seed"])
    $(id).addEventListener("change", () => {
      clearInterval(animTimer);
      drawAnimationFrame(0);
    });
  $("anim-plan").addEventListener("change", clearSimulation); // the simulation was of another plan
  for (const [id] of VIEW_SETTINGS) $(id).addEventListener("change", writeHash);
  $("simulate").addEventListener("click", simulate);
  $("sim-engine").addEventListener("change", () => {
    simEngineChanged();
    validateSimulation();
  });
  $("sim-trials").addEventListener("input", () => ($("sim-trials").dataset.edited = "1"));
  for (const id of ["sim-trials", "sim-offset", "sim-lag", "sim-seed"]) $(id).addEventListener("change", validateSimulation);
  $("figures").addEventListener("click", showFigures);
  $("policy").addEventListener("click", showPolicy);
  $("save").addEventListener("click", saveView);
  $("export").addEventListener("click", () => downloadRobotFile(false));
  $("export-policy").addEventListener("click", () => downloadRobotFile(true));
  $("gallery-prev").addEventListener("click", () => loadGallery(galleryPage - 1));
  $("gallery-next").addEventListener("click", () => loadGallery(galleryPage + 1));
  $("options").addEventListener("change", (evt) => {
    if (evt.target.id !== "export-format") schedule(); // the file's format plans nothing
  });
  window.addEventListener("hashchange", async () => { await readHash(); drawCanvas(); schedule(); });
  Promise.all([ready, loadCatalogue()]).then(() => {
    if (state.catalogue || state.file || state.vertices.length >= 3) run();
  });
  loadGallery();
  loadLimits();
}

start();

// ---- the uploaded file in the URL: deflate-raw, base64url ------------------------------------

function toBase64Url(bin) {
  return btoa(bin).replace(/\+/g, "-").replace(/\//g, "_").replace(/=+$/, "");
}

function fromBase64Url(s) {
  const b = s.replace(/-/g, "+").replace(/_/g, "/");
  return atob(b + "===".slice((b.length + 3) % 4));
}

async function pack(bin) {
  // a binary string (the file's bytes) compressed for the address bar
  const bytes = Uint8Array.from(bin, (c) => c.charCodeAt(0));
  const stream = new Blob([bytes]).stream().pipeThrough(new CompressionStream("deflate-raw"));
  const out = new Uint8Array(await new Response(stream).arrayBuffer());
  let s = "";
  for (let i = 0; i < out.length; i += 0x8000) s += String.fromCharCode.apply(null, out.subarray(i, i + 0x8000));
  return toBase64Url(s);
}

async function unpack(packed) {
  const bytes = Uint8Array.from(fromBase64Url(packed), (c) => c.charCodeAt(0));
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate-raw"));
  const out = new Uint8Array(await new Response(stream).arrayBuffer());
  let s = "";
  for (let i = 0; i < out.length; i += 0x8000) s += String.fromCharCode.apply(null, out.subarray(i, i + 0x8000));
  return s;
}

function showFileName(text) {
  $("file-name").textContent = text ? `current file: ${text}` : "";
  if (!text) $("file").value = "";
}

// ---- validation: each message next to the input that caused it -------------------------------

function fieldError(id, message) {
  const input = $(id);
  let span = document.getElementById(`${id}-error`);
  if (!message) {
    input.removeAttribute("aria-invalid");
    if (span) span.remove();
    return;
  }
  input.setAttribute("aria-invalid", "true");
  if (!span) {
    span = document.createElement("span");
    span.id = `${id}-error`;
    span.className = "field-error";
    span.setAttribute("role", "alert");
    const anchor = input.closest("label, fieldset") || input;
    anchor.insertAdjacentElement("afterend", span);
  }
  span.textContent = message;
}

function validate() {
  let ok = true;
  const number = (id, what, lo, hi, required) => {
    const raw = $(id).value.trim();
    let msg = "";
    if (raw === "") msg = required ? `${what}: enter a number` : "";
    else if (!Number.isFinite(Number(raw))) msg = `${what}: not a number`;
    else if (Number(raw) < lo) msg = `${what}: must be at least ${lo}`;
    else if (hi !== undefined && Number(raw) > hi) msg = `${what}: must be at most ${hi}`;
    fieldError(id, msg);
    if (msg) ok = false;
  };
  number("cost-squeeze", "squeeze cost", 0, undefined, $("act-squeeze").checked);
  number("cost-push-grasp", "push-grasp cost", 0, undefined, $("act-push-grasp").checked);
  number("cost-verify", "verify cost", 0, undefined, true);
  number("cost-retry", "retry cost", 0, undefined, true);
  number("accuracy", "accuracy", 0, 180, true);
  number("max-actions", "max actions", 1, 1000, false);
  number("contact-noise", "contact noise", 0, 1, false);
  number("max-opening", "max opening", 0, undefined, false);
  number("min-opening", "min opening", 0, undefined, false);
  const [hiO, loO] = [$("max-opening").value.trim(), $("min-opening").value.trim()];
  if (hiO !== "" && loO !== "" && Number(loO) > Number(hiO) && !$("min-opening").getAttribute("aria-invalid")) {
    fieldError("min-opening", "min opening: must be at most the max opening");
    ok = false;
  }
  const needs = $("within-stroke").checked && hiO === "" && loO === "";
  fieldError("within-stroke", needs ? "plan within the stroke: give the max and/or min opening" : "");
  if (needs) ok = false;
  if ($("turn-kind").value) number("turn-deg", "turn error", 0, undefined, true);
  else fieldError("turn-deg", "");
  if ($("prior-kind").value === "vonmises") {
    number("prior-mean", "mean", -360, 360, true);
    number("prior-kappa", "kappa", 0, undefined, true);
  } else {
    fieldError("prior-mean", "");
    fieldError("prior-kappa", "");
  }
  const pay = $("payoff").value.trim();
  let payMsg = "";
  if (pay) {
    try {
      const v = JSON.parse(pay);
      if (typeof v !== "object" || v === null || Array.isArray(v)) payMsg = 'payoff: an object {"DEG": V, ...}';
      else if (Object.values(v).some((x) => typeof x !== "number" || x < 0 || x > 1)) payMsg = "payoff: every value must be a number in [0, 1]";
    } catch (err) {
      payMsg = "payoff: not valid JSON";
    }
  }
  fieldError("payoff", payMsg);
  if (payMsg) ok = false;
  const acts = $("act-squeeze").checked || $("act-push-grasp").checked;
  fieldError("actions", acts ? "" : "choose at least one action");
  if (!acts) ok = false;
  if (!ok) setStatus("fix the marked inputs", true);
  return ok;
}

function clearResults() {
  state.last = null;
  clearSimulation();
  $("output").classList.remove("stale");
  $("plans").querySelector("tbody").replaceChildren();
  $("hull").replaceChildren();
  $("diameter").replaceChildren();
  $("anim").replaceChildren();
  $("anim-status").textContent = "";
  $("anim-plan").replaceChildren();
  $("functions").replaceChildren();
  $("belief").replaceChildren();
  state.functions = null;
  clearFigureImages();
  clearPolicy();
}

// ---- interactive figures drawn from the JSON of /views/functions ---------------------------

const round = (x, d) => String(Number(x.toFixed(d)));

function chart(svg, xs, ys, opts) {
  // a line chart with hover values; the wheel zooms the angle axis, a double click resets it
  const W = 640, H = 260, L = 56, R = 12, T = 12, B = 34;
  let lo = opts.lo === undefined ? xs[0] : opts.lo, hi = opts.hi === undefined ? xs[xs.length - 1] : opts.hi;
  const draw = () => {
    svg.replaceChildren();
    svg.setAttribute("viewBox", `0 0 ${W} ${H}`);
    const keep = xs.map((x, i) => i).filter((i) => xs[i] >= lo && xs[i] <= hi);
    const vals = keep.map((i) => ys[i]);
    let y0 = Math.min(...vals), y1 = Math.max(...vals);
    if (opts.angle) { y0 = 0; y1 = 360; }
    if (y1 - y0 < 1e-9) { y0 -= 1; y1 += 1; }
    const X = (x) => L + ((W - L - R) * (x - lo)) / (hi - lo);
    const Y = (y) => H - B - ((H - T - B) * (y - y0)) / (y1 - y0);
    el("rect", { x: L, y: T, width: W - L - R, height: H - T - B, fill: "#fff", stroke: "#ccc" }, svg);
    for (let k = 0; k <= 4; k++) {
      const xv = lo + ((hi - lo) * k) / 4, yv = y0 + ((y1 - y0) * k) / 4;
      el("text", { x: X(xv), y: H - 14, "text-anchor": "middle", "font-size": 13 }, svg).textContent = round(xv, 1);
      el("text", { x: L - 4, y: Y(yv) + 4, "text-anchor": "end", "font-size": 13 }, svg).textContent = round(yv, opts.angle ? 0 : 2);
    }
    el("text", { x: W / 2, y: H - 1, "text-anchor": "middle", "font-size": 13 }, svg).textContent = `${opts.x} (deg)`;
    const d = keep.map((i, k) => `${k ? "L" : "M"}${X(xs[i]).toFixed(1)},${Y(ys[i]).toFixed(1)}`).join("");
    el("path", { d, fill: "none", stroke: "#2f4b6e", "stroke-width": 2, class: "curve" }, svg);
    const dot = el("circle", { r: 4, fill: "#d62728", visibility: "hidden" }, svg);
    const tip = el("text", { x: L + 6, y: T + 16, "font-size": 14, class: "tip" }, svg);
    svg.onmousemove = (evt) => {
      const r = svg.getBoundingClientRect();
      const px = ((evt.clientX - r.left) * W) / r.width;
      const x = lo + ((px - L) * (hi - lo)) / (W - L - R);
      let best = keep[0];
      for (const i of keep) if (Math.abs(xs[i] - x) < Math.abs(xs[best] - x)) best = i;
      dot.setAttribute("cx", X(xs[best]));
      dot.setAttribute("cy", Y(ys[best]));
      dot.setAttribute("visibility", "visible");
      tip.textContent = `${opts.x} ${round(xs[best], 2)}°: ${opts.y} ${round(ys[best], opts.angle ? 2 : 3)}${opts.angle ? "°" : ""}`;
    };
  };
  svg.onwheel = (evt) => {
    evt.preventDefault();
    const mid = (lo + hi) / 2, half = ((hi - lo) / 2) * (evt.deltaY > 0 ? 1.25 : 0.8);
    lo = Math.max(xs[0], mid - half);
    hi = Math.min(xs[xs.length - 1], mid + half);
    draw();
  };
  svg.ondblclick = () => { lo = xs[0]; hi = xs[xs.length - 1]; draw(); };
  draw();
}

const FUNCTION_NAMES = {
  diameter: ["diameter d(θ)", false],
  squeeze: ["squeeze s(θ)", true],
  radius: ["radius r(θ)", false],
  push: ["push p(θ)", true],
  push_grasp: ["push-grasp g(θ)", true],
};

async function loadFunctions(part, o, gen) {
  try {
    // the noise and payoff too: the beliefs of the table's noise-aware Bayes plan
    const doc = await postWhenFree("/views/functions", { part, ...o, ...noise() }, gen);
    if (gen !== generation) return;
    state.functions = doc;
    const box = $("functions");
    box.replaceChildren();
    for (const [key, [label, angle]] of Object.entries(FUNCTION_NAMES)) {
      if (!doc.functions[key]) continue;
      const fig = document.createElement("figure");
      const cap = document.createElement("figcaption");
      cap.textContent = label;
      const svg = el("svg", { class: "chart", "data-function": key, role: "img", "aria-label": label });
      fig.append(cap, svg);
      box.appendChild(fig);
      chart(svg, doc.theta_deg, doc.functions[key], { x: "θ", y: label.split(" ")[0], angle });
    }
    drawBelief(doc);
  } catch (err) {
    if (gen === generation) $("functions").textContent = String(err.message || err);
  }
}

function sameAsTable(shown) {
  // whether the figures' plan is the table's Bayes plan (same actions at the same angles)
  if (!state.last) return true;
  const { plan } = state.last;
  const steps = plan.options[plan.bayes].steps;
  return (
    steps.length === shown.steps.length &&
    steps.every((s, i) => s.type === shown.steps[i].type && Math.abs(deg(s.alpha_rad) - shown.steps[i].alpha_deg) < 1e-3)
  );
}

function drawBelief(doc) {
  // one bar chart a step: the probability of each orientation after the step
  const box = $("belief");
  box.replaceChildren();
  doc.belief.forEach((atoms, k) => {
    const st = doc.plan.steps[k];
    const W = 640, H = 120, L = 40, B = 26, T = 8;
    const svg = el("svg", { viewBox: `0 0 ${W} ${H}`, class: "chart belief", "data-step": k + 1 });
    const cap = document.createElement("figcaption");
    const exact = sameAsTable(doc.plan) ? "" : ", the Bayes plan without the stroke limits (the table's Bayes plan differs)";
    cap.textContent = `after step ${k + 1} (${st.type} at ${round(st.alpha_deg, 2)}°${exact})`;
    const fig = document.createElement("figure");
    fig.append(cap, svg);
    box.appendChild(fig);
    const X = (a) => L + ((W - L - 10) * (((a % 360) + 360) % 360)) / 360;
    el("line", { x1: L, y1: H - B, x2: W - 10, y2: H - B, stroke: "#555" }, svg);
    for (let a = 0; a <= 360; a += 90)
      el("text", { x: X(a === 360 ? 359.999 : a), y: H - 8, "text-anchor": "middle", "font-size": 13 }, svg).textContent = `${a}`;
    for (const { orientation_deg: a, probability: p } of atoms) {
      const h = (H - B - T) * p;
      const goal = Math.abs(((a - doc.plan.final_deg + 540) % 360) - 180) < 1e-6 && k === doc.belief.length - 1;
      const bar = el("rect", { x: X(a) - 4, y: H - B - h, width: 8, height: Math.max(h, 0.5), fill: goal ? "#2a9a2a" : "#2f4b6e", "data-p": p }, svg);
      el("title", {}, bar).textContent = `${round(a, 2)}°: p = ${round(p, 4)}`;
    }
  });
}

// ---- the policy as a collapsible tree ---------------------------------------------------------

function partAt(theta, title) {
  // the part's outline, small, at orientation theta (radians) as the jaws see it
  const ctx = state.policyDraw;
  const svg = el("svg", { viewBox: "0 0 40 40", width: 40, height: 40, class: "policy-part", "data-orientation": deg(theta) });
  const pts = rotate(ctx.outline, theta);
  const f = fit(rotate(ctx.hull, theta), 40, 3);
  el("polygon", { points: pts.map((p) => f(p).join(",")).join(" "), class: "poly" }, svg);
  el("title", {}, svg).textContent = title;
  return svg;
}

function afterAction(atoms, act, first) {
  // the belief after an action: the prior's mass per stable orientation for the first one,
  // else each atom turned by the action's angle and sent through its transfer function
  const ctx = state.policyDraw;
  const doc = act.type === "squeeze" ? ctx.squeeze : ctx.push && ctx.push.push_grasp;
  if (!doc) return atoms;
  const out = first
    ? doc.stable_orientations_rad.map((t, i) => [t, doc.probabilities[i]])
    : atoms.map(([t, p]) => [transfer(t - act.alpha_rad, doc), p]);
  const merged = [];
  for (const [t, p] of out) {
    const hit = merged.find((m) => Math.abs(wrap(m[0] - t)) < 1e-9);
    if (hit) hit[1] += p;
    else merged.push([t, p]);
  }
  return merged;
}

function givenReading(atoms, reading) {
  // the atoms whose jaw width lies in the reading's interval (all of them when none does,
  // as with a noisy sensor, where the tree's probabilities carry the update)
  const [lo, hi] = reading;
  const hull = state.policyDraw.hull;
  const keep = atoms.filter(([t]) => {
    const w = width(hull, t);
    return (lo === null || w >= lo - 1e-9) && (hi === null || w < hi - 1e-9);
  });
  return keep.length ? keep : atoms;
}

function mostProbable(atoms) {
  return atoms.reduce((a, b) => (b[1] > a[1] ? b : a))[0];
}

function policyNode(node, first, unit, belief) {
  // an action node: <details> whose summary is the action and whose children are its readings;
  // each node draws the part at the belief's most probable orientation, a declaration at its
  // declared orientation
  const d = document.createElement("details");
  d.open = true;
  d.className = "policy-node";
  const act = node.action;
  const sum = document.createElement("summary");
  const a = round((act.alpha_rad * 180) / Math.PI, 2);
  const here = !state.policyDraw ? 0 : first ? state.policyDraw.mode : mostProbable(belief);
  if (state.policyDraw && (first || !state.policyDraw.noisy)) sum.appendChild(partAt(here, `most probable orientation here: ${round(((deg(here) % 360) + 360) % 360, 2)}°`));
  sum.append(first ? `${act.type} with the gripper at ${a}°` : `turn ${a}°, ${act.type}`);
  d.appendChild(sum);
  const after = state.policyDraw ? afterAction(belief, act, first) : null;
  const ul = document.createElement("ul");
  for (const b of node.branches) {
    const li = document.createElement("li");
    const [lo, hi] = b.reading;
    const reads =
      lo === null && hi === null ? "any width"
      : lo === null ? `width below ${round(hi, 2)}${unit}`
      : hi === null ? `width ${round(lo, 2)}${unit} or more`
      : `width in [${round(lo, 2)}, ${round(hi, 2)})${unit}`;
    const head = `${reads} (p = ${prob(b.probability)})`;
    const n = b.next;
    const given = after ? givenReading(after, b.reading) : null;
    if (n.action) {
      li.append(document.createTextNode(head + ":"), policyNode(n, false, unit, given));
    } else if (n.reject) {
      if (given && !state.policyDraw.noisy) li.appendChild(partAt(mostProbable(given), "most probable orientation here"));
      li.append(`${head}: reject`);
    } else {
      const t = n.declare.orientation_rad;
      if (given) li.appendChild(partAt(t, `declared orientation ${round(((deg(t) % 360) + 360) % 360, 2)}°`));
      li.append(`${head}: declare ${round((t * 180) / Math.PI, 2)}° (success ${round(n.success_probability, 3)})`);
    }
    ul.appendChild(li);
  }
  d.appendChild(ul);
  return d;
}
