// The student's progress notes (Markdown) and the name on the report, written in the page's
// "Progress report" section: kept in this browser on every keystroke as the lab files are
// (labs.js's keys, one site's apart from another's), and in "Download my labs" as
// progress-notes.md beside labs/, the file ./kit progress-report reads at the kit's root.
import {KEY} from "./labs.js";
import {say} from "./messages.js";
import {$} from "./state.js";

export const NOTES_FILE = "progress-notes.md";
const NOTES_KEY = KEY + "notes:" + NOTES_FILE;
const NAME_KEY = KEY + "notes:student";

function keep(page, field, key) {
  field.value = page.labs.storage((s) => s.getItem(key)) || "";
  field.addEventListener("input", () => {
    const kept = page.labs.storage((s) => {
      if (field.value) s.setItem(key, field.value);
      else s.removeItem(key);
      return true;
    });
    if (!kept)
      say(page, `This browser refused to keep your notes (${page.labs.storageProblem}): use Download my labs ` +
          "before you leave.", "error");
  });
}

export function wireNotes(page) {
  keep(page, $("notes"), NOTES_KEY);
  keep(page, $("student-name"), NAME_KEY);
}

export const notesText = () => $("notes").value;
export const studentName = () => $("student-name").value.trim();

// The notes as a file of "Download my labs": none while they are empty.
export const notesFiles = () => (notesText().trim() ? {[NOTES_FILE]: notesText()} : {});
