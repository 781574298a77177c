// Build time, not in the page: the students' documents of a kit (handouts/*.md and docs/*.md,
// as the tree holds them: a student copy holds only its own, without instructors' sections)
// rendered to HTML for the page's handout pane (handout.js).
//
//   node render-docs.cjs KIT_ROOT OUT_DIR
//
// OUT_DIR/handouts/NAME.html and OUT_DIR/docs/NAME.html, the images they show (under their own
// paths), KaTeX's style sheet and fonts (OUT_DIR/katex/), and OUT_DIR/index.json (each
// document's path and title). tools/web/CMakeLists.txt bundles this script with esbuild for
// node 12 (Ubuntu 22.04's), as it bundles the page, and runs it for the site; ./kit web
// --student-copy N runs it again on the student copy.
//
// The Markdown is markdown-it's (GitHub's tables), the formulas ($...$, $$...$$) KaTeX's,
// typeset here, so the page runs no TeX; the headings' ids are GitHub's (github-slugger), so
// the links the documents and the grader's messages already use (02-lighting.md#common-mistakes)
// open their sections. Rewritten for the page: a link to another document opens it in the pane
// (data-doc, data-anchor), a link to a file of the kit the site does not hold becomes its path
// (class kit-path), and a quoted page address (`index.html?stage=lighting&shaders=labs`) a link
// to that view (data-view). A bad formula, a missing image or a link to a section that no
// heading has fails the build, naming the file and line.
// node 12 has no Array.prototype.at, which the math plug-in calls: core-js's, where it is missing.
import "core-js/actual/array/at";
import katexPlugin from "@vscode/markdown-it-katex";
import {slug} from "github-slugger";
import katex from "katex";
import MarkdownIt from "markdown-it";
import anchor from "markdown-it-anchor";
import fs from "fs";
import path from "path";

const FOLDERS = ["handouts", "docs"];
const VIEW_ADDRESS = /^index\.html\?[A-Za-z0-9_=&.-]+$/;

function fail(message) {
  process.stderr.write(`render_docs: ${message}\n`);
  process.exit(1);
}

const md = new MarkdownIt({html: true, linkify: false, typographer: false});
// The documents hold no HTML blocks, only comments (the checked figures' <!--figure NAME-->
// and the instructors' markers): a line that starts with one stays in its paragraph, so that
// the Markdown after the comment on that line is read as Markdown.
md.disable("html_block");
// A .mjs file imports a CommonJS module as node does: its exports, whose default is the plug-in.
md.use(katexPlugin.default || katexPlugin);  // a formula it cannot typeset: checkFormulas()
md.use(anchor, {slugify: (text) => slug(text), tabIndex: -1});

// A quoted page address becomes the link to that view.
const plainCode = md.renderer.rules.code_inline;
md.renderer.rules.code_inline = (tokens, idx, options, env, self) => {
  const code = plainCode(tokens, idx, options, env, self);
  const content = tokens[idx].content;
  if (!VIEW_ADDRESS.test(content)) return code;
  const query = md.utils.escapeHtml(content.slice("index.html?".length));
  return `<a href="index.html?${query}" data-view="${query}">${code}</a>`;
};

// Every token, the inline ones too, with the source line of the block that holds it.
function* allTokens(tokens) {
  let line = 0;
  for (const token of tokens) {
    if (token.map) line = token.map[0] + 1;
    yield [token, line];
    if (token.children) for (const child of token.children) yield [child, line];
  }
}

// The plug-in prints a formula KaTeX cannot typeset as an error in the page: here it stops
// the build instead, at the formula's line.
function checkFormulas(doc, tokens) {
  for (const [token, line] of allTokens(tokens)) {
    if (!token.type.startsWith("math_")) continue;
    try {
      katex.renderToString(token.content, {displayMode: token.type !== "math_inline", throwOnError: true});
    } catch (e) {
      fail(`${doc}:${line}: a formula KaTeX cannot typeset: ${e.message}`);
    }
  }
}

const isExternal = (href) => /^[a-z][a-z0-9+.-]*:/i.test(href);

// Links and images of one document, rewritten for the page; the sections it links to, to
// check once every document has its ids.
function rewrite(doc, tokens, root, documents, out, sectionLinks) {
  const dir = path.posix.dirname(doc);
  for (const [token, line] of allTokens(tokens)) {
    const where = `${doc}:${line}`;
    if (token.type === "image") {
      const src = token.attrGet("src");
      if (isExternal(src)) fail(`${where}: image ${src}: the site holds only the kit's own images`);
      const file = path.posix.normalize(path.posix.join(dir, decodeURI(src)));
      const from = path.join(root, file);
      if (!fs.existsSync(from)) fail(`${where}: image ${src}: ${file} is missing`);
      fs.mkdirSync(path.join(out, path.dirname(file)), {recursive: true});
      fs.copyFileSync(from, path.join(out, file));
      token.attrSet("src", `doc/${file}`);
      token.attrSet("loading", "lazy");
    } else if (token.type === "link_open") {
      const href = token.attrGet("href");
      if (isExternal(href)) {
        token.attrSet("target", "_blank");
        token.attrSet("rel", "noopener");
        continue;
      }
      const [target, section = ""] = href.split("#");
      const file = target ? path.posix.normalize(path.posix.join(dir, decodeURI(target))) : doc;
      if (documents.has(file)) {
        token.attrSet("href", `doc/${file.replace(/\.md$/, ".html")}${section ? "#" + section : ""}`);
        token.attrSet("data-doc", file);
        if (section) {
          token.attrSet("data-anchor", section);
          sectionLinks.push({where, file, section});
        }
      } else {
        // A file of the kit (a lab file, a tool's source): not in the site.
        token.attrs = [["class", "kit-path"], ["title", `in the kit: ${file}`]];
        token.tag = "span";
        token.kitPath = true;
      }
    } else if (token.type === "link_close") {
      // The span that replaced its link_open closes as a span (markdown-it pairs them in order).
      const opened = token.opener;
      if (opened && opened.kitPath) token.tag = "span";
    }
  }
}

// Pairs every link_close with its link_open, so rewrite() can close a replaced link as a span.
md.core.ruler.push("kit_link_pairs", (state) => {
  for (const block of state.tokens) {
    const open = [];
    for (const t of block.children || []) {
      if (t.type === "link_open") open.push(t);
      else if (t.type === "link_close") t.opener = open.pop();
    }
  }
});

function page(doc, title, body) {
  // <base>: the links and images name their paths from the site's folder, as the pane needs;
  // the file opened on its own resolves them the same way.
  const depth = doc.split("/").length;
  return `<!doctype html>\n<html lang="en"><head><meta charset="utf-8"><base href="${"../".repeat(depth)}">\n` +
         `<title>${md.utils.escapeHtml(title)}</title>\n<link rel="stylesheet" href="doc/katex/katex.min.css">\n` +
         `<link rel="stylesheet" href="kit-page.css"><link rel="stylesheet" href="kit-doc.css"></head>\n<body><article class="doc" data-doc="${doc}">\n${body}` +
         `</article></body></html>\n`;
}

function copyKatex(out) {
  // The style sheet and its fonts, woff2 only: every browser with WebGL2 reads woff2, so the
  // style sheet's woff and ttf fallbacks are never fetched.
  // Found beside this script's bundle (page-npm/node_modules), as node finds a package.
  const dist = path.join(path.dirname(require.resolve("katex/package.json")), "dist");
  const to = path.join(out, "katex");
  fs.mkdirSync(path.join(to, "fonts"), {recursive: true});
  fs.copyFileSync(path.join(dist, "katex.min.css"), path.join(to, "katex.min.css"));
  fs.copyFileSync(path.join(dist, "..", "LICENSE"), path.join(to, "LICENSE"));
  for (const font of fs.readdirSync(path.join(dist, "fonts")))
    if (font.endsWith(".woff2")) fs.copyFileSync(path.join(dist, "fonts", font), path.join(to, "fonts", font));
}

function main(argv) {
  if (argv.length !== 2) fail("usage: render-docs.cjs KIT_ROOT OUT_DIR");
  const [root, out] = argv.map((p) => path.resolve(p));
  const documents = new Set();
  for (const folder of FOLDERS) {
    const dir = path.join(root, folder);
    if (!fs.existsSync(dir)) continue;
    for (const name of fs.readdirSync(dir).sort())
      if (name.endsWith(".md")) documents.add(`${folder}/${name}`);
  }
  if (!documents.size) fail(`${root}: no handouts/*.md or docs/*.md`);
  fs.rmSync ? fs.rmSync(out, {recursive: true, force: true}) : fs.rmdirSync(out, {recursive: true});
  fs.mkdirSync(out, {recursive: true});

  const index = [], ids = new Map(), sectionLinks = [];
  for (const doc of documents) {
    const env = {};
    const tokens = md.parse(fs.readFileSync(path.join(root, doc), "utf8"), env);
    checkFormulas(doc, tokens);
    rewrite(doc, tokens, root, documents, out, sectionLinks);
    ids.set(doc, new Set(Object.keys(env.markdownItAnchor ? env.markdownItAnchor.slugs : {})));
    const heading = tokens.findIndex((t) => t.type === "heading_open" && t.tag === "h1");
    const title = heading >= 0 ? tokens[heading + 1].content : path.basename(doc, ".md");
    const body = md.renderer.render(tokens, md.options, env);
    const file = path.join(out, doc.replace(/\.md$/, ".html"));
    fs.mkdirSync(path.dirname(file), {recursive: true});
    fs.writeFileSync(file, page(doc, title, body));
    index.push({path: doc, title});
  }
  for (const link of sectionLinks)
    if (!ids.get(link.file).has(link.section)) fail(`${link.where}: link to ${link.file}#${link.section}: no such section`);
  copyKatex(out);
  fs.writeFileSync(path.join(out, "index.json"), JSON.stringify({documents: index}, null, 1) + "\n");
  process.stdout.write(`render_docs: ${index.length} documents of ${root} in ${out}\n`);
}

main(process.argv.slice(2));
