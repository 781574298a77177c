// The student's edits: kept in this browser on every keystroke (labs.js), written into
// kit-web's file system and the student's folder when one is open, then compiled and drawn
// once the student stops typing, so the frame follows the text without a button.
import {kitCall} from "./kit.js";
import {LabFiles} from "./labs.js";
import {say} from "./messages.js";
import {markTabs} from "./tabs.js";
import {drawn} from "./view.js";

const COMPILE_DELAY_MS = 300;
// An edit whose frame takes longer than this is not drawn again by itself (a camera move, a
// setting): with a loop that never ends each frame takes the guard's whole budget
// (common/gl/loop_guard.h), seconds of a software GPU, and the page answers nothing meanwhile.
const SLOW_EDIT_FRAME_S = 1;

// Before kit-web's main(): the lab files, with the edits this browser kept put into the file
// system, so the first frame draws them.
export function restoreEdits(page) {
  page.labs = new LabFiles(page.FS);
  page.restoredPaths = page.labs.restore();
}

// The edits restore() held back, since the last load stopped while drawing them (its first
// frame, or an edit's): which files, and their text to look at (never compiled again by itself).
export function sayHeldBack(page) {
  const held = page.labs.heldBack;
  const names = held.map((p) => p.replace(/^\/kit\//, "")).join(", ");
  const text = `The last visit stopped while drawing your edits of ${names} (a shader that took the page ` +
               "down?): this visit starts without them, from the starters. Their text is kept.";
  say(page, text, "error", "", [{
    label: "Show the held-back text",
    run: () => say(page, text, "error", held.map((p) => `// ${p.replace(/^\/kit\//, "")}\n${page.labs.heldText(p)}`)
                                         .join("\n\n")),
  }]);
}

export function onEdit(page, path, text) {
  const labs = page.labs;
  if (!labs.has(path)) return;
  if (!labs.set(path, text))
    say(page, `This browser refused to keep your text (${labs.storageProblem}): use Download my labs before you ` +
        "leave.", "error");
  page.pending.add(path);
  markTabs(page);
  clearTimeout(page.compileTimer);
  page.compileTimer = setTimeout(() => compileEdits(page), COMPILE_DELAY_MS);
}

// Writes the edited files into kit-web's file system (and the student's folder), then
// compiles and draws the stage when it draws one of them.
export function compileEdits(page) {
  clearTimeout(page.compileTimer);
  if (!page.pending.size) return;
  const paths = [...page.pending];
  page.pending.clear();
  for (const path of paths) {
    page.labs.writeFS(path);
    saveToFolder(page, path);
  }
  const ui = page.ui;
  const drawsThem = !ui.solution && paths.some((p) => p.startsWith(`/kit/labs/${ui.stage.folder}/`));
  if (!drawsThem) {
    if (ui.solution)
      say(page, "Saved. The frame shows the reference solution: choose \"my lab files\" to draw your edit.");
    return;
  }
  if (page.lost) {
    page.editWhileLost = true;
    say(page, "Saved. The GPU context is lost: your edit is drawn once the browser restores it.", "error");
    return;
  }
  page.waitingForEdit = false;
  const answer = page.labs.whileDrawing(ui.stage.folder, () => kitCall({cmd: "reload"}));
  if (drawn(page, answer, "edit", "your edit") && answer.seconds > SLOW_EDIT_FRAME_S) {
    page.waitingForEdit = true;
    say(page, `Your edit's frame took ${answer.seconds.toFixed(1)} s, past the page's limit of ${SLOW_EDIT_FRAME_S} s ` +
        "(kit-grade stops such shaders at its CPU time limit): a loop that never ends? In the browser loops stop after a " +
        "fixed count of iterations a pixel (docs/web.md), so the frame ends, and shows where they were cut. The " +
        "page does not draw it again by itself: edit a file, or press Redraw.", "error");
  }
}

// The text now into the student's folder (folder.js), after the writes before it.
export function saveToFolder(page, path) {
  const folder = page.folder;
  if (!folder) return;
  const entry = folder.files.get(path);
  if (!entry) return;
  const text = page.labs.text(path);
  entry.writing = entry.writing.then(async () => {
    const stream = await entry.handle.createWritable();
    await stream.write(text);
    await stream.close();
    const file = await entry.handle.getFile();
    entry.lastModified = file.lastModified;
    entry.text = text;
  }).catch((e) => say(page, `Could not save ${path.replace(/^\/kit\//, "")} into ${page.folder.name} ` +
                      `(${e.message || e}); your text is kept in this browser.`, "error"));
}

export function resetFile(page) {
  const path = page.path, labs = page.labs;
  if (!path || !labs.has(path)) return;
  const starter = labs.starter(path);
  if (labs.text(path) === starter) {
    say(page, "This file is the starter already.");
    return;
  }
  page.editor.setText(path, starter);
  onEdit(page, path, starter);
  say(page, `${path.replace(/^\/kit\//, "")}: back to the starter. Ctrl+Z in the editor brings your text back.`);
}
