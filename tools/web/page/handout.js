// The handout pane (#handout-panel): the current lab's handout beside the editor and the
// frame, and the other documents it links to, rendered at build time (render_docs.mjs) into
// doc/. Opened and closed by its button (kept in this browser); it loads nothing, not even
// KaTeX's style sheet, until it is first opened. It follows the lab chosen; a link to another
// document, anywhere in the page (doc_links.js), opens that document at its section; a link
// to a view (`index.html?stage=...`, the handouts' "In the browser") sets the controls to it.
import {findStage} from "./kit.js";
import {$} from "./state.js";

const OPEN_KEY = "kit-handout-open";
const ID_PREFIX = "doc:";  // the documents' ids, apart from the page's own (a "Check" section)

const labHandout = (page) => `handouts/${page.ui.stage.folder}.md`;

function setOpen(page, open) {
  page.handout.open = open;
  document.body.classList.toggle("handout-open", open);
  $("handout-panel").hidden = !open;
  $("handout-toggle").setAttribute("aria-expanded", String(open));
  try {
    localStorage.setItem(OPEN_KEY, open ? "1" : "0");
  } catch (e) {
    // A browser that keeps nothing: the pane starts closed next time.
  }
}

async function loadIndex(page) {
  if (page.handout.index) return page.handout.index;
  // KaTeX's style sheet, and through it its fonts, and the documents' own.
  for (const href of ["doc/katex/katex.min.css", "kit-doc.css"]) {
    document.head.append(Object.assign(document.createElement("link"), {rel: "stylesheet", href}));
  }
  const response = await fetch("doc/index.json");
  if (!response.ok) throw new Error(`doc/index.json: ${response.status} ${response.statusText}`);
  const index = (await response.json()).documents;
  const select = $("handout-doc");
  select.replaceChildren(...index.map((d) => Object.assign(document.createElement("option"),
                                                          {value: d.path, textContent: `${d.title} (${d.path})`})));
  page.handout.known = new Set(index.map((d) => d.path));
  page.handout.index = index;
  return index;
}

function showSection(anchor) {
  const target = anchor ? document.getElementById(ID_PREFIX + anchor) : null;
  if (target) {
    target.scrollIntoView({block: "start"});
    target.focus({preventScroll: true});
  } else {
    $("handout-body").scrollTop = 0;
  }
}

// Opens the pane at `doc` (its path, handouts/NN-name.md), at the section `anchor`.
export async function openDoc(page, doc, anchor = "") {
  setOpen(page, true);
  const body = $("handout-body"), state = page.handout;
  try {
    await loadIndex(page);
    if (!state.known.has(doc)) throw new Error(`${doc} is not among this site's documents`);
    if (state.doc !== doc) {
      const response = await fetch(`doc/${doc.replace(/\.md$/, ".html")}`);
      if (!response.ok) throw new Error(`${doc}: ${response.status} ${response.statusText}`);
      const parsed = new DOMParser().parseFromString(await response.text(), "text/html");
      const article = parsed.querySelector("article.doc");
      if (!article) throw new Error(`${doc}: no document in the file`);
      for (const e of article.querySelectorAll("[id]")) e.id = ID_PREFIX + e.id;
      body.replaceChildren(document.adoptNode(article));
      state.doc = doc;
      $("handout-doc").value = doc;
    }
    showSection(anchor);
    document.body.dataset.handout = `${doc}#${anchor}`;  // what is shown, for the page's test
  } catch (e) {
    body.replaceChildren(Object.assign(document.createElement("p"), {
      className: "error", textContent: `The handout could not be shown: ${e.message || e}`}));
  }
}

// A link to a view: the controls set to it as if the student had chosen each, in order.
function setControl(id, value) {
  const control = $(id);
  if (!value || ![...control.options].some((o) => o.value === value && !o.disabled)) return;
  if (control.value === value) return;
  control.value = value;
  control.dispatchEvent(new Event("change"));
}

export function openView(page, query) {
  const params = new URLSearchParams(query);
  const stage = params.get("stage") && findStage(page, params.get("stage"));
  if (stage) setControl("stage", stage.name);
  const shaders = {labs: "shaders-labs", solution: "shaders-solution"}[params.get("shaders")];
  if (shaders && !$(shaders).disabled && !$(shaders).checked) {
    $(shaders).checked = true;
    $(shaders).dispatchEvent(new Event("change"));
  }
  for (const key of ["scene", "view", "size"]) setControl(key, params.get(key));
  $("canvas").focus({preventScroll: true});
  $("frame-panel").scrollIntoView({block: "nearest"});
}

export function wireHandout(page) {
  $("handout-toggle").disabled = false;
  $("handout-toggle").addEventListener("click", () => {
    if (page.handout.open) setOpen(page, false);
    else openDoc(page, page.handout.doc || labHandout(page)).then(() => $("handout-panel").focus());
  });
  $("handout-close").addEventListener("click", () => {
    setOpen(page, false);
    $("handout-toggle").focus();
  });
  $("handout-doc").addEventListener("change", () => openDoc(page, $("handout-doc").value));
  // Every link to a document or a view, in the pane or elsewhere in the page.
  document.addEventListener("click", (event) => {
    const link = event.target.closest && event.target.closest("a[data-doc], a[data-view]");
    if (!link || event.ctrlKey || event.metaKey || event.shiftKey || event.button !== 0) return;
    event.preventDefault();
    if (link.dataset.view) openView(page, link.dataset.view);
    else openDoc(page, link.dataset.doc, link.dataset.anchor || "");
  });
  $("stage").addEventListener("change", () => {
    if (page.handout.open) openDoc(page, labHandout(page));
    else page.handout.doc = "";
  });
  let open = false;
  try {
    open = localStorage.getItem(OPEN_KEY) === "1";
  } catch (e) {
    open = false;
  }
  if (open) openDoc(page, labHandout(page));
}
