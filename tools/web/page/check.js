// "Check my lab": the grader's files fetched the first time, the student's edits compiled,
// then kit-web's answer to {"cmd": "check", "lab": N} (tools/web/page_check.cpp, the grader's
// own comparison) shown as a list of checks, each with the student's render, the reference
// and the difference image, the score and the likely mistakes.
import {parseDiagnostics} from "./diagnostics.js";
import {docLink, docLinks} from "./doc_links.js";
import {compileEdits} from "./edits.js";
import {kitCall} from "./kit.js";
import {checkFilesMessage, loadCheckFiles} from "./packages.js";
import {$} from "./state.js";
import {showCompileError} from "./tabs.js";
import {canDraw, fitCanvas} from "./view.js";

function element(tag, attributes = {}, ...children) {
  const e = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) {
    if (key === "className") e.className = value;
    else e.setAttribute(key, value);
  }
  for (const child of children) e.append(child);
  return e;
}

// An RGBA8 file of kit-web's file system (rows top-down) in a canvas; with `worst` ({x, y}),
// that pixel ringed in green, as kit-grade's report rings a failed check's worst pixel.
function image(FS, info, caption, worst) {
  const figure = element("figure");
  try {
    const bytes = FS.readFile(info.path);
    const canvas = element("canvas", {width: info.width, height: info.height, role: "img",
                                      "aria-label": `${caption}, ${info.width}x${info.height}`});
    const pixels = new Uint8ClampedArray(bytes.buffer, bytes.byteOffset, info.width * info.height * 4);
    const context = canvas.getContext("2d");
    context.putImageData(new ImageData(pixels, info.width, info.height), 0, 0);
    if (worst) {
      context.lineWidth = 2;
      context.strokeStyle = "#00ff00";
      context.beginPath();
      context.arc(worst.x + 0.5, worst.y + 0.5, 6, 0, 2 * Math.PI);
      context.stroke();
    }
    figure.append(canvas);
  } catch (e) {
    figure.append(element("p", {className: "error"}, `${caption}: could not read ${info.path}: ${e.message || e}`));
  }
  figure.append(element("figcaption", {}, caption));
  return figure;
}

const points = (n) => (Math.round(n * 100) / 100).toString();

function showCheck(page, container, lab, answer) {
  const FS = page.FS;
  container.replaceChildren();
  const status = answer.status;
  const head = element("p");
  if (status === "graded") {
    head.append(element("strong", {}, `Lab ${lab}: ${answer.passed} of ${answer.total} checks pass, ` +
                                      `${points(answer.score)} of ${points(answer.max_score)} points (preview).`));
  } else {
    const why = {compile_error: "your shaders do not compile", render_error: "a render failed",
                 non_finite_map: "a precomputed map holds NaN or infinite values"}[status] || status;
    head.append(element("strong", {className: "error"}, `Lab ${lab}: not graded: ${why}.`));
  }
  container.append(head);
  if (answer.message)
    container.append(element("pre", {className: status === "graded" ? "" : "error"}, docLinks(page, answer.message)));
  if (answer.seconds && answer.seconds.total !== undefined)
    container.append(element("p", {className: "hint"}, `Rendered and compared in ${answer.seconds.total.toFixed(1)} s.`));

  // The probed functions that differ, with their first inputs (tools/grade/frames/function_probes.h):
  // first, as they point at the line to fix.
  const functions = answer.functions_text || [];
  if (functions.length) {
    container.append(element("h3", {}, "Your functions"));
    const list = element("ul");
    for (const line of functions) list.append(element("li", {}, line));
    container.append(list);
  }

  for (const check of answer.checks || []) {
    const box = element("article", {className: "check " + (check.passed ? "passed" : "failed")});
    box.append(element("h3", {}, `${check.passed ? "Passed" : "Failed"}: ${check.title} `,
                       element("span", {className: "hint"}, `(${check.key}, ${points(check.points)} points)`)));
    if (check.summary) box.append(element("p", {}, docLinks(page, check.summary)));
    if (check.note) box.append(element("p", {className: "hint"}, docLinks(page, check.note)));
    if (check.worst_pixel) box.append(element("p", {}, "At " + check.worst_pixel + "."));
    if (check.image) box.append(image(FS, check.image, "your render"));
    if (check.reference) box.append(image(FS, check.reference, "reference"));
    if (check.diff) box.append(image(FS, check.diff, "difference", check.worst));
    container.append(box);
  }

  const mistakes = answer.likely_mistakes || [];
  if (mistakes.length) {
    container.append(element("h3", {}, "Likely mistakes"));
    const list = element("ul");
    for (const m of mistakes)
      list.append(element("li", {}, docLinks(page, `${m.description} `),
                          element("span", {className: "hint"}, `(${m.id}, similarity ${Math.round(100 * m.similarity)}%)`)));
    container.append(list);
    // As kit-grade's report says it (tools/grade/report/report.cpp), a link that opens the pane there.
    const doc = `handouts/${page.ui.stage.folder}.md`;
    container.append(element("p", {className: "see-handout"}, "See ",
                             docLink(doc, "common-mistakes", `${doc}#common-mistakes`), "."));
  } else if (status === "graded" && answer.passed < answer.total) {
    container.append(element("p", {className: "hint"}, "No known mistake matches these renders."));
  }
}

function sayInCheck(text, className = "") {
  $("check-body").replaceChildren(Object.assign(document.createElement("p"), {className, textContent: text}));
}

// The button: the grader's references and the lab's scenes fetched the first time (they are
// not in kit-web.data: packages.js), the student's edits compiled, then the check, which
// takes kit-web a while.
export async function runCheck(page) {
  if (!canDraw(page)) return;
  const lab = page.ui.stage.number;
  const section = $("check-results");
  section.hidden = false;
  $("check").disabled = true;
  try {
    await loadCheckFiles(page, lab, (received, total) => sayInCheck(checkFilesMessage(received, total)));
  } catch (e) {
    $("check").disabled = false;
    sayInCheck(`The check could not run: the grader's files could not be loaded: ${e.message || e}`, "error");
    section.focus();
    return;
  }
  compileEdits(page);
  if (!canDraw(page)) {
    $("check").disabled = false;
    return;
  }
  sayInCheck(`Checking lab ${lab}: rendering the grader's checks with your files\u2026`);
  // Let the message show before kit-web takes the main thread.
  setTimeout(() => {
    // As an edit's frame: a tab that stops in the check holds the edits back.
    const answer = page.labs.whileDrawing(page.ui.stage.folder, () => kitCall({cmd: "check", lab}));
    page.kitPage.lastCheck = answer;
    $("check").disabled = false;
    if (answer.error) {
      sayInCheck(`The check could not run: ${answer.error}`, "error");
      if (parseDiagnostics(answer.error).length) showCompileError(page, answer.error);
    } else {
      showCheck(page, $("check-body"), lab, answer);
      if (answer.status === "compile_error" && answer.message) showCompileError(page, answer.message);
      fitCanvas(page);
    }
    section.focus();
  }, 30);
}
