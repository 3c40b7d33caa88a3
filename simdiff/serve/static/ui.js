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
  params: null,        // parameters of the motion on screen (generated ones)
  source: null,        // "generate" | "file" | "upload"
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
  setStatus("error", "");
}

function digest(joints) {
  let sum = 0;
  joints.forEach((pose, t) => pose.forEach(([x, y, z], j) => { sum += (t + 1) * (x + 2 * y + 3 * z) + j * 1e-3; }));
  return Math.round(sum * 1e4) / 1e4;
}

function show(motion) {
  player.load(motion);
  showBody(motion);
  const meta = motion.meta;
  Object.assign(state, { frames: motion.joints.length, source: meta.source, digest: digest(motion.joints), meta, error: null });
  $("error").hidden = true;
  let caption;
  if (meta.source === "generate") {
    const p = meta.params;
    state.params = p;
    state.generation_id += 1;
    caption = `“${p.text}”` + (meta.env_used ? ` · g ${p.gravity.toFixed(2)} m/s² · wind (${p.wind_x.toFixed(1)}, ${p.wind_y.toFixed(1)}) N · α ${meta.sampling.alpha}` + (meta.sampling.env_guidance !== 1 ? ` · environment guidance ${meta.sampling.env_guidance}` : "") : "");
    if (meta.simulated) caption += ` · simulated finish (${meta.simulated.status}, joint error ${Math.round(meta.simulated.err_mm)} mm)`;
    const waited = meta.queue_position ? ` after waiting ${meta.waited_s.toFixed(1)} s behind ${meta.queue_position} request(s)` : "";
    setStatus("ready", `Generated ${meta.frames} frames in ${meta.elapsed_s.toFixed(2)} s${waited}.`);
  } else {
    state.params = null;
    caption = meta.name;
    setStatus("ready", `Opened ${meta.name}: ${meta.frames} frames (${meta.seconds.toFixed(2)} s).`);
  }
  $("caption").textContent = caption;
}

// -- generation: one request at a time, the latest parameters win ------------------------------

let busy = false;
let pending = null;
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
  };
}

async function generate() {
  pending = readParams();
  if (busy) return;
  busy = true;
  try {
    while (pending) {
      const params = pending;
      pending = null;
      setStatus("generating", state.model && !state.model.loaded ? "Loading the model and generating…" : "Generating…");
      try {
        show(await api.generate(params));
        if (state.model) state.model.loaded = true;
      } catch (err) {
        showError(err.message);
      }
    }
  } finally {
    busy = false;
  }
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
    input.addEventListener("change", generate);
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
  for (const b of $("gravity-presets").querySelectorAll("button")) {
    b.disabled = !m.env;
    b.addEventListener("click", () => {
      $("gravity").value = b.dataset.gravity;
      $("gravity").dispatchEvent(new Event("input"));
      generate();
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
