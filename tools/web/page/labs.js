// The student's lab files: every file under /kit/labs/NN-name/ in kit-web's file system
// (the starters the site packs), the text the student has now, and its copy in this
// browser's localStorage, one key per file path, kept on every keystroke. A stored text
// goes into the file system before kit-web draws anything (LabFiles.restore), so the first
// frame already draws it. A text equal to the starter is not stored.
import {strToU8, zipSync} from "fflate";

const LABS = "/kit/labs";
// One site's edits apart from another's on the same host (a course page with two sites).
const KEY = "kit-web:" + window.location.pathname.replace(/[^/]*$/, "") + ":";

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

  // Writes the stored edits into the file system; the paths restored.
  restore() {
    const restored = [];
    for (const path of this.paths()) {
      let stored = null;
      try {
        stored = window.localStorage.getItem(KEY + path);
      } catch (e) {
        this.storageProblem = String(e.message || e);
      }
      if (stored !== null && stored !== this.starters.get(path)) {
        this.texts.set(path, stored);
        this.writeFS(path);
        restored.push(path);
      }
    }
    return restored;
  }

  // The text now, kept in this browser; false when the browser refused to keep it.
  set(path, text) {
    this.texts.set(path, text);
    try {
      if (text === this.starters.get(path)) window.localStorage.removeItem(KEY + path);
      else window.localStorage.setItem(KEY + path, text);
      this.storageProblem = "";
      return true;
    } catch (e) {
      this.storageProblem = String(e.message || e);
      return false;
    }
  }

  writeFS(path) { this.FS.writeFile(path, this.texts.get(path)); }

  // Every lab file, edited or not, as labs/NN-name/FILE: the layout ./kit grade takes.
  zip() {
    const entries = {};
    for (const path of this.paths()) entries[path.replace(/^\/kit\//, "")] = strToU8(this.texts.get(path));
    return zipSync(entries, {level: 6});
  }
}
