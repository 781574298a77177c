// The student's labs outside this browser: "Download my labs" (a zip in the layout ./kit grade
// takes) and "Open folder" (the File System Access API), which reads the kit's labs/ folder on
// the student's computer, saves the edits into it (edits.js) and takes the changes made there
// in another editor.
import {compileEdits, saveToFolder} from "./edits.js";
import {kitCall} from "./kit.js";
import {say} from "./messages.js";
import {NOTES_FILE, notesFiles} from "./notes.js";
import {$} from "./state.js";
import {markTabs} from "./tabs.js";
import {drawn} from "./view.js";

export function download(page) {
  compileEdits(page);
  const notes = notesFiles();
  const bytes = page.labs.zip(notes);
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
      "course platform take" + (notes[NOTES_FILE] ? `, and your notes as ${NOTES_FILE}.` : "."));
}

export async function openFolder(page) {
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
