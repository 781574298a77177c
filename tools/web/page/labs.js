// The student's lab files: every file under /kit/labs/NN-name/ in kit-web's file system
// (the starters the site packs), the text the student has now, and its copy in this
// browser's localStorage, one key per file path, kept on every keystroke. A stored text
// goes into the file system before kit-web draws anything (LabFiles.restore), so the first
// frame already draws it. A text equal to the starter is not stored.
import {strToU8, zipSync} from "fflate";

const LABS = "/kit/labs";
// One site's edits apart from another's on the same host (a course page with two sites).
export const KEY = "kit-web:" + window.location.pathname.replace(/[^/]*$/, "") + ":";
// The edited paths kit-web is drawing: those a load restored, until it draws its first frame,
// then a stage's while kit-web draws an edit of it or checks it. A load that never got past
// that (a shader that locked the tab, or the tab closed by its student) leaves them, and the
// next load starts without those edits.
const DRAWING = KEY + "restoring";
// An edit held back so: its text, kept to look at and fix, no longer restored.
const HELD = KEY + "held:";

export class LabFiles {
  constructor(FS) {
    this.FS = FS;
    this.starters = new Map();  // path -> the starter text, as the site packs it
    this.texts = new Map();     // path -> the text now
    this.storageProblem = "";   // why this browser keeps nothing, when it does not
    for (const folder of this.list(LABS).sort()) {
      for (const name of this.list(`${LABS}/${folder}`).sort()) {
        const path = `${LABS}/${folder}/${name}`;
        const text = FS.readFile(path, {encoding: "utf8"});
        this.starters.set(path, text);
        this.texts.set(path, text);
      }
    }
  }

  list(dir) {
    try {
      return this.FS.readdir(dir).filter((name) => name !== "." && name !== "..");
    } catch (e) {
      return [];
    }
  }

  has(path) { return this.starters.has(path); }
  paths() { return [...this.starters.keys()]; }
  folders() { return [...new Set(this.paths().map((p) => p.split("/")[3]))]; }
  filesOf(folder) { return this.paths().filter((p) => p.split("/")[3] === folder).map((p) => p.split("/")[4]); }
  text(path) { return this.texts.get(path); }
  starter(path) { return this.starters.get(path); }
  edited(path) { return this.has(path) && this.texts.get(path) !== this.starters.get(path); }

  // Writes the stored edits into the file system; the paths restored. The edits the last load
  // restored without reaching its first frame are held back instead (this.heldBack).
  restore() {
    const restored = [];
    this.heldBack = [];
    const unfinished = this.storage((s) => JSON.parse(s.getItem(DRAWING) || "[]")) || [];
    for (const path of this.paths()) {
      const stored = this.storage((s) => s.getItem(KEY + path));
      if (stored === null || stored === this.starters.get(path)) continue;
      if (unfinished.includes(path)) {
        this.storage((s) => {
          s.setItem(HELD + path, stored);
          s.removeItem(KEY + path);
        });
        this.heldBack.push(path);
        continue;
      }
      this.texts.set(path, stored);
      this.writeFS(path);
      restored.push(path);
    }
    this.storage((s) => restored.length ? s.setItem(DRAWING, JSON.stringify(restored)) : s.removeItem(DRAWING));
    return restored;
  }

  // draw() with the edited files of lab `folder` marked while it runs (kit-web drawing an edit
  // or checking the lab): its answer.
  whileDrawing(folder, draw) {
    const edited = this.paths().filter((p) => p.split("/")[3] === folder && this.edited(p));
    this.storage((s) => s.setItem(DRAWING, JSON.stringify(edited)));
    try {
      return draw();
    } finally {
      this.drawingDone();
    }
  }

  // The first frame, or the marked draw, is over (drawn or refused with a message): those edits
  // did not lock the tab.
  drawingDone() { this.storage((s) => s.removeItem(DRAWING)); }

  // The text of an edit held back (restore), as it was kept.
  heldText(path) { return this.storage((s) => s.getItem(HELD + path)); }

  // f(localStorage), or null where the browser refuses it (storageProblem says why).
  storage(f) {
    try {
      return f(window.localStorage);
    } catch (e) {
      this.storageProblem = String(e.message || e);
      return null;
    }
  }

  // The text now, kept in this browser; false when the browser refused to keep it.
  set(path, text) {
    this.texts.set(path, text);
    const kept = this.storage((s) => {
      if (text === this.starters.get(path)) s.removeItem(KEY + path);
      else s.setItem(KEY + path, text);
      return true;
    });
    if (kept) this.storageProblem = "";
    return kept === true;
  }

  writeFS(path) { this.FS.writeFile(path, this.texts.get(path)); }

  // Every lab file, edited or not, as labs/NN-name/FILE: the layout ./kit grade takes; and
  // `extra` ({name: text}), files beside labs/ (the progress notes, notes.js).
  zip(extra = {}) {
    const entries = {};
    for (const [name, text] of Object.entries(extra)) entries[name] = strToU8(text);
    for (const path of this.paths()) entries[path.replace(/^\/kit\//, "")] = strToU8(this.texts.get(path));
    return zipSync(entries, {level: 6});
  }
}
