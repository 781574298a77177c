// node licenses.mjs META.json OUT.txt: the licence of every npm package esbuild bundled into
// kit-page.js (its --metafile names the files it read), one after the other, for the site to
// carry beside the script (tools/web/CMakeLists.txt runs this after esbuild).
import {existsSync, readFileSync, readdirSync, writeFileSync} from "node:fs";
import {dirname, join, resolve} from "node:path";

const [metaFile, outFile] = process.argv.slice(2);
const meta = JSON.parse(readFileSync(metaFile, "utf8"));
const packages = new Map();  // name -> folder
for (const input of Object.keys(meta.inputs)) {
  const m = /^(.*node_modules\/)((?:@[^/]+\/)?[^/]+)\//.exec(input);
  if (m) packages.set(m[2], resolve(dirname(metaFile), m[1] + m[2]));
}
let text = "kit-page.js, the kit's page script, bundles these npm packages; their licences follow.\n";
for (const [name, folder] of [...packages].sort()) {
  const info = JSON.parse(readFileSync(join(folder, "package.json"), "utf8"));
  const file = existsSync(folder) ? readdirSync(folder).find((f) => /^(licen[cs]e|copying)/i.test(f)) : undefined;
  text += `\n==== ${name} ${info.version} (${info.license || "licence not stated"}) ====\n\n`;
  text += file ? readFileSync(join(folder, file), "utf8").trim() + "\n" : "(no licence file in the package)\n";
}
writeFileSync(outFile, text);
