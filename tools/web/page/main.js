// The kit's page (index.html): kit-web's first frame from the URL's options, then the
// controls (lab, shaders, scene, view, size, kit-view's settings), orbiting the camera, the
// lab editor (editor.js) whose edits recompile as the student types, their copy in this
// browser (labs.js), "Download my labs", "Open folder", "Check my lab" (check.js), and the
// GPU resets a shader that never ends causes. kit-web answers every command through
// kit_call(JSON) -> JSON (tools/web/kit_web.cpp); the page draws only when something changed.
import {wireCamera} from "./camera.js";
import {showCheck} from "./check.js";
import {syncControls, wireControls} from "./controls.js";
import {parseDiagnostics} from "./diagnostics.js";
import {LabEditor} from "./editor.js";
import {compileEdits, onEdit, resetFile, restoreEdits} from "./edits.js";
import {download, openFolder} from "./folder.js";
import {kitCall} from "./kit.js";
import {say} from "./messages.js";
import {wireModels} from "./models.js";
import {$, createPage} from "./state.js";
import {openStageFiles, showCompileError} from "./tabs.js";
import {firstFrameArguments, initialState, kitArguments, updateURL} from "./url.js";
import {canDraw, firstFrame, fitCanvas, requestDraw, wireContextLoss} from "./view.js";

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
