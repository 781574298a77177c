// The kit's page (index.html): kit-web's first frame from the URL's options, then the
// controls (lab, shaders, scene, view, size, kit-view's settings), orbiting the camera, the
// lab editor (editor.js) whose edits recompile as the student types, their copy in this
// browser (labs.js), "Download my labs", "Open folder", "Check my lab" (check.js), and the
// GPU resets a shader that never ends causes. kit-web answers every command through
// kit_call(JSON) -> JSON (tools/web/kit_web.cpp); the page draws only when something changed.
import {byPath, parseDiagnostics} from "./diagnostics.js";
import {LabEditor} from "./editor.js";
import {LabFiles} from "./labs.js";
import {showCheck} from "./check.js";

const $ = (id) => document.getElementById(id);
const pageStart = performance.now();
const query = new URLSearchParams(window.location.search);
const canvas = $("canvas");
const statusLine = $("status");

// What the page shows; the controls mirror it and every configure sends all of it.
const ui = {
  catalogue: null,
  stage: null,             // the catalogue's stage
  solution: false,         // the reference solution instead of the student's files
  scene: "default",        // a kit scene's name, or a dropped model's path in the file system
  view: "final",
  width: 640, height: 480,
  settings: {gamma: 2.2, attenuation_model: 0, postprocess: true, custom_effect: false, bloom_threshold: 1.0,
             extra_lights: 0},
};
const SIZES = ["320x240", "640x480", "800x600", "1024x768", "1280x720"];
const VIEW_LABELS = {
  final: "final image", position: "G-buffer: position", normal: "G-buffer: normal", albedo: "G-buffer: albedo",
  material: "G-buffer: material", emission: "G-buffer: emission", depth: "depth", hdr: "HDR (before tone mapping)",
  irradiance: "lab 6: irradiance map", prefiltered: "lab 6: prefiltered environment", "brdf-lut": "lab 6: BRDF table",
};
const COMPILE_DELAY_MS = 300;
// A context lost this soon after an edit's frame is taken as that edit's doing.
const LOST_AFTER_EDIT_MS = 10000;

let FS = null;
let labs = null;
let editor = null;
let fellBackToLabs = false;  // the URL asked for the solution, and the site has none of that lab
const pending = new Set();   // paths edited since the last compile
let compileTimer = 0;
let drawRequested = false;
let lost = false, lostAfterEdit = false, editWhileLost = false, waitingForEdit = false;
let lastDraw = {kind: "", at: 0};
let compileErrors = new Map();  // path -> diagnostics of the last failed compile
let folder = null;              // the student's folder (Open folder): {name, labsDir, files: path -> entry}
let droppedCount = 0;
const droppedScenes = [];       // [{path, label}]
const pointers = new Map();
let pinchDistance = 0;
const cameraPending = {rotate: [0, 0], pan: [0, 0], zoom: 0};
let cameraScheduled = false;

// For the page's test (tests/web_page_test.py) and the curious: counters and state.
const kitPage = window.kitPage = {ready: false, frames: 0, errors: 0, lastError: "", lastDownload: null,
                                  messages: [], lastCheck: null};

// ---- kit-web ----

function kitCall(command) {
  try {
    return JSON.parse(window.Module.ccall("kit_call", "string", ["string"], [JSON.stringify(command)]));
  } catch (e) {
    return {error: "kit-web stopped: " + (e && e.message ? e.message : e)};
  }
}

function fsExists(path) {
  try {
    return FS.analyzePath(path).exists;
  } catch (e) {
    return false;
  }
}

function findStage(nameOrNumber) {
  const stages = ui.catalogue ? ui.catalogue.stages : [];
  return stages.find((s) => s.name === nameOrNumber || String(s.number) === nameOrNumber || s.folder === nameOrNumber);
}
const hasLabs = (stage) => fsExists(`/kit/labs/${stage.folder}`);
// The first earlier lab this site has no solution of: stage N is built on labs 1..N-1's solutions.
function missingEarlier(stage) {
  for (const s of ui.catalogue.stages) {
    if (s.number >= stage.number) break;
    if (!s.solution) return s;
  }
  return null;
}

// ---- messages ----

// actions: [{label, run}], buttons under the message.
function say(text, kind = "", detail = "", actions = []) {
  const box = $("messages");
  box.className = kind;
  box.replaceChildren();
  const p = document.createElement("p");
  p.textContent = text;
  box.append(p);
  if (detail) {
    const pre = document.createElement("pre");
    pre.textContent = detail;
    box.append(pre);
  }
  if (actions.length) {
    const row = document.createElement("p");
    for (const action of actions) {
      const button = document.createElement("button");
      button.type = "button";
      button.textContent = action.label;
      button.addEventListener("click", action.run);
      row.append(button, " ");
    }
    box.append(row);
  }
  if (text) kitPage.messages.push(text + (detail ? "\n" + detail : ""));
  if (kitPage.messages.length > 50) kitPage.messages.shift();
}

function frameInfo(answer, what) {
  const ms = (s) => (1000 * s).toFixed(1) + " ms";
  const who = ui.solution ? "reference solution" : "your files";
  const scene = ui.scene.startsWith("/") ? ui.scene.split("/").pop() : ui.scene;
  $("frame-info").textContent = `Lab ${ui.stage.number} (${ui.stage.name}), ${who}, scene ${scene}, ` +
    `${VIEW_LABELS[ui.view] || ui.view}, ${canvas.width}x${canvas.height}: ${what} drawn in ${ms(answer.seconds || 0)}.`;
}

// The canvas at one canvas pixel per CSS pixel; lab 6's maps, which have small sizes of
// their own, magnified by a whole factor.
const MAP_VIEWS = ["irradiance", "prefiltered", "brdf-lut"];
function fitCanvas() {
  const zoom = MAP_VIEWS.includes(ui.view) ? Math.max(1, Math.floor(256 / Math.max(canvas.width, canvas.height))) : 1;
  canvas.style.width = zoom * canvas.width + "px";
  canvas.style.height = zoom * canvas.height + "px";
}

// ---- compile errors in the editor ----

function showCompileError(error) {
  const diagnostics = parseDiagnostics(error);
  const grouped = byPath(diagnostics);
  for (const path of compileErrors.keys())
    if (!grouped.has(path) && editor.has(path)) editor.setDiagnostics(path, []);
  compileErrors = grouped;
  for (const [path, list] of grouped) if (editor.has(path)) editor.setDiagnostics(path, list);
  markTabs();
  const where = [...grouped.keys()].map((p) => p.replace(/^\/kit\//, "")).join(", ");
  const actions = diagnostics.filter((d) => currentFiles.some((f) => f.path === d.path)).slice(0, 4).map((d) => ({
    label: `Go to ${d.path.split("/").pop()} line ${d.line}`,
    run: () => {
      showFile(d.path);
      editor.goto(d.line);
    },
  }));
  say(`Does not compile${where ? " (" + where + ")" : ""}: the frame shows your last good version.`, "error", error,
      actions);
}

function clearCompileErrors() {
  for (const path of compileErrors.keys()) if (editor.has(path)) editor.setDiagnostics(path, []);
  compileErrors = new Map();
  markTabs();
}

// ---- drawing ----

// An answer to a command that draws: the frame it drew, or the problem (the canvas keeps
// the last good frame). kind: "edit" (a compile of the student's files), "build" (a
// configure that built the renderer anew from the files), "settings" (one that kept the
// renderer: a compile error of the files stands) or "move".
function drawn(answer, kind, label) {
  if (answer.error) {
    kitPage.errors += 1;
    kitPage.lastError = answer.error;
    if (lost || /WebGL context is lost/.test(answer.error)) say("Waiting for the browser to restore the GPU context.", "error");
    else if (parseDiagnostics(answer.error).length) showCompileError(answer.error);
    else say(answer.error, "error");
    return false;
  }
  fitCanvas();
  kitPage.frames += 1;
  lastDraw = {kind, at: performance.now()};
  if (kind === "edit" || kind === "build") {
    clearCompileErrors();
    if (kind === "edit") say(`Compiled and drawn (${(1000 * (answer.seconds || 0)).toFixed(0)} ms).`, "ok");
    else if ($("messages").classList.contains("error")) say("");
  } else if (!compileErrors.size && $("messages").classList.contains("error")) {
    say("");
  }
  if (answer.warnings && answer.warnings.length) say("Warnings:", "", answer.warnings.join("\n"));
  frameInfo(answer, label);
  return true;
}

function configureCommand() {
  return {cmd: "configure", stage: ui.stage.name, solution: ui.solution, scene: ui.scene, view: ui.view,
          width: ui.width, height: ui.height, ...ui.settings};
}

function canDraw() {
  if (lost) {
    say("The GPU context is lost; the page draws again once the browser restores it.", "error");
    return false;
  }
  if (waitingForEdit) {
    say("Not drawing: the GPU reset right after your last edit. Edit a file to try again, or press Redraw.", "error");
    return false;
  }
  return true;
}

// kit-web builds its renderer anew, from the files, when the stage, the shaders or the
// scene change (and after a lost context); other settings keep it.
let builtKey = "";
const buildKey = () => `${ui.stage.name}/${ui.solution}/${ui.scene}`;

// Draws with the controls' state now; kind as drawn() takes it, "build" or "settings" by
// what changed since the last frame kit-web built.
function configure(label, rebuilt = false) {
  const key = buildKey();
  const answer = kitCall(configureCommand());
  const ok = drawn(answer, rebuilt || key !== builtKey ? "build" : "settings", label);
  if (ok) builtKey = key;
  return ok;
}

// Draws with the controls' state at the next animation frame (changes in between coalesce).
function requestDraw() {
  updateURL();
  if (drawRequested) return;
  drawRequested = true;
  requestAnimationFrame(() => {
    drawRequested = false;
    if (!canDraw()) return;
    configure("frame");
  });
}

function flushCamera() {
  cameraScheduled = false;
  if (!canDraw()) return;
  const [rx, ry] = cameraPending.rotate, [px, py] = cameraPending.pan, zoom = cameraPending.zoom;
  cameraPending.rotate = [0, 0];
  cameraPending.pan = [0, 0];
  cameraPending.zoom = 0;
  let answer = null;
  if (rx || ry) answer = kitCall({cmd: "camera", action: "rotate", dx: rx, dy: ry});
  if (px || py) answer = kitCall({cmd: "camera", action: "pan", dx: px, dy: py});
  if (zoom) answer = kitCall({cmd: "camera", action: "zoom", steps: zoom});
  if (answer) drawn(answer, "move", "camera moved,");
}

function moveCamera(action, a, b = 0) {
  if (action === "zoom") cameraPending.zoom += a;
  else {
    cameraPending[action][0] += a;
    cameraPending[action][1] += b;
  }
  if (!cameraScheduled) {
    cameraScheduled = true;
    requestAnimationFrame(flushCamera);
  }
}

// ---- the URL ----

function updateURL() {
  const params = new URLSearchParams(window.location.search);
  params.set("stage", ui.stage.name);
  if (!ui.scene.startsWith("/")) params.set("scene", ui.scene);  // a dropped model is not on the next visit
  params.set("view", ui.view);
  params.set("size", `${ui.width}x${ui.height}`);
  if (ui.solution) params.delete("shaders");
  else params.set("shaders", "labs");
  const url = `${window.location.pathname}?${params.toString().replace(/%2F/g, "/")}${window.location.hash}`;
  window.history.replaceState(null, "", url);
}

// ---- controls ----

function option(value, text, disabled = false) {
  const o = document.createElement("option");
  o.value = value;
  o.textContent = text;
  o.disabled = disabled;
  return o;
}

function fillStages() {
  const select = $("stage");
  select.replaceChildren();
  for (const s of ui.catalogue.stages) {
    const missing = missingEarlier(s);
    const label = `${s.number} ${s.name}` + (missing ? ` (needs lab ${missing.number}'s solution)` : "");
    select.append(option(s.name, label, Boolean(missing)));
  }
  select.value = ui.stage.name;
}

function fillViews() {
  const select = $("view");
  select.replaceChildren();
  // As kit-view offers them: HDR from the first lit stage, lab 6's maps in lab 6.
  const allowed = (v) => (v !== "hdr" || ui.stage.number >= 2) &&
                         (!MAP_VIEWS.includes(v) || ui.stage.name === "ibl");
  for (const v of ui.catalogue.views) if (allowed(v)) select.append(option(v, VIEW_LABELS[v] || v));
  if (![...select.options].some((o) => o.value === ui.view)) ui.view = "final";
  select.value = ui.view;
}

function fillScenes() {
  const select = $("scene");
  select.replaceChildren();
  const kit = document.createElement("optgroup");
  kit.label = "The kit's scenes";
  for (const name of ui.catalogue.scenes) kit.append(option(name, name));
  select.append(kit);
  if (droppedScenes.length) {
    const own = document.createElement("optgroup");
    own.label = "Your models";
    for (const d of droppedScenes) own.append(option(d.path, d.label));
    select.append(own);
  }
  if (![...select.querySelectorAll("option")].some((o) => o.value === ui.scene)) {
    select.append(option(ui.scene, ui.scene));
  }
  select.value = ui.scene;
}

function fillSizes() {
  const select = $("size");
  select.replaceChildren();
  const sizes = [...SIZES];
  const current = `${ui.width}x${ui.height}`;
  if (!sizes.includes(current)) sizes.unshift(current);
  for (const s of sizes) select.append(option(s, s.replace("x", " x ")));
  select.value = current;
}

function syncShaders() {
  const labsThere = hasLabs(ui.stage);
  $("shaders-labs").disabled = !labsThere;
  $("shaders-solution").disabled = !ui.stage.solution;
  $("shaders-labs").checked = !ui.solution;
  $("shaders-solution").checked = ui.solution;
}

function syncSettings() {
  let shown = 0;
  for (const row of document.querySelectorAll("[data-from-lab]")) {
    row.hidden = ui.stage.number < Number(row.dataset.fromLab);
    if (!row.hidden) shown += 1;
  }
  $("settings-none").hidden = shown > 0;
  $("bloom-threshold").disabled = !ui.settings.postprocess;
}

function syncControls() {
  fillStages();
  syncShaders();
  fillScenes();
  fillViews();
  fillSizes();
  syncSettings();
  const s = ui.settings;
  $("postprocess").checked = s.postprocess;
  $("custom-effect").checked = s.custom_effect;
  $("gamma").value = s.gamma;
  $("gamma-value").textContent = Number(s.gamma).toFixed(2);
  $("bloom-threshold").value = s.bloom_threshold;
  $("bloom-threshold-value").textContent = Number(s.bloom_threshold).toFixed(2);
  $("extra-lights").value = s.extra_lights;
  $("extra-lights-value").textContent = String(s.extra_lights);
  for (const radio of document.querySelectorAll('input[name="attenuation"]'))
    radio.checked = Number(radio.value) === s.attenuation_model;
  $("check").disabled = !hasLabs(ui.stage) || Boolean(missingEarlier(ui.stage));
}

function wireControls() {
  for (const id of ["stage", "scene", "view", "size", "postprocess", "custom-effect", "gamma", "bloom-threshold",
                    "extra-lights", "model-file", "shaders-labs", "shaders-solution"])
    $(id).disabled = false;
  for (const radio of document.querySelectorAll('input[name="attenuation"]')) radio.disabled = false;

  $("stage").addEventListener("change", () => {
    ui.stage = findStage($("stage").value);
    // A student's default is their own files; a lab that is over shows its solution.
    ui.solution = !hasLabs(ui.stage) && ui.stage.solution;
    syncControls();
    openStageFiles();
    requestDraw();
  });
  for (const id of ["shaders-labs", "shaders-solution"]) {
    $(id).addEventListener("change", () => {
      ui.solution = $("shaders-solution").checked;
      openStageFiles();
      requestDraw();
    });
  }
  $("scene").addEventListener("change", () => {
    ui.scene = $("scene").value;
    requestDraw();
  });
  $("view").addEventListener("change", () => {
    ui.view = $("view").value;
    requestDraw();
  });
  $("size").addEventListener("change", () => {
    [ui.width, ui.height] = $("size").value.split("x").map(Number);
    requestDraw();
  });
  $("postprocess").addEventListener("change", () => {
    ui.settings.postprocess = $("postprocess").checked;
    syncSettings();
    requestDraw();
  });
  $("custom-effect").addEventListener("change", () => {
    ui.settings.custom_effect = $("custom-effect").checked;
    requestDraw();
  });
  const slider = (id, key, digits) => {
    $(id).addEventListener("input", () => {
      ui.settings[key] = Number($(id).value);
      $(id + "-value").textContent = ui.settings[key].toFixed(digits);
      requestDraw();
    });
  };
  slider("gamma", "gamma", 2);
  slider("bloom-threshold", "bloom_threshold", 2);
  slider("extra-lights", "extra_lights", 0);
  for (const radio of document.querySelectorAll('input[name="attenuation"]')) {
    radio.addEventListener("change", () => {
      ui.settings.attenuation_model = Number(radio.value);
      requestDraw();
    });
  }
  $("model-file").addEventListener("change", () => {
    const files = [...$("model-file").files];
    $("model-file").value = "";
    loadModel(files);
  });
}

// ---- the camera: mouse, touch, keyboard ----

function wireCamera() {
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("pointerdown", (e) => {
    canvas.setPointerCapture(e.pointerId);
    pointers.set(e.pointerId, {x: e.clientX, y: e.clientY, button: e.button});
    if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      pinchDistance = Math.hypot(a.x - b.x, a.y - b.y);
    }
    canvas.focus();
    e.preventDefault();
  });
  canvas.addEventListener("pointermove", (e) => {
    const p = pointers.get(e.pointerId);
    if (!p) return;
    const dx = e.clientX - p.x, dy = e.clientY - p.y;
    p.x = e.clientX;
    p.y = e.clientY;
    if (pointers.size === 1) {
      moveCamera(p.button === 2 || p.button === 1 || e.shiftKey ? "pan" : "rotate", dx, dy);
    } else if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      const distance = Math.hypot(a.x - b.x, a.y - b.y);
      moveCamera("zoom", (distance - pinchDistance) / 40);  // 40 px of pinch: one wheel step
      pinchDistance = distance;
    }
  });
  const up = (e) => {
    pointers.delete(e.pointerId);
  };
  canvas.addEventListener("pointerup", up);
  canvas.addEventListener("pointercancel", up);
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const perStep = e.deltaMode === 1 ? 3 : e.deltaMode === 2 ? 1 : 100;
    moveCamera("zoom", -e.deltaY / perStep);
  }, {passive: false});
  canvas.addEventListener("keydown", (e) => {
    const step = 20;
    const keys = {ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step]};
    if (keys[e.key]) moveCamera(e.shiftKey ? "pan" : "rotate", ...keys[e.key]);
    else if (e.key === "+" || e.key === "=" || e.key === "PageUp") moveCamera("zoom", 1);
    else if (e.key === "-" || e.key === "PageDown") moveCamera("zoom", -1);
    else return;
    e.preventDefault();
  });
}

// ---- the editor and its tabs ----

// The files the editor shows for the stage: the student's (labs/NN-name/), or, where the
// site has no labs/ folder of that lab (a lab that is over), its solution, read only.
function stageFiles() {
  const stage = ui.stage;
  if (hasLabs(stage))
    return stage.files.map((f) => ({path: `/kit/labs/${stage.folder}/${f.name}`, name: f.name, readOnly: false}));
  if (stage.solution)
    return stage.files.map((f) => ({path: `/kit/solutions/${stage.folder}/${f.name}`, name: f.name, readOnly: true}));
  return [];
}

function fileText(file) {
  if (labs.has(file.path)) return labs.text(file.path);
  try {
    return FS.readFile(file.path, {encoding: "utf8"});
  } catch (e) {
    return `// ${file.path}: ${e.message || e}`;
  }
}

const SOLUTION_NOTE = "The frame shows the reference solution; your edits are kept and drawn when you choose " +
                      "\"my lab files\".";
let currentFiles = [];
let currentPath = null;

function openStageFiles() {
  currentFiles = stageFiles();
  const stage = ui.stage;
  const heading = $("editor-heading");
  if (!currentFiles.length) heading.textContent = `Lab ${stage.number}: no files in this site`;
  else if (currentFiles[0].readOnly) heading.textContent = `Lab ${stage.number}'s reference solution (read only)`;
  else heading.textContent = `Your files of lab ${stage.number}: labs/${stage.folder}/`;
  if (!currentFiles.some((f) => f.path === currentPath)) currentPath = currentFiles.length ? currentFiles[0].path : null;
  renderTabs();
  if (currentPath) showFile(currentPath);
  $("reset-file").disabled = !currentPath || currentFiles[0].readOnly;
  if (ui.solution && currentFiles.length && !currentFiles[0].readOnly) {
    say(SOLUTION_NOTE);
  } else if (kitPage.messages.at(-1) === SOLUTION_NOTE) {
    say("");
  }
}

function renderTabs() {
  const tabs = $("tabs");
  tabs.replaceChildren();
  for (const file of currentFiles) {
    const tab = document.createElement("button");
    tab.type = "button";
    tab.setAttribute("role", "tab");
    tab.id = "tab-" + file.name.replace(/\W/g, "-");
    tab.dataset.path = file.path;
    tab.setAttribute("aria-controls", "editor");
    tab.addEventListener("click", () => showFile(file.path));
    tab.addEventListener("keydown", (e) => {
      const i = currentFiles.indexOf(file);
      const to = {ArrowRight: i + 1, ArrowLeft: i - 1, Home: 0, End: currentFiles.length - 1}[e.key];
      if (to === undefined) return;
      e.preventDefault();
      const next = currentFiles[(to + currentFiles.length) % currentFiles.length];
      showFile(next.path);
      document.querySelector(`[role="tab"][data-path="${next.path}"]`).focus();
    });
    tabs.append(tab);
  }
  markTabs();
}

function markTabs() {
  for (const tab of document.querySelectorAll('#tabs [role="tab"]')) {
    const path = tab.dataset.path;
    const name = path.split("/").pop();
    const selected = path === currentPath;
    const edited = labs.edited(path), broken = compileErrors.has(path);
    tab.setAttribute("aria-selected", String(selected));
    tab.tabIndex = selected ? 0 : -1;
    tab.replaceChildren(name);
    if (edited) tab.append(" \u2022");
    if (broken) {
      const mark = document.createElement("span");
      mark.className = "mark-error";
      mark.textContent = " \u26a0";
      tab.append(mark);
    }
    tab.setAttribute("aria-label", name + (edited ? ", edited" : "") + (broken ? ", does not compile" : ""));
  }
}

function showFile(path) {
  const file = currentFiles.find((f) => f.path === path);
  if (!file) return;
  currentPath = path;
  const label = path.replace(/^\/kit\//, "");
  editor.show(path, fileText(file), file.readOnly, label);
  if (compileErrors.has(path)) editor.setDiagnostics(path, compileErrors.get(path));
  $("editor").setAttribute("aria-labelledby", $("tabs").querySelector(`[data-path="${path}"]`)?.id || "editor-heading");
  markTabs();
}

// ---- edits: kept, written into the file system, compiled ----

function onEdit(path, text) {
  if (!labs.has(path)) return;
  if (!labs.set(path, text))
    say(`This browser refused to keep your text (${labs.storageProblem}): use Download my labs before you leave.`,
        "error");
  pending.add(path);
  markTabs();
  clearTimeout(compileTimer);
  compileTimer = setTimeout(compileEdits, COMPILE_DELAY_MS);
}

// Writes the edited files into kit-web's file system (and the student's folder), then
// compiles and draws the stage when it draws one of them.
function compileEdits() {
  clearTimeout(compileTimer);
  if (!pending.size) return;
  const paths = [...pending];
  pending.clear();
  for (const path of paths) {
    labs.writeFS(path);
    saveToFolder(path);
  }
  const drawsThem = !ui.solution && paths.some((p) => p.startsWith(`/kit/labs/${ui.stage.folder}/`));
  if (!drawsThem) {
    if (ui.solution) say("Saved. The frame shows the reference solution: choose \"my lab files\" to draw your edit.");
    return;
  }
  if (lost) {
    editWhileLost = true;
    say("Saved. The GPU context is lost: your edit is drawn once the browser restores it.", "error");
    return;
  }
  waitingForEdit = false;
  const answer = kitCall({cmd: "reload"});
  drawn(answer, "edit", "your edit");
}

function resetFile() {
  if (!currentPath || !labs.has(currentPath)) return;
  const starter = labs.starter(currentPath);
  if (labs.text(currentPath) === starter) {
    say("This file is the starter already.");
    return;
  }
  editor.setText(currentPath, starter);
  onEdit(currentPath, starter);
  say(`${currentPath.replace(/^\/kit\//, "")}: back to the starter. Ctrl+Z in the editor brings your text back.`);
}

// ---- Download my labs ----

function download() {
  compileEdits();
  const bytes = labs.zip();
  kitPage.lastDownload = {name: "labs.zip", bytes};
  const url = URL.createObjectURL(new Blob([bytes], {type: "application/zip"}));
  const a = document.createElement("a");
  a.href = url;
  a.download = "labs.zip";
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 60000);
  say(`labs.zip: ${labs.paths().length} files as labs/NN-name/FILE, the layout ./kit grade and the course ` +
      "platform take.");
}

// ---- Open folder (File System Access API) ----

async function openFolder() {
  let dir;
  try {
    dir = await window.showDirectoryPicker({id: "kit-labs", mode: "readwrite"});
  } catch (e) {
    if (e.name !== "AbortError") say("Could not open the folder: " + (e.message || e), "error");
    return;
  }
  compileEdits();  // what was typed before goes where it went so far, not into this folder
  let labsDir = null;
  try {
    labsDir = await dir.getDirectoryHandle("labs");
  } catch (e) {
    for await (const [name, handle] of dir.entries())
      if (handle.kind === "directory" && /^\d\d-/.test(name)) labsDir = dir;
  }
  if (!labsDir) {
    say(`${dir.name} has no labs/ folder: choose your kit's folder, or its labs/ folder.`, "error");
    return;
  }
  const files = new Map();
  for (const folderName of labs.folders()) {
    let sub;
    try {
      sub = await labsDir.getDirectoryHandle(folderName);
    } catch (e) {
      continue;
    }
    for (const name of labs.filesOf(folderName)) {
      try {
        const handle = await sub.getFileHandle(name);
        const file = await handle.getFile();
        files.set(`/kit/labs/${folderName}/${name}`, {handle, text: await file.text(), lastModified: file.lastModified,
                                                      writing: Promise.resolve()});
      } catch (e) {
        // not in the folder: the page keeps its own text
      }
    }
  }
  if (!files.size) {
    say(`${dir.name}: none of this site's lab files (labs/NN-name/FILE) are in it.`, "error");
    return;
  }
  const conflicts = [...files].filter(([path, entry]) => labs.edited(path) && labs.text(path) !== entry.text);
  let takeFolder = true;
  if (conflicts.length) {
    const names = conflicts.map(([path]) => path.replace(/^\/kit\//, "")).join("\n");
    takeFolder = window.confirm(`These files differ between this page and ${dir.name}:\n${names}\n\n` +
                                "OK: use the folder's files (this page's versions are replaced).\n" +
                                "Cancel: keep this page's versions and save them into the folder.");
  }
  folder = {name: dir.name, labsDir, files};
  const taken = [];
  for (const [path, entry] of files) {
    if (entry.text === labs.text(path)) continue;
    if (takeFolder || !conflicts.some(([p]) => p === path)) {
      takeText(path, entry.text);
      taken.push(path);
    } else {
      saveToFolder(path);
    }
  }
  $("folder-info").hidden = false;
  $("folder-info").textContent = `Folder ${dir.name}: ${files.size} lab files; your edits are saved into it, and ` +
                                 "changes made there (in your editor) show here.";
  say(`Opened ${dir.name}.`, "ok");
  drawTaken(taken);
  if (!folderTimer) folderTimer = setInterval(pollFolder, 1500);
}

// A text from the student's folder: into the editor, this browser's copy and the file system.
function takeText(path, text) {
  editor.setText(path, text);
  labs.set(path, text);
  labs.writeFS(path);
  markTabs();
}

// Compiles and draws the texts taken from the folder when the stage draws one of them.
function drawTaken(paths) {
  if (ui.solution || lost || !paths.some((p) => p.startsWith(`/kit/labs/${ui.stage.folder}/`))) return;
  waitingForEdit = false;
  drawn(kitCall({cmd: "reload"}), "edit", "your folder's files");
}

function saveToFolder(path) {
  if (!folder) return;
  const entry = folder.files.get(path);
  if (!entry) return;
  const text = labs.text(path);
  entry.writing = entry.writing.then(async () => {
    const stream = await entry.handle.createWritable();
    await stream.write(text);
    await stream.close();
    const file = await entry.handle.getFile();
    entry.lastModified = file.lastModified;
    entry.text = text;
  }).catch((e) => say(`Could not save ${path.replace(/^\/kit\//, "")} into ${folder.name} (${e.message || e}); ` +
                      "your text is kept in this browser.", "error"));
}

let polling = false;
let folderTimer = 0;
async function pollFolder() {
  if (!folder || polling || document.visibilityState !== "visible") return;
  polling = true;
  try {
    const changed = [];
    for (const [path, entry] of folder.files) {
      await entry.writing;
      let file;
      try {
        file = await entry.handle.getFile();
      } catch (e) {
        continue;  // being written by another program, or gone: the next look tells
      }
      if (file.lastModified === entry.lastModified) continue;
      entry.lastModified = file.lastModified;
      const text = await file.text();
      entry.text = text;
      if (text !== labs.text(path) && !pending.has(path)) {
        takeText(path, text);
        changed.push(path);
      }
    }
    if (changed.length) {
      say(`Changed in ${folder.name}: ${changed.map((p) => p.replace(/^\/kit\//, "")).join(", ")}.`);
      drawTaken(changed);
    }
  } catch (e) {
    say(`Could not read ${folder.name}: ${e.message || e}`, "error");
  } finally {
    polling = false;
  }
}

// ---- Check my lab ----

function runCheck() {
  compileEdits();
  if (!canDraw()) return;
  const lab = ui.stage.number;
  const section = $("check-results");
  section.hidden = false;
  $("check-body").replaceChildren(Object.assign(document.createElement("p"), {
    textContent: `Checking lab ${lab}: rendering the grader's checks with your files\u2026`}));
  $("check").disabled = true;
  // Let the message show before kit-web takes the main thread.
  setTimeout(() => {
    const answer = kitCall({cmd: "check", lab});
    kitPage.lastCheck = answer;
    $("check").disabled = false;
    if (answer.error) {
      $("check-body").replaceChildren(Object.assign(document.createElement("p"), {
        className: "error", textContent: `The check could not run: ${answer.error}`}));
      if (parseDiagnostics(answer.error).length) showCompileError(answer.error);
    } else {
      showCheck($("check-body"), FS, lab, answer);
      if (answer.status === "compile_error" && answer.message) showCompileError(answer.message);
      fitCanvas();
    }
    section.focus();
  }, 30);
}

// ---- a student's model: dropped or picked ----

async function loadModel(files) {
  if (!files.length) return;
  const names = files.map((f) => f.name);
  if (names.some((n) => /\.obj$/i.test(n)) && !names.some((n) => /\.(glb|gltf)$/i.test(n))) {
    say("OBJ scenes are refused in the browser build (it has no OBJ reader): export the model as glTF (.glb) " +
        "(Blender: File > Export > glTF 2.0), or draw it with ./kit render or ./kit view.", "error");
    return;
  }
  const main = files.find((f) => /\.glb$/i.test(f.name)) || files.find((f) => /\.gltf$/i.test(f.name));
  if (!main) {
    say(`Not a model: ${names.join(", ")}. Drop a .glb, or a .gltf together with its .bin and images.`, "error");
    return;
  }
  droppedCount += 1;
  const dir = `/work/dropped/${droppedCount}`;
  FS.mkdirTree(dir);
  for (const file of files) FS.writeFile(`${dir}/${file.name}`, new Uint8Array(await file.arrayBuffer()));
  if (/\.gltf$/i.test(main.name)) {
    try {
      const gltf = JSON.parse(await main.text());
      const uris = [...(gltf.buffers || []), ...(gltf.images || [])].map((x) => x.uri)
        .filter((u) => u && !u.startsWith("data:")).map((u) => decodeURIComponent(u));
      const missing = uris.filter((u) => !fsExists(`${dir}/${u}`));
      if (missing.length) {
        say(`${main.name} needs ${missing.join(", ")}: drop or pick them together with it.`, "error");
        return;
      }
    } catch (e) {
      say(`${main.name} is not glTF's JSON: ${e.message || e}`, "error");
      return;
    }
  }
  const previous = ui.scene;
  ui.scene = `${dir}/${main.name}`;
  if (!canDraw()) {
    ui.scene = previous;
    return;
  }
  if (configure(main.name)) {
    droppedScenes.push({path: ui.scene, label: main.name});
    fillScenes();
    say(`Drawing your model ${main.name}.`, "ok");
  } else {
    // kit-web keeps the scene it was given: back to the one before, the message kept.
    ui.scene = previous;
    fillScenes();
    const why = kitPage.lastError;
    if (!kitCall(configureCommand()).error) fitCanvas();
    say(`${main.name} could not be drawn: ${why}`, "error");
  }
}

function wireDrop() {
  const overlay = $("drop-overlay");
  let depth = 0;
  const hasFiles = (e) => e.dataTransfer && [...e.dataTransfer.types].includes("Files");
  window.addEventListener("dragenter", (e) => {
    if (!hasFiles(e)) return;
    depth += 1;
    overlay.hidden = false;
  });
  window.addEventListener("dragleave", () => {
    depth = Math.max(0, depth - 1);
    if (!depth) overlay.hidden = true;
  });
  window.addEventListener("dragover", (e) => {
    if (hasFiles(e)) e.preventDefault();
  });
  window.addEventListener("drop", (e) => {
    depth = 0;
    overlay.hidden = true;
    if (!e.dataTransfer || !e.dataTransfer.files.length) return;
    e.preventDefault();
    loadModel([...e.dataTransfer.files]);
  });
}

// ---- a lost GPU context ----

function wireContextLoss() {
  canvas.addEventListener("webglcontextlost", (e) => {
    e.preventDefault();  // the browser restores it then
    lost = true;
    lostAfterEdit = lastDraw.kind === "edit" && performance.now() - lastDraw.at < LOST_AFTER_EDIT_MS;
    editWhileLost = false;
    kitCall({cmd: "lost"});
    say("The GPU reset while drawing: a shader took too long (a loop that never ends?). Your files are kept; " +
        "the page draws again once the browser restores the GPU context.", "error");
    kitPage.lostAt = performance.now();
  });
  canvas.addEventListener("webglcontextrestored", () => {
    lost = false;
    const restored = kitCall({cmd: "restored"});
    if (restored.error) {
      say("The GPU context came back, but kit-web could not use it: " + restored.error, "error");
      return;
    }
    if (lostAfterEdit && !editWhileLost) {
      waitingForEdit = true;
      say("The GPU reset while drawing: a shader took too long (a loop that never ends?). The GPU context is back, " +
          "but the page does not draw your last edit again by itself: edit a file to try again (or press Redraw).",
          "error");
      return;
    }
    waitingForEdit = false;
    if (configure("frame after the GPU reset", true)) {
      if (editWhileLost) lastDraw.kind = "edit";  // a loss now is that edit's doing
      else say("The GPU context is back: drawn again.", "ok");
    }
  });
}

// ---- start ----

function initialState(report) {
  const fromUrl = query.get("stage");
  ui.stage = findStage(report.stage || fromUrl || "gbuffer") || ui.catalogue.stages[0];
  if (report.solution !== undefined) ui.solution = report.solution;
  else if (hasLabs(ui.stage)) ui.solution = query.get("shaders") !== "labs" && ui.stage.solution;
  else ui.solution = ui.stage.solution;
  ui.scene = report.scene || query.get("scene") || "default";
  ui.view = report.view || query.get("view") || "final";
  const size = /^(\d+)x(\d+)$/.exec(report.size || query.get("size") || "");
  if (size) [ui.width, ui.height] = [Number(size[1]), Number(size[2])];
}

function start(state, report) {
  if (!ui.catalogue || ui.catalogue.error) ui.catalogue = kitCall({cmd: "catalogue"});
  if (ui.catalogue.error) {
    say("kit-web could not list its stages: " + ui.catalogue.error, "error");
    return;
  }
  initialState(report);
  editor = new LabEditor($("editor"), onEdit);
  wireControls();
  syncControls();
  openStageFiles();
  wireCamera();
  wireDrop();
  wireContextLoss();
  $("reset-file").addEventListener("click", resetFile);
  $("download").addEventListener("click", download);
  $("download").disabled = false;
  $("redraw").disabled = false;
  $("redraw").addEventListener("click", () => {
    waitingForEdit = false;
    requestDraw();
  });
  $("check").addEventListener("click", runCheck);
  if ("showDirectoryPicker" in window) {
    $("open-folder").hidden = false;
    $("open-folder").disabled = false;
    $("open-folder").addEventListener("click", openFolder);
  }
  updateURL();
  fitCanvas();
  if (state === "ready") {
    frameInfo({seconds: report.seconds && report.seconds.frame}, "first frame");
    lastDraw = {kind: "build", at: performance.now()};
    builtKey = buildKey();
    if (fellBackToLabs)
      say(`This site has no reference solution of lab ${ui.stage.number}: the frame shows your files.`);
    if (restoredPaths.length)
      say(`Your edits kept in this browser: ${restoredPaths.map((p) => p.replace(/^\/kit\//, "")).join(", ")}.`);
  } else if (report.error) {
    if (parseDiagnostics(report.error).length) showCompileError(report.error);
    else say(report.error, "error");
  }
  if (labs.storageProblem) say(`This browser keeps nothing for this page (${labs.storageProblem}): use Download ` +
                               "my labs to keep your work.", "error");
  kitPage.ready = true;
  kitPage.editor = editor;
  kitPage.labs = labs;
  kitPage.ui = ui;
  kitPage.compileNow = compileEdits;
  document.body.dataset.kitPage = "ready";
}

let restoredPaths = [];

// kit-web's Module: the URL's options as kit-render's arguments (--solution added in
// onRuntimeInitialized, once the file system tells whether the site has that solution).
const args = [];
for (const [key, flag] of [["stage", "--stage"], ["scene", "--scene"], ["view", "--view"], ["size", "--size"],
                           ["camera", "--camera"]]) {
  if (query.has(key)) args.push(flag, query.get(key));
}
const size = /^(\d+)x(\d+)$/.exec(query.get("size") || "");
if (size) {
  // Exactly that many pixels, shown one canvas pixel to one CSS pixel.
  canvas.style.width = size[1] + "px";
  canvas.style.height = size[2] + "px";
}

window.Module = {
  arguments: args,
  canvas,
  print: (text) => console.log(text),
  printErr: (text) => console.warn(text),
  // Before main(): the file system holds the site's files. The student's kept edits go into
  // it, so the first frame draws them, and the URL's shaders decide --solution.
  onRuntimeInitialized: () => {
    FS = window.Module.FS;
    labs = new LabFiles(FS);
    restoredPaths = labs.restore();
    ui.catalogue = kitCall({cmd: "catalogue"});
    let stage = ui.catalogue.stages ? findStage(query.get("stage") || "gbuffer") : null;
    if (!query.has("stage") && ui.catalogue.stages) {
      // No stage in the URL: the first lab this site has the student's files of and can
      // draw (a class's site: the class's lab; the instructors': lab 1, as kit-render).
      const own = ui.catalogue.stages.find((s) => hasLabs(s) && !missingEarlier(s));
      if (own && own !== stage) {
        stage = own;
        args.push("--stage", own.name);
      }
    }
    if (query.get("shaders") !== "labs") {
      if (stage && !stage.solution && hasLabs(stage)) fellBackToLabs = true;
      // emscripten passes this same array to main(): the flag is added in place.
      else args.push("--solution");
    }
  },
  kitDone: (state, json) => {
    const report = JSON.parse(json);
    report.page_seconds_to_frame = (performance.now() - pageStart) / 1000;
    window.kitReport = report;
    $("report").textContent = JSON.stringify(report, null, 2);
    if (state === "ready") {
      statusLine.textContent = "Stage " + report.stage + ", view " + report.view + ", scene " + report.scene + ", " +
                               report.size + ": first frame after " + report.page_seconds_to_frame.toFixed(2) + " s.";
      statusLine.className = "";
    } else {
      statusLine.textContent = report.error;
      statusLine.className = "error";
    }
    document.body.dataset.kitState = state;
    // After main() has returned: kit_call is not called from inside it.
    setTimeout(() => start(state, report), 0);
  },
};
window.addEventListener("error", (event) => {
  if (document.body.dataset.kitState) {
    // After the first frame: the page goes on; the problem shows in the messages.
    say("The page failed: " + event.message, "error");
    return;
  }
  statusLine.textContent = "kit-web failed: " + event.message;
  statusLine.className = "error";
  document.body.dataset.kitState = "error";
});
