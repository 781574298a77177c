// The editor's tabs: the files of the lab shown (the student's, or a finished lab's solution,
// read only), which one is open, and their marks (edited, does not compile). A compile
// error goes to the lines it names, in the editor and as "Go to" buttons under the message.
import {byPath, parseDiagnostics} from "./diagnostics.js";
import {hasLabs} from "./kit.js";
import {say} from "./messages.js";
import {$} from "./state.js";

const SOLUTION_NOTE = "The frame shows the reference solution; your edits are kept and drawn when you choose " +
                      "\"my lab files\".";

// The files the editor shows for the stage: the student's (labs/NN-name/), or, where the
// site has no labs/ folder of that lab (a lab that is over), its solution, read only.
function stageFiles(page) {
  const stage = page.ui.stage;
  if (hasLabs(page, stage))
    return stage.files.map((f) => ({path: `/kit/labs/${stage.folder}/${f.name}`, name: f.name, readOnly: false}));
  if (stage.solution)
    return stage.files.map((f) => ({path: `/kit/solutions/${stage.folder}/${f.name}`, name: f.name, readOnly: true}));
  return [];
}

function fileText(page, file) {
  if (page.labs.has(file.path)) return page.labs.text(file.path);
  try {
    return page.FS.readFile(file.path, {encoding: "utf8"});
  } catch (e) {
    return `// ${file.path}: ${e.message || e}`;
  }
}

export function openStageFiles(page) {
  page.files = stageFiles(page);
  const stage = page.ui.stage, files = page.files;
  const heading = $("editor-heading");
  if (!files.length) heading.textContent = `Lab ${stage.number}: no files in this site`;
  else if (files[0].readOnly) heading.textContent = `Lab ${stage.number}'s reference solution (read only)`;
  else heading.textContent = `Your files of lab ${stage.number}: labs/${stage.folder}/`;
  if (!files.some((f) => f.path === page.path)) page.path = files.length ? files[0].path : null;
  renderTabs(page);
  if (page.path) showFile(page, page.path);
  $("reset-file").disabled = !page.path || files[0].readOnly;
  if (page.ui.solution && files.length && !files[0].readOnly) {
    say(page, SOLUTION_NOTE);
  } else if (page.kitPage.messages.at(-1) === SOLUTION_NOTE) {
    say(page, "");
  }
}

function renderTabs(page) {
  const tabs = $("tabs");
  tabs.replaceChildren();
  for (const file of page.files) {
    const tab = document.createElement("button");
    tab.type = "button";
    tab.setAttribute("role", "tab");
    tab.id = "tab-" + file.name.replace(/\W/g, "-");
    tab.dataset.path = file.path;
    tab.setAttribute("aria-controls", "editor");
    tab.addEventListener("click", () => showFile(page, file.path));
    tab.addEventListener("keydown", (e) => {
      const files = page.files;
      const i = files.indexOf(file);
      const to = {ArrowRight: i + 1, ArrowLeft: i - 1, Home: 0, End: files.length - 1}[e.key];
      if (to === undefined) return;
      e.preventDefault();
      const next = files[(to + files.length) % files.length];
      showFile(page, next.path);
      document.querySelector(`[role="tab"][data-path="${next.path}"]`).focus();
    });
    tabs.append(tab);
  }
  markTabs(page);
}

export function markTabs(page) {
  for (const tab of document.querySelectorAll('#tabs [role="tab"]')) {
    const path = tab.dataset.path;
    const name = path.split("/").pop();
    const selected = path === page.path;
    const edited = page.labs.edited(path), broken = page.compileErrors.has(path);
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

function showFile(page, path) {
  const file = page.files.find((f) => f.path === path);
  if (!file) return;
  page.path = path;
  const label = path.replace(/^\/kit\//, "");
  page.editor.show(path, fileText(page, file), file.readOnly, label);
  if (page.compileErrors.has(path)) page.editor.setDiagnostics(path, page.compileErrors.get(path));
  $("editor").setAttribute("aria-labelledby", $("tabs").querySelector(`[data-path="${path}"]`)?.id || "editor-heading");
  markTabs(page);
}

export function showCompileError(page, error) {
  const editor = page.editor;
  const diagnostics = parseDiagnostics(error);
  const grouped = byPath(diagnostics);
  for (const path of page.compileErrors.keys())
    if (!grouped.has(path) && editor.has(path)) editor.setDiagnostics(path, []);
  page.compileErrors = grouped;
  for (const [path, list] of grouped) if (editor.has(path)) editor.setDiagnostics(path, list);
  markTabs(page);
  const where = [...grouped.keys()].map((p) => p.replace(/^\/kit\//, "")).join(", ");
  const actions = diagnostics.filter((d) => page.files.some((f) => f.path === d.path)).slice(0, 4).map((d) => ({
    label: `Go to ${d.path.split("/").pop()} line ${d.line}`,
    run: () => {
      showFile(page, d.path);
      editor.goto(d.line);
    },
  }));
  say(page, `Does not compile${where ? " (" + where + ")" : ""}: the frame shows your last good version.`, "error",
      error, actions);
}

export function clearCompileErrors(page) {
  for (const path of page.compileErrors.keys()) if (page.editor.has(path)) page.editor.setDiagnostics(path, []);
  page.compileErrors = new Map();
  markTabs(page);
}
