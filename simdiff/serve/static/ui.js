// Page wiring: controls → API → player. Page state for tests and scripts is window.simdiffState; the 3D
// view's numbers are window.simdiffViewer.debug().

import { api } from "./api.js";
import { SkeletonPlayer } from "./player.js";
import { BodyPlayer } from "./scene.js";

const $ = (id) => document.getElementById(id);
const SLIDERS = ["gravity", "wind_x", "wind_y", "alpha", "env_guidance", "guidance"];
/** Sliders that act only with a physics (SimDiff) model. */
const ENV_SLIDERS = ["gravity", "wind_x", "wind_y", "alpha", "env_guidance"];

const state = {
  status: "starting",  // starting | loading | generating | opening | ready | idle | error
  error: null,         // last one-line error, null after a success
  frames: 0,           // frames of the motion on screen
  frame: 0,
  playing: false,
  generation_id: 0,    // generated motions shown so far
  shown: 0,            // motions shown so far (generated, opened, re-played, timelines)
  params: null,        // parameters of the motion on screen (generated and re-played ones)
  source: null,        // "generate" | "file" | "upload" | "edit" (a re-play) | "timeline"
  motion: null,        // the server's number of the motion on screen (an answer's `motion`)
  file_motion: null,   // number of the open file's motion, which "Re-play" and the sliders re-play; null: no file open
  file_name: null,
  pins: { start: null, end: null },  // numbers of the motions whose first / last pose the next generation pins
  digest: null,        // checksum of the joints on screen (changes when the motion does)
  meta: null,
  model: null,
  view: null,          // "webgl" (body + stick figure) | "2d" (stick figure only: no WebGL here)
  body: null,          // the body of the motion on screen: "loading" | "ready" | "error" | null (2d view)
  body_error: null,    // why it could not be shown
  stick: false,        // the stick-figure box
};
window.simdiffState = state;

const hooks = {
  onFrame(frame, frames, playing) {
    Object.assign(state, { frame, frames, playing });
    $("scrub").max = String(Math.max(0, frames - 1));
    $("scrub").value = String(frame);
    const fps = player.motion ? player.motion.fps : 20;
    $("time").textContent = `${(frame / fps).toFixed(2)} / ${(Math.max(0, frames - 1) / fps).toFixed(2)} s`;
    $("play").textContent = playing ? "Pause" : "Play";
  },
};
let player;
try {
  player = new BodyPlayer($("view"), hooks);
  state.view = "webgl";
} catch (err) {  // no WebGL: the 2D stick figure
  player = new SkeletonPlayer($("view"), hooks);
  state.view = "2d";
  $("stick").closest("label").hidden = true;
  $("model-info").dataset.note = "No WebGL in this browser: the stick figure only.";
}
window.simdiffPlayer = player;
window.simdiffViewer = { debug: () => (player.debug ? player.debug() : { renderer: "2d" }) };

/** Fetch and show the body of `motion` (the answer's `body` address); the stick figure stands in meanwhile. */
async function showBody(motion) {
  if (!player.setBody) return;
  Object.assign(state, { body: "loading", body_error: null });
  try {
    if (!motion.body) throw new Error("the server sent no body");
    const bytes = await api.body(motion.body);
    await player.setBody(motion, bytes);
    if (player.motion === motion) state.body = "ready";
  } catch (err) {
    if (player.motion !== motion) return;
    player.bodyFailed();
    Object.assign(state, { body: "error", body_error: err.message });
    $("status").textContent += ` No body: ${err.message}`;
  }
}

function setStatus(status, text) {
  state.status = status;
  $("status").textContent = text;
  document.body.classList.toggle("busy", status === "generating" || status === "opening");
}

function showError(message) {
  state.error = message;
  $("error").textContent = message;
  $("error").hidden = false;
  $("error").scrollIntoView({ block: "nearest" });  // the panel may be scrolled to the timeline builder
  setStatus("error", "");
}

function digest(joints) {
  let sum = 0;
  joints.forEach((pose, t) => pose.forEach(([x, y, z], j) => { sum += (t + 1) * (x + 2 * y + 3 * z) + j * 1e-3; }));
  return Math.round(sum * 1e4) / 1e4;
}

const envText = (p) => `g ${p.gravity.toFixed(2)} m/s² · wind (${p.wind_x.toFixed(1)}, ${p.wind_y.toFixed(1)}) N`;
const gravityText = (read) => (read ? `${read.gravity.toFixed(1)} m/s²` : "none (no flight)");

function show(motion) {
  player.load(motion);
  showBody(motion);
  const meta = motion.meta;
  Object.assign(state, { frames: motion.joints.length, source: meta.source, digest: digest(motion.joints), meta, error: null,
    motion: motion.motion ?? null, shown: state.shown + 1 });
  $("error").hidden = true;
  const waited = meta.queue_position ? ` after waiting ${meta.waited_s.toFixed(1)} s behind ${meta.queue_position} request(s)` : "";
  let caption;
  if (meta.source === "generate") {
    const p = meta.params;
    state.params = p;
    state.generation_id += 1;
    caption = `“${p.text}”` + (meta.env_used ? ` · ${envText(p)} · α ${meta.sampling.alpha}` + (meta.sampling.env_guidance !== 1 ? ` · environment guidance ${meta.sampling.env_guidance}` : "") : "");
    if (meta.simulated) caption += ` · simulated finish (${meta.simulated.status}, joint error ${Math.round(meta.simulated.err_mm)} mm)`;
    const pinned = meta.pins ? ` Pinned ${[meta.pins.start !== null ? "start" : "", meta.pins.end !== null ? "end" : ""].filter(Boolean).join(" and ")} pose met within ${meta.keyframe_error_cm.toFixed(1)} cm.` : "";
    if (meta.pins) caption += " · pinned pose";
    setStatus("ready", `Generated ${meta.frames} frames in ${meta.elapsed_s.toFixed(2)} s${waited}.${pinned}`);
    setFile(null);
  } else if (meta.source === "edit") {
    state.params = meta.params;
    caption = `${state.file_name ?? `motion ${meta.params.source}`} re-played · ${envText(meta.params)} · α ${meta.sampling.alpha}`;
    const read = meta.gravity_read;
    const flights = read.input || read.edited
      ? ` Gravity read from the flights: ${gravityText(read.input)} before, ${gravityText(read.edited)} after.`
      : " No flight to read gravity from.";
    setStatus("ready", `Re-played ${meta.frames} frames in ${meta.elapsed_s.toFixed(2)} s${waited}: joints moved `
      + `${(100 * meta.changed_m).toFixed(1)} cm on average.${flights}`);
  } else if (meta.source === "timeline") {
    state.params = null;
    caption = meta.segments.map((s) => `“${s.text}”` + (meta.env_used && (s.gravity !== -9.81 || s.wind[0] || s.wind[1]) ? ` (g ${s.gravity}, wind ${s.wind[0]}, ${s.wind[1]})` : "")).join(" → ");
    setStatus("ready", `Generated a timeline of ${meta.segments.length} prompts: ${meta.frames} frames (${meta.seconds.toFixed(2)} s) in ${meta.elapsed_s.toFixed(2)} s${waited}.`);
    setFile(null);
  } else {
    state.params = null;
    caption = meta.name;
    setStatus("ready", `Opened ${meta.name}: ${meta.frames} frames (${meta.seconds.toFixed(2)} s).`);
    setFile(motion.motion ?? null, meta.name);
  }
  if (meta.warnings?.length) $("status").textContent += ` Warning: ${meta.warnings.join(" ")}`;
  $("caption").textContent = caption;
}

/** The open file (its motion's number) that "Re-play" and the sliders re-play; null when a generated motion replaced it. */
function setFile(number, name = null) {
  Object.assign(state, { file_motion: number, file_name: number === null ? null : name });
  $("replay").hidden = number === null;
}

// -- generation: one request at a time, the latest one wins ------------------------------------

let busy = false;
let pending = null;  // the next request: {verb, call}; a newer one replaces it
/** Foot-lock strength when the box is ticked: the model's own (1 if it has none). */
let footLock = 1;

function readParams() {
  const value = (id) => Number($(id).value);
  return {
    text: $("prompt").value.trim() || $("prompt").placeholder,
    gravity: value("gravity"), wind_x: value("wind_x"), wind_y: value("wind_y"), alpha: value("alpha"),
    env_guidance: value("env_guidance"), guidance: value("guidance"),
    seconds: value("seconds"), seed: Math.round(value("seed")),
    simulate: Boolean($("simulate") && $("simulate").checked),
    foot_lock: $("foot_lock") && $("foot_lock").checked ? footLock : 0,
    ...(state.pins.start !== null ? { pin_start: state.pins.start } : {}),
    ...(state.pins.end !== null ? { pin_end: state.pins.end } : {}),
  };
}

/** Run `call` (an API request answering a motion) after the running one; `verb` says what it does. */
async function submit(verb, call) {
  pending = { verb, call };
  if (busy) return;
  busy = true;
  try {
    while (pending) {
      const job = pending;
      pending = null;
      const loading = state.model && !state.model.loaded;
      setStatus("generating", loading ? `Loading the model and ${job.verb}…` : `${job.verb[0].toUpperCase()}${job.verb.slice(1)}…`);
      try {
        show(await job.call());
        if (state.model) state.model.loaded = true;
      } catch (err) {
        showError(err.message);
      }
    }
  } finally {
    busy = false;
  }
}

function generate() {
  const params = readParams();
  submit("generating", () => api.generate(params));
}

/** The open file re-played under the sliders' gravity and wind (and α, environment guidance, foot lock, seed). */
function replay() {
  if (state.file_motion === null) return showError("Re-play needs a motion file open: open one first");
  const { gravity, wind_x, wind_y, alpha, env_guidance, seed, foot_lock } = readParams();
  const params = { source: state.file_motion, gravity, wind_x, wind_y, alpha, env_guidance, seed, foot_lock };
  submit("re-playing", () => api.edit(params));
}

/** Sliders act on what is on screen: an open file is re-played, anything else generated from the prompt. */
function regenerate() {
  if (state.file_motion !== null && state.model && state.model.env) replay();
  else generate();
}

// -- pins: the first / last pose of the motion on screen when the box is ticked ------------------

function bindPin(end) {
  const box = $(end ? "pin_end" : "pin_start");
  const key = end ? "end" : "start";
  box.addEventListener("change", () => {
    if (box.checked && state.motion === null) {
      box.checked = false;
      showError(`Pin ${key} pose needs a motion on screen: generate or open one first`);
    }
    state.pins[key] = box.checked ? state.motion : null;
    const notes = ["start", "end"].filter((k) => state.pins[k] !== null).map((k) => `${k} pose of motion ${state.pins[k]}`);
    $("pin-note").textContent = notes.length ? `Pinned: the ${notes.join(" and the ")} (${$("caption").textContent || "on screen"}).` : "";
    $("pin-note").hidden = !notes.length;
  });
}

// -- timeline builder ------------------------------------------------------------------------

const SEGMENT_FIELDS = [["seg-seconds", "s", "0.1"], ["seg-gravity", "g", "0.01"], ["seg-wind-x", "wind x", "0.1"], ["seg-wind-y", "wind y", "0.1"]];

/** Add a row (prompt, seconds, gravity, optional wind) to the timeline builder. */
function addSegment(text = "", seconds = 3, gravity = -9.81) {
  const row = document.createElement("div");
  row.className = "segment";
  const prompt = Object.assign(document.createElement("input"), { className: "seg-text", type: "text", value: text, placeholder: "prompt", maxLength: 500 });
  prompt.setAttribute("aria-label", "segment prompt");
  const numbers = document.createElement("div");
  numbers.className = "numbers";
  for (const [cls, name, step] of SEGMENT_FIELDS) {
    const label = document.createElement("label");
    const input = Object.assign(document.createElement("input"), { className: cls, type: "number", step });
    if (cls === "seg-seconds") input.value = String(seconds);
    else if (cls === "seg-gravity") input.value = String(gravity);
    else input.placeholder = "0";
    label.append(name, input);
    numbers.append(label);
  }
  const remove = Object.assign(document.createElement("button"), { type: "button", className: "seg-remove", textContent: "×", title: "remove this row" });
  remove.addEventListener("click", () => row.remove());
  numbers.append(remove);
  row.append(prompt, numbers);
  $("segments").append(row);
  return row;
}

/** The rows as the API's segments; blank numbers are left out (the server names what is missing or wrong). */
function readTimeline() {
  const number = (row, cls) => { const v = row.querySelector(`.${cls}`).value; return v === "" ? null : Number(v); };
  const segments = [...$("segments").querySelectorAll(".segment")].map((row) => {
    const segment = { text: row.querySelector(".seg-text").value };
    const seconds = number(row, "seg-seconds");
    const gravity = number(row, "seg-gravity");
    const wind = [number(row, "seg-wind-x"), number(row, "seg-wind-y")];
    if (seconds !== null) segment.seconds = seconds;
    if (gravity !== null) segment.gravity = gravity;
    if (wind[0] !== null || wind[1] !== null) segment.wind = wind.map((w) => w ?? 0);
    return segment;
  });
  const { alpha, env_guidance, guidance, foot_lock, seed } = readParams();
  return { segments, seed, alpha, env_guidance, guidance, foot_lock };
}

function generateTimeline() {
  const params = readTimeline();
  submit("generating the timeline", () => api.timeline(params));
}

async function openWith(label, load) {
  setStatus("opening", `Opening ${label}…`);
  try {
    show(await load());
  } catch (err) {
    showError(err.message);
  }
}

// -- controls --------------------------------------------------------------------------------

function configure(info) {
  const { limits, defaults } = info;
  const ranges = {
    gravity: limits.gravity, wind_x: [-limits.wind, limits.wind], wind_y: [-limits.wind, limits.wind], alpha: limits.alpha,
    env_guidance: limits.env_guidance, guidance: limits.guidance,
  };
  for (const id of SLIDERS) {
    const input = $(id);
    [input.min, input.max] = ranges[id].map(String);
    input.value = String(defaults[id]);  // step "any": the model's exact value, not snapped to a grid
    const label = () => { $(`${id}-value`).textContent = String(Number(Number(input.value).toFixed(3))); };
    label();
    input.addEventListener("input", label);
    input.addEventListener("change", regenerate);
    input.disabled = ENV_SLIDERS.includes(id) && !info.model.env;
  }
  $("env-note").hidden = info.model.env || !info.model.found;
  $("prompt").value = defaults.text;
  Object.assign($("seconds"), { min: String(limits.min_seconds ?? 1 / limits.fps), max: String(limits.seconds), value: String(defaults.seconds) });
  $("seed").value = String(defaults.seed);
  $("foot_lock").checked = Number(defaults.foot_lock) > 0;
  footLock = Number(defaults.foot_lock) > 0 ? Number(defaults.foot_lock) : 1;
  $("version").textContent = `v${info.version}`;
  const m = info.model;
  $("model-info").textContent = (m.error ? m.error : `Model: ${m.path} (${m.kind})`) + ($("model-info").dataset.note ? ` ${$("model-info").dataset.note}` : "");
  $("generate").disabled = !m.found || Boolean(m.error);
  $("generate-timeline").disabled = $("generate").disabled;
  $("replay").disabled = $("generate").disabled || !m.env;
  if (!m.env) $("replay").title = "this model has no physics adapters: it cannot re-play a motion under gravity and wind";
  addSegment(defaults.text, 3, defaults.gravity);
  for (const b of $("gravity-presets").querySelectorAll("button")) {
    b.disabled = !m.env;
    b.addEventListener("click", () => {
      $("gravity").value = b.dataset.gravity;
      $("gravity").dispatchEvent(new Event("input"));
      regenerate();
    });
  }
  const list = $("file-list");
  if (info.files.length) {
    list.hidden = false;
    list.replaceChildren(new Option("files from the command line…", ""),
      ...info.files.map((f) => new Option(`${f.name} (${f.frames} frames)`, String(f.index))));
    list.addEventListener("change", () => {
      if (list.value !== "") openWith(list.selectedOptions[0].text, () => api.openListed(Number(list.value)));
    });
  }
}

function bindControls() {
  $("generate-form").addEventListener("submit", (e) => { e.preventDefault(); generate(); });
  $("prompt").addEventListener("keydown", (e) => {
    if (e.key === "Enter" && !e.shiftKey) { e.preventDefault(); generate(); }
  });
  $("play").addEventListener("click", () => player.toggle());
  $("replay").addEventListener("click", replay);
  $("add-segment").addEventListener("click", () => addSegment());
  $("generate-timeline").addEventListener("click", generateTimeline);
  bindPin(false);
  bindPin(true);
  $("scrub").addEventListener("input", () => {
    const frame = Number($("scrub").value);  // read first: pausing redraws the timeline
    player.pause();
    player.setFrame(frame);
  });
  $("follow").addEventListener("change", () => { player.follow = $("follow").checked; player._dirty = true; });
  $("stick").addEventListener("change", () => {
    state.stick = $("stick").checked;
    if (player.setStick) player.setStick(state.stick);
  });
  $("file-input").addEventListener("change", () => {
    const file = $("file-input").files[0];
    if (file) openWith(file.name, () => api.open(file));
    $("file-input").value = "";
  });
  const stage = $("stage");
  stage.addEventListener("dragover", (e) => { e.preventDefault(); document.body.classList.add("dragging"); });
  stage.addEventListener("dragleave", () => document.body.classList.remove("dragging"));
  stage.addEventListener("drop", (e) => {
    e.preventDefault();
    document.body.classList.remove("dragging");
    const file = e.dataTransfer.files[0];
    if (file) openWith(file.name, () => api.open(file));
  });
  document.addEventListener("keydown", (e) => {
    if (e.target.closest("input, textarea, select, button")) return;
    if (e.key === " ") { e.preventDefault(); player.toggle(); }
    else if (e.key === "ArrowRight") { player.pause(); player.setFrame(player.frame + 1); }
    else if (e.key === "ArrowLeft") { player.pause(); player.setFrame(player.frame - 1); }
  });
}

async function start() {
  bindControls();
  setStatus("loading", "Connecting…");
  let info;
  try {
    info = await api.info();
  } catch (err) {
    showError(err.message);
    return;
  }
  state.model = info.model;
  configure(info);
  if (info.files.length) {
    $("file-list").value = "0";
    await openWith(info.files[0].name, () => api.openListed(0));
  } else if (info.model.found && !info.model.error) {
    await generate();
  } else {
    setStatus("idle", "No model to generate with: open a motion file.");
  }
}

start();
