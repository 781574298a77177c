// The kit's page (index.html): kit-web's first frame from the URL's options, then the
// controls (lab, shaders, scene, view, size, kit-view's settings), orbiting the camera, the
// lab editor whose edits recompile as the student types, their copy in this browser,
// "Download my labs", "Open folder", "Check my lab", and the GPU resets a shader that never
// ends causes. kit-web answers every command through kit_call(JSON) -> JSON
// (tools/web/kit_web.cpp); the page draws only when something changed.
//
// This file only wires the modules together. They share one page object (state.js) and
// draw through one redraw loop (view.js):
//   state.js        the page object and its defaults
//   kit.js          calls into kit-web, and what its catalogue says of a lab
//   view.js         drawing, the redraw loop, lost GPU contexts
//   url.js          the URL's options, in and out
//   controls.js     the controls beside the frame
//   camera.js       orbiting the camera: mouse, touch, keyboard
//   models.js       the student's models, dropped or picked
//   messages.js     the message under the editor
//   tabs.js         the editor's tabs, and compile errors at their lines
//   editor.js       the editor (CodeMirror)
//   diagnostics.js  the files and lines a compile error names
//   edits.js        the student's edits: kept, saved, compiled
//   labs.js         the lab files and their copy in this browser
//   folder.js       Open folder, Download my labs
//   check.js        Check my lab
//   handout.js      the handout pane, and links to documents and views
//   doc_links.js    a document named in a message, as a link to it
//   notes.js        the student's progress notes, kept
//   report.js       Progress report
//   packages.js     the site's files past the first frame's: scenes, the grader's references
import {wireCamera} from "./camera.js";
import {runCheck} from "./check.js";
import {syncControls, wireControls} from "./controls.js";
import {parseDiagnostics} from "./diagnostics.js";
import {LabEditor} from "./editor.js";
import {compileEdits, onEdit, resetFile, restoreEdits, sayHeldBack} from "./edits.js";
import {download, openFolder} from "./folder.js";
import {wireHandout} from "./handout.js";
import {kitCall} from "./kit.js";
import {say} from "./messages.js";
import {wireModels} from "./models.js";
import {wireNotes} from "./notes.js";
import {wireReport} from "./report.js";
import {holdForFirstScene, loadCheckFiles, offeredScenes, startPackages} from "./packages.js";
import {$, createPage} from "./state.js";
import {openStageFiles, showCompileError} from "./tabs.js";
import {firstFrameArguments, initialState, kitArguments, updateURL} from "./url.js";
import {firstFrame, fitCanvas, requestDraw, wireContextLoss} from "./view.js";

const page = createPage();
const statusLine = $("status");
// The list of the packages fetched later, beside kit-web's own downloads.
startPackages(page);

// After kit-web's first frame (or its refusal): the controls, the editor and the buttons.
function start(state, report) {
  const ui = page.ui;
  if (!ui.catalogue || ui.catalogue.error) ui.catalogue = kitCall({cmd: "catalogue"});
  if (ui.catalogue.error) {
    say(page, "kit-web could not list its stages: " + ui.catalogue.error, "error");
    return;
  }
  ui.catalogue.scenes = offeredScenes(page, ui.catalogue.scenes);
  initialState(page, report);
  page.editor = new LabEditor($("editor"), (path, text) => onEdit(page, path, text));
  wireControls(page);
  syncControls(page);
  openStageFiles(page);
  wireCamera(page);
  wireModels(page);
  wireContextLoss(page);
  wireHandout(page);
  $("reset-file").addEventListener("click", () => resetFile(page));
  $("download").addEventListener("click", () => download(page));
  $("download").disabled = false;
  $("redraw").disabled = false;
  $("redraw").addEventListener("click", () => {
    page.waitingForEdit = false;
    requestDraw(page);
  });
  $("check").addEventListener("click", () => runCheck(page));
  wireNotes(page);
  wireReport(page);
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
    if (page.labs.heldBack.length) sayHeldBack(page);
  } else if (report.error) {
    if (parseDiagnostics(report.error).length) showCompileError(page, report.error);
    else say(page, report.error, "error");
  }
  if (page.packages.problem) say(page, `This site's files: ${page.packages.problem}.`, "error");
  const problem = page.labs.storageProblem;
  if (problem) say(page, `This browser keeps nothing for this page (${problem}): use Download ` +
                   "my labs to keep your work.", "error");
  Object.assign(page.kitPage, {ready: true, editor: page.editor, labs: page.labs, ui,
                               compileNow: () => compileEdits(page),
                               loadCheckFiles: (lab) => loadCheckFiles(page, lab).then(() => true)});
  document.body.dataset.kitPage = "ready";
}

// kit-web's Module: the URL's options as kit-render's arguments.
const args = kitArguments(page);
window.Module = {
  arguments: args,
  canvas: page.canvas,
  print: (text) => console.log(text),
  printErr: (text) => console.warn(text),
  // Before main(): the URL's scene, where it is in a package of its own (packages.js).
  preRun: [() => holdForFirstScene(page, window.Module, page.query.get("scene"))],
  // Before main(): the file system holds the site's files. The student's kept edits go into
  // it, so the first frame draws them, and the URL's shaders decide --solution.
  onRuntimeInitialized: () => {
    page.runtimeReadyAt = performance.now() / 1000;
    page.FS = window.Module.FS;
    restoreEdits(page);
    page.ui.catalogue = kitCall({cmd: "catalogue"});
    firstFrameArguments(page, args);
  },
  kitDone: (state, json) => {
    page.labs.drawingDone();
    const report = JSON.parse(json);
    report.page_seconds_to_frame = (performance.now() - page.startedAt) / 1000;
    // From the navigation's start: what a first visit waits (tests/web_first_visit_test.py),
    // and when the program was compiled and its first files were in.
    report.seconds_since_navigation = performance.now() / 1000;
    report.seconds_to_runtime = page.runtimeReadyAt;
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
