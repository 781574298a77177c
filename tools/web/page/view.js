// Drawing: the page draws only when something changed, at most once an animation frame, and
// every answer of kit-web that draws comes through drawn(): the frame, or the problem while
// the canvas keeps the last good frame. A shader that never ends makes the browser reset the
// GPU; the page then waits for the context to come back before it draws again.
import {parseDiagnostics} from "./diagnostics.js";
import {buildKey, configureCommand, kitCall} from "./kit.js";
import {say, showsError} from "./messages.js";
import {$, MAP_VIEWS, VIEW_LABELS} from "./state.js";
import {clearCompileErrors, showCompileError} from "./tabs.js";
import {updateURL} from "./url.js";

// A context lost this soon after an edit's frame is taken as that edit's doing.
const LOST_AFTER_EDIT_MS = 10000;

export function frameInfo(page, answer, what) {
  const ui = page.ui, canvas = page.canvas;
  const ms = (s) => (1000 * s).toFixed(1) + " ms";
  const who = ui.solution ? "reference solution" : "your files";
  const scene = ui.scene.startsWith("/") ? ui.scene.split("/").pop() : ui.scene;
  $("frame-info").textContent = `Lab ${ui.stage.number} (${ui.stage.name}), ${who}, scene ${scene}, ` +
    `${VIEW_LABELS[ui.view] || ui.view}, ${canvas.width}x${canvas.height}: ${what} drawn in ${ms(answer.seconds || 0)}.`;
}

// The canvas at one canvas pixel per CSS pixel; lab 6's maps, which have small sizes of
// their own, magnified by a whole factor.
export function fitCanvas(page) {
  const canvas = page.canvas;
  const zoom = MAP_VIEWS.includes(page.ui.view) ? Math.max(1, Math.floor(256 / Math.max(canvas.width, canvas.height)))
                                                : 1;
  canvas.style.width = zoom * canvas.width + "px";
  canvas.style.height = zoom * canvas.height + "px";
}

// An answer to a command that draws: the frame it drew, or the problem (the canvas keeps
// the last good frame). kind: "edit" (a compile of the student's files), "build" (a
// configure that built the renderer anew from the files), "settings" (one that kept the
// renderer: a compile error of the files stands) or "move".
export function drawn(page, answer, kind, label) {
  const kitPage = page.kitPage;
  if (answer.error) {
    kitPage.errors += 1;
    kitPage.lastError = answer.error;
    if (page.lost || /WebGL context is lost/.test(answer.error))
      say(page, "Waiting for the browser to restore the GPU context.", "error");
    else if (parseDiagnostics(answer.error).length) showCompileError(page, answer.error);
    else say(page, answer.error, "error");
    return false;
  }
  fitCanvas(page);
  kitPage.frames += 1;
  page.lastDraw = {kind, at: performance.now()};
  if (kind === "edit" || kind === "build") {
    clearCompileErrors(page);
    if (kind === "edit") say(page, `Compiled and drawn (${(1000 * (answer.seconds || 0)).toFixed(0)} ms).`, "ok");
    else if (showsError()) say(page, "");
  } else if (!page.compileErrors.size && showsError()) {
    say(page, "");
  }
  if (answer.warnings && answer.warnings.length) say(page, "Warnings:", "", answer.warnings.join("\n"));
  frameInfo(page, answer, label);
  return true;
}

export function canDraw(page) {
  if (page.lost) {
    say(page, "The GPU context is lost; the page draws again once the browser restores it.", "error");
    return false;
  }
  if (page.waitingForEdit) {
    say(page, "Not drawing: your last edit's frame reset the GPU or ran past the page's time limit. Edit a file to " +
        "try again, or press Redraw.", "error");
    return false;
  }
  return true;
}

// Draws with the controls' state now; kind as drawn() takes it, "build" or "settings" by
// what changed since the last frame kit-web built.
export function configure(page, label, rebuilt = false) {
  const key = buildKey(page);
  const answer = page.lastAnswer = kitCall(configureCommand(page));
  const ok = drawn(page, answer, rebuilt || key !== page.builtKey ? "build" : "settings", label);
  if (ok) page.builtKey = key;
  return ok;
}

// Draws with the controls' state at the next animation frame (changes in between coalesce).
export function requestDraw(page) {
  updateURL(page);
  if (page.drawRequested) return;
  page.drawRequested = true;
  requestAnimationFrame(() => {
    page.drawRequested = false;
    if (!canDraw(page)) return;
    configure(page, "frame");
  });
}

// The first frame, drawn by kit-web's main() before the page started: as if configure() drew it.
export function firstFrame(page, report) {
  frameInfo(page, {seconds: report.seconds && report.seconds.frame}, "first frame");
  page.lastDraw = {kind: "build", at: performance.now()};
  page.builtKey = buildKey(page);
}

export function wireContextLoss(page) {
  const canvas = page.canvas;
  canvas.addEventListener("webglcontextlost", (e) => {
    e.preventDefault();  // the browser restores it then
    page.lost = true;
    page.lostAfterEdit = page.lastDraw.kind === "edit" && performance.now() - page.lastDraw.at < LOST_AFTER_EDIT_MS;
    page.editWhileLost = false;
    kitCall({cmd: "lost"});
    say(page, "The GPU reset while drawing: a shader took too long (a loop that never ends?). Your files are kept; " +
        "the page draws again once the browser restores the GPU context.", "error");
    page.kitPage.lostAt = performance.now();
  });
  canvas.addEventListener("webglcontextrestored", () => {
    page.lost = false;
    const restored = kitCall({cmd: "restored"});
    if (restored.error) {
      say(page, "The GPU context came back, but kit-web could not use it: " + restored.error, "error");
      return;
    }
    if (page.lostAfterEdit && !page.editWhileLost) {
      page.waitingForEdit = true;
      say(page, "The GPU reset while drawing: a shader took too long (a loop that never ends?). The GPU context is " +
          "back, but the page does not draw your last edit again by itself: edit a file to try again (or press " +
          "Redraw).", "error");
      return;
    }
    page.waitingForEdit = false;
    if (configure(page, "frame after the GPU reset", true)) {
      if (page.editWhileLost) page.lastDraw.kind = "edit";  // a loss now is that edit's doing
      else say(page, "The GPU context is back: drawn again.", "ok");
    }
  });
}
