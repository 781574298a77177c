// The lab editor: CodeMirror 6 with GLSL highlighting (the legacy clike mode's `shader`) and
// the compiler's errors as lint diagnostics at the student's lines. One EditorView; one
// EditorState per file, kept while the page lives, so each tab keeps its undo history.
import {basicSetup} from "codemirror";
import {EditorState} from "@codemirror/state";
import {EditorView} from "@codemirror/view";
import {StreamLanguage} from "@codemirror/language";
import {shader} from "@codemirror/legacy-modes/mode/clike";
import {forEachDiagnostic, lintGutter, setDiagnostics} from "@codemirror/lint";

const glsl = StreamLanguage.define(shader);

export class LabEditor {
  // onEdit(path, text): the student changed a file's text.
  constructor(parent, onEdit) {
    this.onEdit = onEdit;
    this.states = new Map();
    this.path = null;
    this.silent = false;
    this.view = new EditorView({parent, state: EditorState.create({doc: ""})});
  }

  // path's state, made with `text` the first time.
  state(path, text, readOnly, label) {
    if (!this.states.has(path)) {
      this.states.set(path, EditorState.create({
        doc: text,
        extensions: [
          basicSetup,
          glsl,
          lintGutter(),
          EditorState.readOnly.of(readOnly),
          EditorView.editable.of(!readOnly),
          EditorView.contentAttributes.of({"aria-label": label + (readOnly ? " (read only)" : "")}),
          EditorView.updateListener.of((update) => {
            if (update.docChanged && !this.silent) this.onEdit(path, update.state.doc.toString());
          }),
        ],
      }));
    }
    return this.states.get(path);
  }

  show(path, text, readOnly, label) {
    if (this.path) this.states.set(this.path, this.view.state);
    this.path = path;
    this.view.setState(this.state(path, text, readOnly, label));
  }

  has(path) { return this.states.has(path); }

  // A text from elsewhere (the starter, the student's folder): replaces the document as an
  // edit, so Ctrl+Z brings the text before it back; onEdit is not called.
  setText(path, text) {
    const apply = (state) => state.update({changes: {from: 0, to: state.doc.length, insert: text}});
    this.silent = true;
    try {
      if (path === this.path) {
        if (this.view.state.doc.toString() !== text) this.view.dispatch(apply(this.view.state));
      } else if (this.states.has(path)) {
        const state = this.states.get(path);
        if (state.doc.toString() !== text) this.states.set(path, apply(state).state);
      }
    } finally {
      this.silent = false;
    }
  }

  // diagnostics: [{line, column, message}] of one file; [] clears them.
  setDiagnostics(path, diagnostics) {
    const apply = (state) => {
      const doc = state.doc;
      const list = diagnostics.map((d) => {
        const line = doc.line(Math.min(Math.max(d.line, 1), doc.lines));
        let from = line.from, to = line.to;
        if (d.column > 0 && d.column - 1 < line.length) {
          from = line.from + d.column - 1;
          to = Math.max(from + 1, line.to);
        }
        return {from, to, severity: "error", source: "compiler", message: d.message};
      });
      return setDiagnostics(state, list);
    };
    if (path === this.path) this.view.dispatch(apply(this.view.state));
    else if (this.states.has(path)) {
      const state = this.states.get(path);
      this.states.set(path, state.update(apply(state)).state);
    }
  }

  // [{line, message}] of the diagnostics the editor holds for path (for the page's test).
  diagnostics(path) {
    const state = path === this.path ? this.view.state : this.states.get(path);
    const out = [];
    if (state) forEachDiagnostic(state, (d, from) => out.push({line: state.doc.lineAt(from).number, message: d.message}));
    return out;
  }

  // The cursor to a line of the file shown, scrolled into view.
  goto(lineNumber) {
    const doc = this.view.state.doc;
    const line = doc.line(Math.min(Math.max(lineNumber, 1), doc.lines));
    this.view.dispatch({selection: {anchor: line.from}, effects: EditorView.scrollIntoView(line.from, {y: "center"})});
    this.view.focus();
  }
}
