// "Progress report": the PDF the student hands in, made in the page. Each lab this site can
// assemble is checked with the student's files (kit-web's "check", as Check my lab) and timed
// (kit-web's "time", as kit-render --frames), then the report's one layout,
// tools/progress/report.mustache (the one ./kit progress-report fills: layout.py), is filled
// with the same fields and shown in a frame the browser prints to PDF. The notes' Markdown is
// rendered by markdown-it as layout.py's markdown-it-py renders it (CommonMark and tables, raw
// HTML off: the notes are text).
import {compileEdits} from "./edits.js";
import {hasLabs, kitCall, missingEarlier} from "./kit.js";
import {lazyScript} from "./lazy_script.js";
import {notesText, studentName} from "./notes.js";
import {checkFilesMessage, loadCheckFiles} from "./packages.js";
import {$, DEFAULT_SETTINGS} from "./state.js";
import {canDraw, configure} from "./view.js";

// As ./kit progress-report times a lab (tools/progress/results.py): the default scene at
// 640x480, 6 frames, the first (the driver's shader compilation) dropped, the median of the rest.
const TIMING = {frames: 6, width: 640, height: 480};

const formatScore = (v) => v.toFixed(3).replace(/0+$/, "").replace(/\.$/, "");
const formatMs = (v) => (v >= 10 ? v.toFixed(1) : v.toFixed(2)) + " ms";
const median = (values) => {
  const s = [...values].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
const pause = () => new Promise((resolve) => setTimeout(resolve, 20));

// An RGBA8 file of kit-web's file system (check.js's images) as a PNG data: URL.
function pngURL(FS, info) {
  if (!info) return null;
  try {
    const bytes = FS.readFile(info.path);
    const canvas = Object.assign(document.createElement("canvas"), {width: info.width, height: info.height});
    const pixels = new Uint8ClampedArray(bytes.buffer, bytes.byteOffset, info.width * info.height * 4);
    canvas.getContext("2d").putImageData(new ImageData(pixels, info.width, info.height), 0, 0);
    return canvas.toDataURL("image/png");
  } catch (e) {
    return null;
  }
}

// The lab's frame time: {frame_ms, frame_detail} or {frame_error}.
function timeLab(stage) {
  const setUp = kitCall({cmd: "configure", stage: stage.name, solution: false, scene: "default", view: "final",
                         width: TIMING.width, height: TIMING.height, ...DEFAULT_SETTINGS});
  const answer = setUp.error ? setUp : kitCall({cmd: "time", frames: TIMING.frames});
  if (answer.error) return {frame_ms: null, frame_error: answer.error};
  const times = answer.frame_ms.slice(1);
  return {frame_ms: formatMs(median(times)),
          frame_detail: `median of ${times.length} frames (${times.map((t) => t.toFixed(1)).join(", ")} ms) after ` +
                        `one warm-up frame; default scene, ${TIMING.width}x${TIMING.height}; this page's kit-web`};
}

// The grader's likely mistakes, first in each failed check's text, as kit-grade's report words them.
function likelyText(answer) {
  const m = answer.likely_mistakes || [];
  if (!m.length) return "";
  return "Looks like: " + m.map((x) => `${x.description} (similarity ${x.similarity.toFixed(2)})`).join("; or: ") + ". ";
}

// One lab's fields of the layout, from kit-web's check answer (as layout.py's lab_fields does
// from kit-grade's).
function labFields(FS, stage, answer, timing) {
  const fields = {number: stage.number, stage: stage.name, graded: false, ...timing};
  if (answer.error) {
    return {...fields, score: "not graded", score_class: "muted", result: "", line: "not graded",
            not_graded: answer.error, has_checks: false};
  }
  const graded = answer.status === "graded";
  const score = `${formatScore(answer.score)} / ${formatScore(answer.max_score)}`;
  const result = graded ? `${answer.passed} of ${answer.total} checks passed` : answer.status.replace(/_/g, " ");
  const guess = likelyText(answer);
  const checks = (answer.checks || []).map((c) => ({
    title: c.title, verdict: c.passed ? "passed" : "failed",
    score: `${formatScore(c.score)} / ${formatScore(c.points)}`,
    words: (c.passed ? "" : guess) + (c.note ? c.note + ". " : "") + (c.summary || ""),
    image: pngURL(FS, c.image), reference: pngURL(FS, c.reference), diff: pngURL(FS, c.diff),
    reference_caption: c.key === "custom-on" ? "yours, effect off" : null,
  }));
  return {...fields, graded, score, score_class: answer.score >= answer.max_score - 1e-9 ? "full" : "short", result,
          line: `${score}   (${result})`, checks, has_checks: checks.length > 0,
          message: graded ? null : (answer.message || "(no message)")};
}

// The GPU and driver, where the browser tells them (WEBGL_debug_renderer_info); else GL_RENDERER,
// which browsers mask ("WebKit WebGL").
function rendererName(page) {
  try {
    const gl = page.canvas.getContext("webgl2");
    const info = gl && gl.getExtension("WEBGL_debug_renderer_info");
    if (info) return gl.getParameter(info.UNMASKED_RENDERER_WEBGL);
  } catch (e) {
    // no answer: the masked name below
  }
  return (window.kitReport && window.kitReport.gl && window.kitReport.gl.renderer) || "this browser's WebGL2";
}

// kit-report.js (report_libs.js), loaded once, at the first report.
const reportLibs = () => lazyScript("kit-report.js", "kitReportLibs");

function reportFields(page, labs, seconds, MarkdownIt) {
  const graded = labs.filter((l) => l.score_class !== "muted");
  const sum = (key) => graded.reduce((t, l) => t + l[key], 0);
  const gl = rendererName(page);
  const now = new Date();
  const pad = (n) => String(n).padStart(2, "0");
  return {
    student: studentName() || "(no name given)",
    date: `${now.getFullYear()}-${pad(now.getMonth() + 1)}-${pad(now.getDate())} ${pad(now.getHours())}:` +
          pad(now.getMinutes()),
    version: "the course's page, " + window.location.origin + window.location.pathname,
    labs_included: labs.map((l) => `${l.number} ${l.stage}`).join(", "),
    total: `${formatScore(sum("scoreValue"))} / ${formatScore(sum("maxValue"))}`,
    grading: "Scores: this page's check of each lab (kit-grade's checks, references and tolerances, compiled to " +
             `WebAssembly), on your files in this browser, rendered at 256x192 with ${gl}, in ${seconds.toFixed(0)} s. ` +
             "Each lab's pages show every check: your render, the reference and the difference (|yours - reference| " +
             "x 16, inferno colour map). A preview: the grade that counts is the one your instructor runs on your " +
             "submission.",
    timing: `Frame time: this page renders your stage on the default scene at ${TIMING.width}x${TIMING.height}, ` +
            `${TIMING.frames} frames, each timed from the start of the geometry pass until the GPU has finished. ` +
            `The first frame (which holds the shader compilation of the driver) is dropped and the median of the other ` +
            `${TIMING.frames - 1} is shown. Renderer: ${gl}. The times depend on the computer, the browser and what ` +
            "else runs: compare them with times taken on the same computer.",
    grader_note: null,
    labs,
    notes_html: new MarkdownIt("commonmark", {html: false}).enable("table").render(notesText() || "*(no notes written)*"),
    notes_source: "the notes written in the page",
  };
}

// The report in the page's frame, and in a tab of its own (kitPage.lastReport.url).
function show(page, html) {
  const old = page.kitPage.lastReport;
  if (old && old.url) URL.revokeObjectURL(old.url);
  const url = URL.createObjectURL(new Blob([html], {type: "text/html"}));
  $("report-frame").srcdoc = html;
  $("report-open").href = url;
  $("report-result").hidden = false;
  $("report-print").disabled = false;
  return url;
}

export async function makeReport(page) {
  compileEdits(page);
  if (!canDraw(page)) return;
  const status = $("report-status");
  const stages = page.ui.catalogue.stages.filter((s) => hasLabs(page, s) && !missingEarlier(page, s));
  $("make-report").disabled = true;
  const started = performance.now();
  const labs = [];
  try {
    for (const stage of stages) {
      // The references and the lab's scenes, fetched once a visit, as Check my lab does.
      await loadCheckFiles(page, stage.number, (received, total) => {
        status.textContent = checkFilesMessage(received, total);
      });
      status.textContent = `Lab ${stage.number} (${labs.length + 1} of ${stages.length}): checking your files\u2026`;
      await pause();  // the message shows before kit-web takes the main thread
      const answer = kitCall({cmd: "check", lab: stage.number});
      const timing = answer.status === "graded" ? timeLab(stage)
        : {frame_ms: null, frame_error: answer.error || "the lab did not render in the check"};
      labs.push({...labFields(page.FS, stage, answer, timing), scoreValue: answer.score || 0,
                 maxValue: answer.max_score || 0});
    }
  } finally {
    configure(page, "your frame", true);  // the check and the timing drew into the canvas
    $("make-report").disabled = false;
  }
  const seconds = (performance.now() - started) / 1000;
  const {MarkdownIt, Mustache, TEMPLATE} = await reportLibs();
  const fields = reportFields(page, labs, seconds, MarkdownIt);
  const html = Mustache.render(TEMPLATE, fields);
  const url = show(page, html);
  page.kitPage.lastReport = {html, url, seconds, fields,
                             labs: labs.map((l) => ({number: l.number, stage: l.stage, score: l.score}))};
  status.textContent = `Made in ${seconds.toFixed(0)} s: ${labs.length} labs, total ${fields.total}. Print it or ` +
                       "save it as PDF below (your browser's print dialog: Save as PDF).";
}

export function wireReport(page) {
  $("make-report").disabled = false;
  $("make-report").addEventListener("click", () => makeReport(page));
  $("report-print").addEventListener("click", () => $("report-frame").contentWindow.print());
}
