// The kit's page (index.html): kit-web's first frame from the URL's options, then the
// controls (lab, shaders, scene, view, size, kit-view's settings), orbiting the camera, the
// lab editor (editor.js) whose edits recompile as the student types, their copy in this
// browser (labs.js), "Download my labs", "Open folder", "Check my lab" (check.js), and the
// GPU resets a shader that never ends causes. kit-web answers every command through
// kit_call(JSON) -> JSON (tools/web/kit_web.cpp); the page draws only when something changed.
import {wireCamera} from "./camera.js";
import {showCheck} from "./check.js";
import {parseDiagnostics} from "./diagnostics.js";
import {LabEditor} from "./editor.js";
import {compileEdits, onEdit, resetFile, restoreEdits, saveToFolder} from "./edits.js";
import {configureCommand, findStage, fsExists, hasLabs, kitCall, missingEarlier} from "./kit.js";
import {say} from "./messages.js";
import {$, MAP_VIEWS, SIZES, VIEW_LABELS, createPage} from "./state.js";
import {markTabs, openStageFiles, showCompileError} from "./tabs.js";
import {firstFrameArguments, initialState, kitArguments, updateURL} from "./url.js";
import {canDraw, configure, drawn, firstFrame, fitCanvas, requestDraw, wireContextLoss} from "./view.js";

// The student's labs outside this browser: "Download my labs" (a zip in the layout ./kit grade
// takes) and "Open folder" (the File System Access API), which reads the kit's labs/ folder on
// the student's computer, saves the edits into it (edits.js) and takes the changes made there
// in another editor.
function download(page) {
  compileEdits(page);
  const bytes = page.labs.zip();
  page.kitPage.lastDownload = {name: "labs.zip", bytes};
  const url = URL.createObjectURL(new Blob([bytes], {type: "application/zip"}));
  const a = document.createElement("a");
  a.href = url;
  a.download = "labs.zip";
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 60000);
  say(page, `labs.zip: ${page.labs.paths().length} files as labs/NN-name/FILE, the layout ./kit grade and the ` +
      "course platform take.");
}

async function openFolder(page) {
  const labs = page.labs;
  let dir;
  try {
    dir = await window.showDirectoryPicker({id: "kit-labs", mode: "readwrite"});
  } catch (e) {
    if (e.name !== "AbortError") say(page, "Could not open the folder: " + (e.message || e), "error");
    return;
  }
  compileEdits(page);  // what was typed before goes where it went so far, not into this folder
  let labsDir = null;
  try {
    labsDir = await dir.getDirectoryHandle("labs");
  } catch (e) {
    for await (const [name, handle] of dir.entries())
      if (handle.kind === "directory" && /^\d\d-/.test(name)) labsDir = dir;
  }
  if (!labsDir) {
    say(page, `${dir.name} has no labs/ folder: choose your kit's folder, or its labs/ folder.`, "error");
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
    say(page, `${dir.name}: none of this site's lab files (labs/NN-name/FILE) are in it.`, "error");
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
  page.folder = {name: dir.name, labsDir, files};
  const taken = [];
  for (const [path, entry] of files) {
    if (entry.text === labs.text(path)) continue;
    if (takeFolder || !conflicts.some(([p]) => p === path)) {
      takeText(page, path, entry.text);
      taken.push(path);
    } else {
      saveToFolder(page, path);
    }
  }
  $("folder-info").hidden = false;
  $("folder-info").textContent = `Folder ${dir.name}: ${files.size} lab files; your edits are saved into it, and ` +
                                 "changes made there (in your editor) show here.";
  say(page, `Opened ${dir.name}.`, "ok");
  drawTaken(page, taken);
  if (!page.folderTimer) page.folderTimer = setInterval(() => pollFolder(page), 1500);
}

// A text from the student's folder: into the editor, this browser's copy and the file system.
function takeText(page, path, text) {
  page.editor.setText(path, text);
  page.labs.set(path, text);
  page.labs.writeFS(path);
  markTabs(page);
}

// Compiles and draws the texts taken from the folder when the stage draws one of them.
function drawTaken(page, paths) {
  if (page.ui.solution || page.lost || !paths.some((p) => p.startsWith(`/kit/labs/${page.ui.stage.folder}/`))) return;
  page.waitingForEdit = false;
  drawn(page, kitCall({cmd: "reload"}), "edit", "your folder's files");
}

async function pollFolder(page) {
  if (!page.folder || page.polling || document.visibilityState !== "visible") return;
  page.polling = true;
  try {
    const changed = [];
    for (const [path, entry] of page.folder.files) {
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
      if (text !== page.labs.text(path) && !page.pending.has(path)) {
        takeText(page, path, text);
        changed.push(path);
      }
    }
    if (changed.length) {
      say(page, `Changed in ${page.folder.name}: ${changed.map((p) => p.replace(/^\/kit\//, "")).join(", ")}.`);
      drawTaken(page, changed);
    }
  } catch (e) {
    say(page, `Could not read ${page.folder.name}: ${e.message || e}`, "error");
  } finally {
    page.polling = false;
  }
}

// The controls beside the frame (lab, shaders, scene, view, size, kit-view's settings): they
// mirror page.ui, offer only what the lab can draw, and each change goes into page.ui and
// asks for a frame (view.js), which also puts it in the URL.
function option(value, text, disabled = false) {
  const o = document.createElement("option");
  o.value = value;
  o.textContent = text;
  o.disabled = disabled;
  return o;
}

function fillStages(page) {
  const select = $("stage");
  select.replaceChildren();
  for (const s of page.ui.catalogue.stages) {
    const missing = missingEarlier(page, s);
    const label = `${s.number} ${s.name}` + (missing ? ` (needs lab ${missing.number}'s solution)` : "");
    select.append(option(s.name, label, Boolean(missing)));
  }
  select.value = page.ui.stage.name;
}

function fillViews(page) {
  const ui = page.ui;
  const select = $("view");
  select.replaceChildren();
  // As kit-view offers them: HDR from the first lit stage, lab 6's maps in lab 6.
  const allowed = (v) => (v !== "hdr" || ui.stage.number >= 2) &&
                         (!MAP_VIEWS.includes(v) || ui.stage.name === "ibl");
  for (const v of ui.catalogue.views) if (allowed(v)) select.append(option(v, VIEW_LABELS[v] || v));
  if (![...select.options].some((o) => o.value === ui.view)) ui.view = "final";
  select.value = ui.view;
}

function fillScenes(page) {
  const ui = page.ui;
  const select = $("scene");
  select.replaceChildren();
  const kit = document.createElement("optgroup");
  kit.label = "The kit's scenes";
  for (const name of ui.catalogue.scenes) kit.append(option(name, name));
  select.append(kit);
  if (page.droppedScenes.length) {
    const own = document.createElement("optgroup");
    own.label = "Your models";
    for (const d of page.droppedScenes) own.append(option(d.path, d.label));
    select.append(own);
  }
  if (![...select.querySelectorAll("option")].some((o) => o.value === ui.scene)) {
    select.append(option(ui.scene, ui.scene));
  }
  select.value = ui.scene;
}

function fillSizes(page) {
  const select = $("size");
  select.replaceChildren();
  const sizes = [...SIZES];
  const current = `${page.ui.width}x${page.ui.height}`;
  if (!sizes.includes(current)) sizes.unshift(current);
  for (const s of sizes) select.append(option(s, s.replace("x", " x ")));
  select.value = current;
}

function syncShaders(page) {
  const labsThere = hasLabs(page, page.ui.stage);
  $("shaders-labs").disabled = !labsThere;
  $("shaders-solution").disabled = !page.ui.stage.solution;
  $("shaders-labs").checked = !page.ui.solution;
  $("shaders-solution").checked = page.ui.solution;
}

function syncSettings(page) {
  let shown = 0;
  for (const row of document.querySelectorAll("[data-from-lab]")) {
    row.hidden = page.ui.stage.number < Number(row.dataset.fromLab);
    if (!row.hidden) shown += 1;
  }
  $("settings-none").hidden = shown > 0;
  $("bloom-threshold").disabled = !page.ui.settings.postprocess;
}

function syncControls(page) {
  fillStages(page);
  syncShaders(page);
  fillScenes(page);
  fillViews(page);
  fillSizes(page);
  syncSettings(page);
  const s = page.ui.settings;
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
  $("check").disabled = !hasLabs(page, page.ui.stage) || Boolean(missingEarlier(page, page.ui.stage));
}

function wireControls(page) {
  const ui = page.ui;
  for (const id of ["stage", "scene", "view", "size", "postprocess", "custom-effect", "gamma", "bloom-threshold",
                    "extra-lights", "model-file", "shaders-labs", "shaders-solution"])
    $(id).disabled = false;
  for (const radio of document.querySelectorAll('input[name="attenuation"]')) radio.disabled = false;

  $("stage").addEventListener("change", () => {
    ui.stage = findStage(page, $("stage").value);
    // A student's default is their own files; a lab that is over shows its solution.
    ui.solution = !hasLabs(page, ui.stage) && ui.stage.solution;
    syncControls(page);
    openStageFiles(page);
    requestDraw(page);
  });
  for (const id of ["shaders-labs", "shaders-solution"]) {
    $(id).addEventListener("change", () => {
      ui.solution = $("shaders-solution").checked;
      openStageFiles(page);
      requestDraw(page);
    });
  }
  $("scene").addEventListener("change", () => {
    ui.scene = $("scene").value;
    requestDraw(page);
  });
  $("view").addEventListener("change", () => {
    ui.view = $("view").value;
    requestDraw(page);
  });
  $("size").addEventListener("change", () => {
    [ui.width, ui.height] = $("size").value.split("x").map(Number);
    requestDraw(page);
  });
  $("postprocess").addEventListener("change", () => {
    ui.settings.postprocess = $("postprocess").checked;
    syncSettings(page);
    requestDraw(page);
  });
  $("custom-effect").addEventListener("change", () => {
    ui.settings.custom_effect = $("custom-effect").checked;
    requestDraw(page);
  });
  const slider = (id, key, digits) => {
    $(id).addEventListener("input", () => {
      ui.settings[key] = Number($(id).value);
      $(id + "-value").textContent = ui.settings[key].toFixed(digits);
      requestDraw(page);
    });
  };
  slider("gamma", "gamma", 2);
  slider("bloom-threshold", "bloom_threshold", 2);
  slider("extra-lights", "extra_lights", 0);
  for (const radio of document.querySelectorAll('input[name="attenuation"]')) {
    radio.addEventListener("change", () => {
      ui.settings.attenuation_model = Number(radio.value);
      requestDraw(page);
    });
  }
}

// The student's own model, dropped on the page or picked with "Your model": its files go into
// kit-web's file system and it becomes a scene of the Scene list. kit-web reads glTF only;
// a model it cannot draw leaves the scene as it was.
async function loadModel(page, files) {
  if (!files.length) return;
  const ui = page.ui;
  const names = files.map((f) => f.name);
  if (names.some((n) => /\.obj$/i.test(n)) && !names.some((n) => /\.(glb|gltf)$/i.test(n))) {
    say(page, "OBJ scenes are refused in the browser build (it has no OBJ reader): export the model as glTF (.glb) " +
        "(Blender: File > Export > glTF 2.0), or draw it with ./kit render or ./kit view.", "error");
    return;
  }
  const main = files.find((f) => /\.glb$/i.test(f.name)) || files.find((f) => /\.gltf$/i.test(f.name));
  if (!main) {
    say(page, `Not a model: ${names.join(", ")}. Drop a .glb, or a .gltf together with its .bin and images.`, "error");
    return;
  }
  page.droppedCount += 1;
  const dir = `/work/dropped/${page.droppedCount}`;
  page.FS.mkdirTree(dir);
  for (const file of files) page.FS.writeFile(`${dir}/${file.name}`, new Uint8Array(await file.arrayBuffer()));
  if (/\.gltf$/i.test(main.name)) {
    try {
      const gltf = JSON.parse(await main.text());
      const uris = [...(gltf.buffers || []), ...(gltf.images || [])].map((x) => x.uri)
        .filter((u) => u && !u.startsWith("data:")).map((u) => decodeURIComponent(u));
      const missing = uris.filter((u) => !fsExists(page, `${dir}/${u}`));
      if (missing.length) {
        say(page, `${main.name} needs ${missing.join(", ")}: drop or pick them together with it.`, "error");
        return;
      }
    } catch (e) {
      say(page, `${main.name} is not glTF's JSON: ${e.message || e}`, "error");
      return;
    }
  }
  const previous = ui.scene;
  ui.scene = `${dir}/${main.name}`;
  if (!canDraw(page)) {
    ui.scene = previous;
    return;
  }
  if (configure(page, main.name)) {
    page.droppedScenes.push({path: ui.scene, label: main.name});
    fillScenes(page);
    say(page, `Drawing your model ${main.name}.`, "ok");
  } else {
    // kit-web keeps the scene it was given: back to the one before, the message kept.
    ui.scene = previous;
    fillScenes(page);
    const why = page.kitPage.lastError;
    if (!kitCall(configureCommand(page)).error) fitCanvas(page);
    say(page, `${main.name} could not be drawn: ${why}`, "error");
  }
}

// Files dragged over the page show the drop overlay; dropped or picked, they are loaded.
function wireModels(page) {
  $("model-file").addEventListener("change", () => {
    const files = [...$("model-file").files];
    $("model-file").value = "";
    loadModel(page, files);
  });
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
    loadModel(page, [...e.dataTransfer.files]);
  });
}

// ---- Check my lab ----
// The button: the student's edits compiled first, then the check, which takes kit-web a while.
function runCheck(page) {
  compileEdits(page);
  if (!canDraw(page)) return;
  const lab = page.ui.stage.number;
  const section = $("check-results");
  section.hidden = false;
  $("check-body").replaceChildren(Object.assign(document.createElement("p"), {
    textContent: `Checking lab ${lab}: rendering the grader's checks with your files\u2026`}));
  $("check").disabled = true;
  // Let the message show before kit-web takes the main thread.
  setTimeout(() => {
    const answer = kitCall({cmd: "check", lab});
    page.kitPage.lastCheck = answer;
    $("check").disabled = false;
    if (answer.error) {
      $("check-body").replaceChildren(Object.assign(document.createElement("p"), {
        className: "error", textContent: `The check could not run: ${answer.error}`}));
      if (parseDiagnostics(answer.error).length) showCompileError(page, answer.error);
    } else {
      showCheck($("check-body"), page.FS, lab, answer);
      if (answer.status === "compile_error" && answer.message) showCompileError(page, answer.message);
      fitCanvas(page);
    }
    section.focus();
  }, 30);
}

const page = createPage();
const statusLine = $("status");

// After kit-web's first frame (or its refusal): the controls, the editor and the buttons.
function start(state, report) {
  const ui = page.ui;
  if (!ui.catalogue || ui.catalogue.error) ui.catalogue = kitCall({cmd: "catalogue"});
  if (ui.catalogue.error) {
    say(page, "kit-web could not list its stages: " + ui.catalogue.error, "error");
    return;
  }
  initialState(page, report);
  page.editor = new LabEditor($("editor"), (path, text) => onEdit(page, path, text));
  wireControls(page);
  syncControls(page);
  openStageFiles(page);
  wireCamera(page);
  wireModels(page);
  wireContextLoss(page);
  $("reset-file").addEventListener("click", () => resetFile(page));
  $("download").addEventListener("click", () => download(page));
  $("download").disabled = false;
  $("redraw").disabled = false;
  $("redraw").addEventListener("click", () => {
    page.waitingForEdit = false;
    requestDraw(page);
  });
  $("check").addEventListener("click", () => runCheck(page));
  if ("showDirectoryPicker" in window) {
    $("open-folder").hidden = false;
    $("open-folder").disabled = false;
    $("open-folder").addEventListener("click", () => openFolder(page));
  }
  updateURL(page);
  fitCanvas(page);
  if (state === "ready") {
    firstFrame(page, report);
    if (page.fellBackToLabs)
      say(page, `This site has no reference solution of lab ${ui.stage.number}: the frame shows your files.`);
    const restored = page.restoredPaths.map((p) => p.replace(/^\/kit\//, ""));
    if (restored.length) say(page, `Your edits kept in this browser: ${restored.join(", ")}.`);
  } else if (report.error) {
    if (parseDiagnostics(report.error).length) showCompileError(page, report.error);
    else say(page, report.error, "error");
  }
  const problem = page.labs.storageProblem;
  if (problem) say(page, `This browser keeps nothing for this page (${problem}): use Download ` +
                   "my labs to keep your work.", "error");
  Object.assign(page.kitPage, {ready: true, editor: page.editor, labs: page.labs, ui,
                               compileNow: () => compileEdits(page)});
  document.body.dataset.kitPage = "ready";
}

// kit-web's Module: the URL's options as kit-render's arguments.
const args = kitArguments(page);
window.Module = {
  arguments: args,
  canvas: page.canvas,
  print: (text) => console.log(text),
  printErr: (text) => console.warn(text),
  // Before main(): the file system holds the site's files. The student's kept edits go into
  // it, so the first frame draws them, and the URL's shaders decide --solution.
  onRuntimeInitialized: () => {
    page.FS = window.Module.FS;
    restoreEdits(page);
    page.ui.catalogue = kitCall({cmd: "catalogue"});
    firstFrameArguments(page, args);
  },
  kitDone: (state, json) => {
    const report = JSON.parse(json);
    report.page_seconds_to_frame = (performance.now() - page.startedAt) / 1000;
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
    say(page, "The page failed: " + event.message, "error");
    return;
  }
  statusLine.textContent = "kit-web failed: " + event.message;
  statusLine.className = "error";
  document.body.dataset.kitState = "error";
});
