// node licenses.mjs META.json... OUT.txt: the licence of every npm package esbuild bundled into
// the page's scripts (each --metafile names the files it read), one after the other, for the
// site to carry beside them (tools/web/CMakeLists.txt runs this after esbuild).
import {existsSync, readFileSync, readdirSync, writeFileSync} from "node:fs";
import {dirname, join, resolve} from "node:path";

const metaFiles = process.argv.slice(2, -1), outFile = process.argv[process.argv.length - 1];
const packages = new Map();  // name -> folder
for (const metaFile of metaFiles) {
  const meta = JSON.parse(readFileSync(metaFile, "utf8"));
  for (const input of Object.keys(meta.inputs)) {
    const m = /^(.*node_modules\/)((?:@[^/]+\/)?[^/]+)\//.exec(input);
    if (m) packages.set(m[2], resolve(dirname(metaFile), m[1] + m[2]));
  }
}
let text = "kit-page.js, kit-report.js and kit-draco.js (with kit-draco-decoder.wasm, draco3d's own build), the kit's page " +
           "scripts, bundle these npm packages; their licences follow.\n";
for (const [name, folder] of [...packages].sort()) {
  const info = JSON.parse(readFileSync(join(folder, "package.json"), "utf8"));
  const file = existsSync(folder) ? readdirSync(folder).find((f) => /^(licen[cs]e|copying)/i.test(f)) : undefined;
  text += `\n==== ${name} ${info.version} (${info.license || "licence not stated"}) ====\n\n`;
  // A package without a licence file of its own (draco3d): the text of the licence it states,
  // from the system's common licences (Debian's and Ubuntu's base-files), where they hold it.
  const spdx = /^[A-Za-z0-9.+-]+$/.test(info.license || "");
  const common = spdx ? join("/usr/share/common-licenses", info.license) : "";
  if (file) text += readFileSync(join(folder, file), "utf8").trim() + "\n";
  else if (common && existsSync(common))
    text += `(the package has no licence file: the text of ${info.license}, from ${common})\n\n` +
            readFileSync(common, "utf8").trim() + "\n";
  else text += "(no licence file in the package)\n";
}
writeFileSync(outFile, text);
