// posecov live: the control page. Plain JavaScript, no build step.
// The controls come from GET /api/state; a change is POSTed to /api/edit as {id, value};
// the server validates it exactly as a scenario file and answers with the new state or
// with the error and the field it names. /api/status is polled for progress.
"use strict";

const $ = (id) => document.getElementById(id);
const rows = new Map(); // control id -> {range, number, row, control}
let pending = null;     // newest edit waiting to be sent
let sending = false;
let lastGood = new Map(); // id -> last accepted value

async function call(method, path, body) {
  const init = { method, headers: {} };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  const response = await fetch(path, init);
  const data = await response.json().catch(() => ({ error: response.statusText }));
  return { ok: response.ok, data };
}

function fmt(x, step) {
  if (!Number.isFinite(x)) return String(x);
  const digits = Math.min(6, Math.max(0, -Math.floor(Math.log10(step || 1))));
  return Number(x.toFixed(digits)).toString();
}

function render(state) {
  document.title = `posecov live — ${state.title}`;
  $("title").textContent = state.title;
  $("origin").textContent = state.origin;
  $("save").hidden = !state.save_to;
  if (state.save_to) $("save").title = `Write the current values to ${state.save_to}`;
  if (state.viewer_url && $("viewer").hidden) {
    $("viewer").hidden = false;
    // Through this page's own server (same origin): the viewer reads its stream from the
    // host this page was reached at, so a tablet that reaches the page gets the viewer too.
    const stream = encodeURIComponent(`rerun+${location.protocol}//${location.host}/proxy`);
    $("viewer-frame").src = state.viewer_same_origin ? `${state.viewer_url}?url=${stream}` : state.viewer_url;
  }
  document.body.classList.toggle("no-viewer", !state.viewer_url);
  const form = $("controls");
  form.textContent = "";
  rows.clear();
  const sections = new Map();
  for (const c of state.controls) {
    if (!sections.has(c.section)) {
      const fs = document.createElement("fieldset");
      const legend = document.createElement("legend");
      legend.textContent = c.section;
      fs.append(legend);
      sections.set(c.section, { fs, toggles: null });
      form.append(fs);
    }
    const section = sections.get(c.section);
    if (c.kind.type === "toggle") {
      if (!section.toggles) {
        section.toggles = document.createElement("div");
        section.toggles.className = "toggles";
        section.fs.append(section.toggles);
      }
      const label = document.createElement("label");
      const box = document.createElement("input");
      box.type = "checkbox";
      box.checked = c.kind.value;
      box.dataset.id = c.id;
      box.addEventListener("change", () => send(c.id, box.checked));
      label.append(box, " ", c.label);
      section.toggles.append(label);
      rows.set(c.id, { box, control: c });
      lastGood.set(c.id, c.kind.value);
    } else {
      section.fs.append(numberRow(c));
    }
  }
}

function numberRow(c) {
  const k = c.kind;
  const row = document.createElement("div");
  row.className = "row";
  const label = document.createElement("label");
  label.textContent = c.label;
  label.title = c.id;
  const range = document.createElement("input");
  range.type = "range";
  range.min = Math.min(k.min, k.value);
  range.max = Math.max(k.max, k.value);
  range.step = k.step;
  range.value = k.value;
  range.dataset.id = c.id;
  range.setAttribute("aria-label", `${c.section}: ${c.label}`);
  const number = document.createElement("input");
  number.type = "number";
  number.step = "any";
  number.value = fmt(k.value, k.step);
  number.dataset.id = c.id;
  number.setAttribute("aria-label", `${c.section}: ${c.label} (typed)`);
  const unit = document.createElement("span");
  unit.className = "unit";
  unit.textContent = c.unit;
  const id = label.htmlFor = `c-${c.id}`;
  range.id = id;
  range.addEventListener("input", () => {
    number.value = fmt(Number(range.value), k.step);
    send(c.id, Number(range.value));
  });
  const typed = () => {
    // A cleared field (or one the browser cannot read as a number) is sent as null: the
    // server refuses it naming the field.
    const v = number.value.trim() === "" ? null : Number(number.value);
    if (v !== null && Number.isFinite(v)) {
      if (Number(range.min) > v) range.min = v;
      if (Number(range.max) < v) range.max = v;
      range.value = v;
    }
    send(c.id, v);
  };
  number.addEventListener("change", typed);
  number.addEventListener("keydown", (e) => { if (e.key === "Enter") typed(); });
  row.append(label, range, number, unit);
  rows.set(c.id, { range, number, row, control: c });
  lastGood.set(c.id, k.value);
  return row;
}

// Only the newest value matters: while one edit is in flight, later ones replace each other.
function send(id, value) {
  pending = { id, value };
  if (!sending) flush();
}

async function flush() {
  sending = true;
  while (pending) {
    const edit = pending;
    pending = null;
    // JSON has no NaN: send it as a string the server refuses with the field named.
    const body = { id: edit.id, value: Number.isNaN(edit.value) ? "NaN" : edit.value };
    const { ok, data } = await call("POST", "/api/edit", body).catch((e) => ({ ok: false, data: { error: String(e) } }));
    const r = rows.get(edit.id);
    if (ok) {
      lastGood.set(edit.id, edit.value);
      if (r && r.row) r.row.classList.remove("bad");
      showError(null);
      updateStatus(data.status);
      // Values elsewhere never change on an edit; a structural change (methods) re-renders.
      if (data.controls.length !== rows.size) render(data);
    } else {
      if (r && r.row) r.row.classList.add("bad");
      showError(data.error + (pending ? "" : "\n(the last good picture stays)"));
    }
  }
  sending = false;
}

function showError(message) {
  $("error").hidden = !message;
  $("error").textContent = message || "";
}

// "· inside the 95 % regions of map_from_camera: first order 95 % tangent, 70 % Cartesian; …"
function coverageText(coverage) {
  if (!coverage || coverage.length === 0) return "";
  const names = { tangent: "tangent", tangent_position: "position", cartesian: "Cartesian", vector_space: "ellipse" };
  const pct = (x) => `${(100 * x).toFixed(1)} %`;
  const first = coverage[0];
  const at = first.step === null ? first.output : `${first.output} (step ${first.step})`;
  const methods = coverage.map((m) => {
    const regions = m.coverage
      .filter((c) => c.region !== "tangent_position")
      .map((c) => `${pct(c.inside)} ${names[c.region] || c.region}`);
    return `${m.method} ${regions.join(", ")}`;
  });
  return ` · inside the ${pct(first.confidence)} regions of ${at}: ${methods.join("; ")}`;
}

function updateStatus(s) {
  if (!s) return;
  const el = $("status");
  const busy = s.phase !== "idle";
  el.classList.toggle("busy", busy);
  // Each accepted change (and Reset) is numbered; 0 is the file as opened.
  const change = (n) => (n === 0 ? "the file's values" : `change ${n}`);
  const shown = s.shown === null ? "nothing yet" : change(s.shown);
  const samples = s.shown_samples ? `, ${s.shown_samples} samples` : "";
  const first = s.first_picture_ms !== null ? ` · first picture ${s.first_picture_ms.toFixed(0)} ms` : "";
  const final = s.final_picture_ms !== null && s.done ? ` · final ${s.final_picture_ms.toFixed(0)} ms` : "";
  const phase = s.phase === "preview" ? "quick preview" : "full picture";
  const doing = busy ? ` · ${phase} of ${change(s.generation)} (${s.samples} samples)…` : "";
  el.textContent = `showing ${shown}${s.done ? "" : " (preview)"}${samples}${first}${final}${doing}${coverageText(s.coverage)}`;
  el.dataset.generation = s.generation;
  el.dataset.shown = s.shown === null ? "" : s.shown;
  el.dataset.done = s.done;
  const p = $("progress");
  p.hidden = !busy;
  p.value = s.phase === "preview" ? 0.3 : s.phase === "full" ? 0.7 : 1;
  if (s.error) showError(s.error);
}

async function poll() {
  const { ok, data } = await call("GET", "/api/status").catch(() => ({ ok: false }));
  if (ok) updateStatus(data);
  setTimeout(poll, data && data.phase !== "idle" ? 100 : 400);
}

$("reset").addEventListener("click", async () => {
  const { ok, data } = await call("POST", "/api/reset", {});
  if (ok) { render(data); updateStatus(data.status); showError(null); } else showError(data.error);
});

$("reframe").addEventListener("click", async () => {
  const { ok, data } = await call("POST", "/api/reframe", {});
  if (ok) updateStatus(data.status); else showError(data.error);
});

$("save").addEventListener("click", async () => {
  const { ok, data } = await call("POST", "/api/save", {});
  showError(ok ? null : data.error);
  if (ok) $("status").textContent = `saved ${data.saved}`;
});

(async () => {
  const { ok, data } = await call("GET", "/api/state");
  if (!ok) { showError(data.error); return; }
  render(data);
  updateStatus(data.status);
  poll();
})();
