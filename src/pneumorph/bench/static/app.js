// The bench page: reads the target fields, asks the server, shows its answer. No design logic here.
import { drawProfile } from "./plot.js";
import { Viewer } from "./viewer.js";
import { DrawArea } from "./draw.js";

const $ = (id) => document.getElementById(id);
const state = { info: null, answer: null, seq: 0, selected: null, profiles: null, centrelines: null, curve: null,
  job: null, polling: new Set(), shapeSeq: 0, stages: [], stageCurve: null };
const ACTIVE = ["queued", "running"];
const FIELDS = ["target", "preset", "amplitude", "periods", "expression", "goal", "point", "points", "stages", "model", "unit",
  "top", "obstacle"];
const STAGE_COLOURS = ["#e07b1a", "#8250df", "#1a7f37", "#cf222e", "#bf8700", "#0a7ea4"];

async function api(path, options = {}) {
  const response = await fetch(path, { credentials: "same-origin", ...options });
  let data = null;
  try { data = await response.json(); } catch { data = null; }
  if (!response.ok) {
    const error = (data && data.error) || { field: "target", message: `the server answered ${response.status}` };
    throw Object.assign(new Error(error.message), { field: error.field });
  }
  return data;
}
const post = (path, body) => api(path, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });

function number(id) {
  const text = $(id).value.trim();
  const value = Number(text);
  return text === "" || !Number.isFinite(value) ? text : value;   // the server says what is wrong
}

function currentBody() {
  const kind = $("target-kind").value;
  let target;
  if (kind === "preset" && state.info.path_presets.includes($("preset").value)) target = { kind: "path", preset: $("preset").value };
  else if (kind === "preset") target = { kind, name: $("preset").value, amplitude: number("amplitude"), periods: number("periods") };
  else if (kind === "expression") target = { kind, expression: $("expression").value, amplitude: number("expr-amplitude") };
  else if (kind === "tip") {
    target = { kind, goal: $("goal").value };
    if (target.goal === "reach") {
      target.point = [number("point-x"), number("point-y")];
      if ($("point-z").value.trim() !== "") target.point.push(number("point-z"));   // off the plane of bending
    }
  } else if (kind === "stages") {
    target = { kind, stages: state.stages.map((st) => ({ pressure_kpa: st.pressure_kpa, target: { kind: "curve", points: st.points } })) };
  } else {
    target = { kind, points: state.curve || [] };
    if (state.curveTop) target.top_points = state.curveTop;   // the view from above: the curve's z
  }
  const body = { target, model: $("model").value, unit: $("unit").value, top: 10 };
  // an object on the page: the answer's design is solved against it by the 2D FE model with contact
  if ($("object-on").checked) body.obstacle = { centre: [number("object-x"), number("object-y")], radius: number("object-r") };
  return body;
}

function clearErrors() {
  for (const f of FIELDS) { const el = $(`${f}-error`); if (el) el.textContent = ""; }
  document.querySelectorAll("[aria-invalid]").forEach((el) => el.removeAttribute("aria-invalid"));
}

function showError(field, message) {
  const el = $(`${field}-error`) || $("target-error");
  el.textContent = message;
  const input = $(field === "amplitude" && $("target-kind").value === "expression" ? "expr-amplitude" : field);
  if (input && input.tagName === "INPUT") input.setAttribute("aria-invalid", "true");
}

// -- the answer ----------------------------------------------------------------------------
let timer = null;
function schedule() {
  clearTimeout(timer);
  timer = setTimeout(ask, 150);
}

async function ask() {
  if ($("target-kind").value === "curve" && !state.curve) return;   // nothing drawn yet
  if ($("target-kind").value === "stages" && !state.stages.length) return;   // no stage added yet
  const seq = ++state.seq;
  $("answer").dataset.state = "loading";
  // a tip goal over sideways units: a branch-and-bound over 4^15 designs (BENCHMARKS.md: 45-70 s on one core)
  if ($("target-kind").value === "tip" && $("unit").value === "spatial") {
    $("answer-time").textContent = "(searching 1,073,741,824 designs for a tip goal: about a minute)";
  }
  // a path takes a second or so; over the spatial library a branch-and-bound of minutes (docs/bench.md)
  const slow = setTimeout(() => {
    if (seq !== state.seq || $("answer-time").textContent.startsWith("(searching")) return;
    $("answer-time").textContent = `(searching${$("unit").value === "spatial" ? ": a path over 1,073,741,824 designs " +
      "takes minutes" : " ..."})`;
  }, 1500);
  try {
    const answer = await post("/api/design", currentBody());
    clearTimeout(slow);
    if (seq !== state.seq) return;                                  // a newer question is on its way
    clearErrors();
    show(answer);
  } catch (error) {
    clearTimeout(slow);
    if (seq !== state.seq) return;
    clearErrors();
    showError(error.field, error.message);
    $("answer").dataset.state = "error";
    if ($("answer-time").textContent.startsWith("(searching")) $("answer-time").textContent = "";
  }
}

function show(answer) {
  state.answer = answer;
  state.selected = answer.winner.design;
  state.profiles = answer.profiles;
  state.centrelines = answer.centrelines;   // a path's frame: the centres as the model reports them
  const w = answer.winner;
  $("answer").dataset.queryId = answer.query_id;
  $("answer").dataset.state = "ok";
  $("winner-design").textContent = w.design;
  $("design-boxes").innerHTML = [...w.design].map((b, i) => `<span class="b${b}" title="unit ${i + 1}">${b}</span>`).join("");
  $("winner-pressure").textContent = `${w.pressure_kpa.toFixed(1)} kPa (level ${w.level + 1} of ${answer.pressures_kpa.length})`;
  $("winner-error").textContent = `${w.value.toFixed(3)} ${answer.value_unit}` +
    (answer.sense === "max" ? " (maximised)" : answer.path ? " (the centres' distances to the path, root-sum-square)"
      : answer.value_unit === "mm" ? " (Eq 4.1)" : "");
  $("winner-label").textContent = answer.label;
  $("stroke-kind").textContent = answer.path && $("target-kind").value === "curve" ? "The stroke turns back (or " +
    "climbs too steeply) to be a graph y = f(x): it is matched as a path, the unit centres along it in order." : "";
  $("certificate").textContent = answer.certificate.statement;
  $("answer-time").textContent = answer.memo ? "(remembered)" : `(${answer.elapsed_ms.toFixed(0)} ms)`;
  const body = $("top-table").querySelector("tbody");
  body.innerHTML = answer.top.map((r) => `<tr data-design="${r.design}"${r.design === state.selected ? ' class="selected"' : ""}>` +
    `<td>${r.rank}</td><td><code>${r.design}</code></td><td>${r.value.toFixed(3)} ${answer.value_unit}</td>` +
    `<td>${r.pressure_kpa.toFixed(1)} kPa</td><td>${r.optimistic.toFixed(3)}</td></tr>`).join("");
  const slider = $("pressure-slider");
  slider.max = String(answer.pressures_kpa.length - 1);
  slider.value = String(w.level);
  redraw();
  loadShape();
}

function redraw() {
  const a = state.answer;
  if (!a) return;
  const k = Number($("pressure-slider").value);
  $("slider-value").textContent = `${a.pressures_kpa[k].toFixed(1)} kPa`;
  // a path (or stages with one) is drawn in its frame: the centres as the model reports them, y from the
  // bottom face; heights above the axis (profiles, tip points) are lifted onto the axis there
  const lift = state.centrelines ? a.axis_mm : 0;
  const lines = state.centrelines || state.profiles;
  const xy = (s, dy = 0) => s.x.map((x, i) => [x, s.y[i] + dy]);
  const up = (p) => (p && lift ? [p[0], p[1] + lift, ...p.slice(2)] : p);
  const target = a.path ? xy(a.path) : a.target ? xy(a.target, lift) : null;
  // stages: every stage's target (the one at this level drawn bold) and the whole ramp behind the profile
  const stages = (a.stages || []).map((st, i) => ({
    points: st.path ? xy(st.path) : st.target ? xy(st.target, lift) : null, point: up(st.point),
    colour: STAGE_COLOURS[i % STAGE_COLOURS.length], current: st.level === k,
    label: `${st.pressure_kpa} kPa ${st.path ? "path" : "target"}`,
  }));
  $("plot-title").textContent = a.path ? "Path: the unit centres as the model reports them"
    : state.centrelines ? "The unit centres as the model reports them" : "Profile";
  const touch = contactAt(k);
  drawProfile($("profile-plot"), { target, point: up(a.point), profile: lines[k], label: `design ${state.selected}`,
    stages, ramp: a.stages ? lines : null, axis: lift, vertical: lift ? "y (mm) from the bottom face" : "y (mm)",
    targetLabel: a.path ? `path${a.path.name === "path" ? "" : ` ${a.path.name}`}: the centres along it, in order` : "target",
    circle: touch && touch.circle, contact: touch ? touch.points : [], fe: touch ? touch.line : null });
  // a space curve or a design that leaves the plane: the view from above, the target's z against the
  // actuator's (z = 0 where the chain is planar: it bends in its plane)
  const shape = a.path || a.target;
  const targetZ = Boolean(shape && shape.z);
  const pointZ = Boolean(a.point && a.point.length === 3);
  const space = targetZ || pointZ || lines[k][0].length === 3;
  $("top-view").hidden = !space;
  if (space) {
    drawProfile($("top-plot"), { target: targetZ ? shape.x.map((x, i) => [x, shape.z[i]]) : null,
      point: pointZ ? [a.point[0], a.point[2]] : null, targetLabel: a.path ? "path" : "target",
      profile: lines[k].map(([x, , z]) => [x, z || 0]), label: `design ${state.selected}`, vertical: "z (mm)" });
  }
}

// the answer solved against the object at level k, drawn in the frame of the unit centres (y from the bottom face):
// the circle, the FE centreline and the nodes in contact
function contactAt(k) {
  const a = state.answer, c = a && a.contact;
  $("contact-text").hidden = !c;
  if (!c) return null;
  if (c.failure || !c.levels.length) { $("contact-text").textContent = `Against the object: ${c.failure}`; return null; }
  const lv = c.levels[k];
  const shown = state.selected === c.design;
  $("contact-text").textContent = `Against the object (design ${c.design}, 2D FE with contact) at ` +
    `${lv.pressure_kpa.toFixed(1)} kPa: force ${lv.force_magnitude_n.toFixed(4)} N ` +
    `(${lv.force_n.map((v) => v.toFixed(4)).join(", ")}), contact length ${lv.contact_length_mm.toFixed(2)} mm, ` +
    `clearance ${lv.clearance_mm.toFixed(3)} mm, ${lv.points.length} node${lv.points.length === 1 ? "" : "s"} in contact` +
    (shown ? "" : "; the design shown is not the one solved against it");
  // an answer with an object has its centrelines: the plot is in the model's frame, as the object's
  return { circle: { centre: c.obstacle.centre, radius: c.obstacle.radius }, points: shown ? lv.points : [],
    line: shown ? lv.centreline : null };
}

function renderStages() {
  $("stage-list").innerHTML = state.stages.map((st, i) => `<li style="color:${STAGE_COLOURS[i % STAGE_COLOURS.length]}">` +
    `${st.pressure_kpa} kPa: a drawn curve (${st.points.length} points) <button type="button" data-stage="${i}">remove</button></li>`).join("");
}

async function select(design) {
  const a = state.answer;
  state.selected = design;
  document.querySelectorAll("#top-table tbody tr").forEach((tr) => tr.classList.toggle("selected", tr.dataset.design === design));
  const data = await api(`/api/profiles?design=${design}&model=${a.model}&unit=${encodeURIComponent($("unit").value)}`);
  state.profiles = data.profiles;
  state.centrelines = a.centrelines ? data.centrelines : null;
  redraw();
  loadShape();
}

let shapeTimer = null;
function loadShape() {
  clearTimeout(shapeTimer);
  shapeTimer = setTimeout(async () => {
    const a = state.answer;
    if (!a) return;
    const seq = ++state.shapeSeq;
    const level = $("pressure-slider").value;
    try {
      const shape = await api(`/api/shape?design=${state.selected}&level=${level}&model=${a.model}&unit=${encodeURIComponent($("unit").value)}`);
      if (seq !== state.shapeSeq) return;
      viewer.show(shape, shape.source === "fe" ? [0.3, 0.62, 0.45] : [0.35, 0.55, 0.8]);
      $("shape-source").textContent = shape.source === "fe" ? "(3D FE solution)" : "(laid along the chain model's centreline)";
    } catch (error) {
      $("shape-source").textContent = `(${error.message})`;
    }
  }, 60);
}

// -- jobs ----------------------------------------------------------------------------------
function renderJob(job) {
  if (!state.job || job.id !== state.job) return;
  $("job-progress").value = job.progress;
  $("job-status").textContent = job.state;
  $("job-status").title = job.message;
  $("job-log").textContent = job.log.join("\n");
  $("job-cancel").hidden = !ACTIVE.includes(job.state);
  $("downloads").innerHTML = job.files.map((f) => `<li><a href="${f.url}" download="${f.name}">${f.name}</a></li>`).join("");
  if (job.state === "done" && job.kind === "verify" && job.result) {
    const r = job.result;
    $("job-status").textContent = `done: ${r.design} ${r.fe_value.toFixed(3)} ${r.unit} by FE ` +
      `(chain ${r.chain_value.toFixed(3)})${r.certified ? ", certified" : `, gap ${r.gap.toFixed(3)}`}`;
    $("job-status").dataset.state = "done";
  } else {
    $("job-status").dataset.state = job.state;
  }
}

async function refreshJobs() {
  const { jobs } = await api("/api/jobs");
  $("jobs").innerHTML = jobs.map((j) => `<li data-job="${j.id}"><a href="#" data-job="${j.id}">${j.kind}</a> ` +
    `${j.state}${j.state === "running" ? ` (${Math.round(100 * j.progress)} %)` : ""}` +
    `${j.state === "done" ? summary(j) : `: ${escape(j.message)}`}</li>`).join("");
  for (const j of jobs) {
    if (ACTIVE.includes(j.state)) poll(j.id);
  }
  return jobs;
}

function summary(job) {
  const r = job.result || {};
  if (job.kind === "verify") return `: ${r.design} ${r.fe_value.toFixed(3)} ${r.unit} by ${r.model.toUpperCase()} FE`;
  if (job.kind === "export") return `: ${r.design}`;
  if (job.kind === "table") return `: unit ${escape(r.name)} (${r.model})`;
  return "";
}

function escape(text) {
  return String(text).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" }[c]));
}

async function poll(id) {
  if (state.polling.has(id)) return;
  state.polling.add(id);
  try {
    for (;;) {
      const job = await api(`/api/jobs/${id}`);
      renderJob(job);
      if (!ACTIVE.includes(job.state)) {                            // done, failed, cancelled or interrupted
        await refreshJobs();
        if (job.kind === "verify" && job.state === "done") loadShape();
        if (job.kind === "table" && job.state === "done") await refreshUnits(job.result.unit_id);
        break;
      }
      await new Promise((r) => setTimeout(r, 1000));
    }
  } finally {
    state.polling.delete(id);
  }
}

async function start(body, path = "/api/jobs", options = null) {
  try {
    const { job_id } = options ? await api(path, options) : await post(path, body);
    state.job = job_id;
    $("job-status").textContent = "queued";
    $("job-status").dataset.state = "queued";
    $("job-progress").value = 0;
    $("downloads").innerHTML = "";
    await refreshJobs();
    poll(job_id);
  } catch (error) {
    clearErrors();
    showError(error.field, error.message);
  }
}

async function refreshUnits(choose) {
  const { units } = await api("/api/units");
  $("unit").innerHTML = units.map((u) => `<option value="${u.id}">${escape(u.name)} (${u.id === "builtin" ? "built-in" : u.model})</option>`).join("");
  if (choose) { $("unit").value = choose; schedule(); }
}

// -- wiring --------------------------------------------------------------------------------
function showKind() {
  const kind = $("target-kind").value;
  document.querySelectorAll("fieldset[data-kind]").forEach((f) => { f.hidden = f.dataset.kind !== kind; });
  $("point-fields").hidden = $("goal").value !== "reach";
}

const viewer = new Viewer($("viewer"));
let drawArea = null;
let topArea = null;
let stageArea = null;

async function main() {
  state.info = await api("/api/info");
  $("goal").innerHTML = state.info.tip_goals.map((g) => `<option value="${g}">${g}</option>`).join("");
  $("preset").insertAdjacentHTML("beforeend", `<optgroup label="Paths: the unit centres along a shape, in order">` +
    state.info.path_presets.map((p) => `<option value="${p}">${p} (a path)</option>`).join("") + "</optgroup>");
  drawArea = new DrawArea($("draw-canvas"), state.info.length_mm, (points) => { state.curve = points; schedule(); });
  topArea = new DrawArea($("draw-top-canvas"), state.info.length_mm, (points) => { state.curveTop = points; schedule(); });
  const changed = () => { showKind(); schedule(); };
  for (const id of ["target-kind", "preset", "amplitude", "periods", "expression", "expr-amplitude", "goal", "point-x",
    "point-y", "point-z", "model", "unit", "object-on", "object-x", "object-y", "object-r"]) {
    $(id).addEventListener("input", changed);
    if ($(id).tagName === "SELECT") $(id).addEventListener("change", changed);
  }
  $("draw-clear").addEventListener("click", () => {
    drawArea.clear(); topArea.clear(); state.curve = null; state.curveTop = null;
  });
  stageArea = new DrawArea($("stage-canvas"), state.info.length_mm, (points) => { state.stageCurve = points; });
  $("stage-pressure").innerHTML = state.info.pressures_kpa.map((p) => `<option value="${p}">${+p.toFixed(3)} kPa</option>`).join("");
  $("stage-pressure").value = String(state.info.pressures_kpa[state.info.pressures_kpa.length - 1]);
  $("stage-add").addEventListener("click", () => {
    clearErrors();
    if (!state.stageCurve) { showError("stages", "draw the stage's curve first"); return; }
    const pressure = Number($("stage-pressure").value);
    state.stages = state.stages.filter((st) => st.pressure_kpa !== pressure);   // one stage per pressure: the newest
    state.stages.push({ pressure_kpa: pressure, points: state.stageCurve });
    state.stages.sort((a, b) => a.pressure_kpa - b.pressure_kpa);
    state.stageCurve = null; stageArea.clear(); renderStages(); schedule();
  });
  $("stage-clear").addEventListener("click", () => { state.stages = []; renderStages(); });
  $("stage-list").addEventListener("click", (e) => {
    const b = e.target.closest("button[data-stage]");
    if (!b) return;
    state.stages.splice(Number(b.dataset.stage), 1); renderStages(); schedule();
  });
  $("pressure-slider").addEventListener("input", () => { redraw(); loadShape(); });
  $("top-table").addEventListener("click", (e) => { const tr = e.target.closest("tr[data-design]"); if (tr) select(tr.dataset.design); });
  $("verify-button").addEventListener("click", () => start({ kind: "verify", query: currentBody() }));
  $("export-button").addEventListener("click", () => start({ kind: "export", design: state.selected, unit: $("unit").value }));
  $("job-cancel").addEventListener("click", async () => {
    if (!state.job) return;
    try { renderJob(await api(`/api/jobs/${state.job}`, { method: "DELETE" })); await refreshJobs(); }
    catch (error) { showError(error.field, error.message); }
  });
  $("unit-upload").addEventListener("click", () => {
    const file = $("unit-file").files[0];
    if (!file) { showError("unit", "choose a unit TOML file first"); return; }
    const form = new FormData();
    form.append("unit", file);
    form.append("model", $("model").value);
    start(null, "/api/jobs/table", { method: "POST", body: form });
  });
  $("jobs").addEventListener("click", async (e) => {
    const a = e.target.closest("a[data-job]");
    if (!a) return;
    e.preventDefault();
    state.job = a.dataset.job;
    renderJob(await api(`/api/jobs/${state.job}`));
  });
  showKind();
  await refreshUnits();
  const jobs = await refreshJobs();
  if (jobs.length) { state.job = jobs[0].id; renderJob(jobs[0]); }
  ask();
}

main().catch((error) => { $("target-error").textContent = `the page could not start: ${error.message}`; });
