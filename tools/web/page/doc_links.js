// A document named in the page's text ("See handouts/02-lighting.md#common-mistakes", as the
// grader writes it) as a link that opens the handout pane at that section (handout.js
// handles every a[data-doc] of the page). Only the documents the site holds (doc/index.json)
// become links; until the pane has loaded that list, any handouts/ or docs/ name does.
const NAMED = /\b((?:handouts|docs)\/[A-Za-z0-9_.-]+\.md)(?:#([A-Za-z0-9_-]+))?/g;

export function docLink(doc, anchor, text) {
  const a = document.createElement("a");
  a.href = `doc/${doc.replace(/\.md$/, ".html")}${anchor ? "#" + anchor : ""}`;
  a.dataset.doc = doc;
  if (anchor) a.dataset.anchor = anchor;
  a.textContent = text;
  return a;
}

// `text` as a fragment: plain text, and links where it names a document the site holds.
export function docLinks(page, text) {
  const known = page.handout.known, fragment = document.createDocumentFragment();
  let last = 0;
  for (const match of String(text).matchAll(NAMED)) {
    if (known && !known.has(match[1])) continue;
    fragment.append(text.slice(last, match.index), docLink(match[1], match[2], match[0]));
    last = match.index + match[0].length;
  }
  fragment.append(String(text).slice(last));
  return fragment;
}
