// The student's own model, dropped on the page or picked with "Your model": its files go into
// kit-web's file system and it becomes a scene of the Scene list. kit-web reads what the
// desktop's loader reads, with the same code: glTF (.gltf with its .bin and images, or .glb)
// and Wavefront OBJ with its MTL and textures (common/scene/obj_scene.h), Draco-compressed glTF
// through Google's decoder, loaded when such a model comes (draco_libs.js). The files may come
// one by one, as a dropped folder, or in a .zip; a model it cannot draw leaves the scene as
// it was.
import {unzipSync} from "fflate";

import {fillScenes} from "./controls.js";
import {configureCommand, fsExists, kitCall} from "./kit.js";
import {lazyScript} from "./lazy_script.js";
import {say} from "./messages.js";
import {$} from "./state.js";
import {canDraw, configure, fitCanvas} from "./view.js";

// What a dropped zip may inflate to, all its files together: the loader's own limit for one
// file (1 GiB) would not fit in the tab's memory beside the kit.
const MAX_ZIP_BYTES = 512 * 1024 * 1024;
const MODEL = /\.(glb|gltf|obj)$/i;

// A path inside the drop, as the loader will see it under the drop's folder: forward slashes,
// no empty, "." or ".." parts (a name the loader then refuses could not reach outside anyway).
function cleanPath(path) {
  const parts = path.replace(/\\/g, "/").split("/").filter((p) => p && p !== ".");
  if (parts.includes("..")) throw new Error(`${path}: a name in the drop climbs out of it ("..")`);
  return parts.join("/");
}

// A dropped zip's files, each [path, bytes], under the zip's own folder-less names.
function unzipped(name, bytes) {
  let total = 0;
  const entries = unzipSync(bytes, {
    filter: (f) => {
      if (f.name.endsWith("/") || f.name.startsWith("__MACOSX/")) return false;
      total += f.originalSize;
      if (total > MAX_ZIP_BYTES)
        throw new Error(`${name} holds more than ${MAX_ZIP_BYTES >> 20} MiB of files: drop the model's files instead`);
      return true;
    },
  });
  return Object.entries(entries).map(([path, data]) => [cleanPath(path), data]).filter(([path]) => path);
}

// The files of a dropped folder, each [path, File] with the folder's name in front.
async function folderFiles(entry) {
  if (entry.isFile) return [[entry.fullPath, await new Promise((ok, fail) => entry.file(ok, fail))]];
  const reader = entry.createReader();
  const out = [];
  for (;;) {
    const batch = await new Promise((ok, fail) => reader.readEntries(ok, fail));
    if (!batch.length) return out;
    for (const child of batch) out.push(...await folderFiles(child));
  }
}

// Every file of the drop or the pick as [path, bytes]: zips unpacked, folders walked.
async function readAll(sources) {
  const out = [];
  for (const source of sources) {
    const listed = source.isDirectory ? await folderFiles(source) : [[source.name, source]];
    for (const [path, file] of listed) {
      const bytes = new Uint8Array(await file.arrayBuffer());
      if (/\.zip$/i.test(path)) out.push(...unzipped(file.name, bytes));
      else if (cleanPath(path)) out.push([cleanPath(path), bytes]);
    }
  }
  return out;
}

// The model among the files: a glTF before an OBJ, then the shortest path (the folder's top).
function mainModel(paths) {
  const rank = (p) => [/\.obj$/i.test(p) ? 1 : 0, p.split("/").length, p];
  return paths.filter((p) => MODEL.test(p)).sort((a, b) => {
    const [x, y] = [rank(a), rank(b)];
    return x[0] - y[0] || x[1] - y[1] || (x[2] < y[2] ? -1 : 1);
  })[0];
}

// A glTF's JSON: a .gltf's text, or a .glb's first chunk (glTF 2.0, GLB: a 12-byte header,
// then the JSON chunk's length and type).
function gltfJson(path, bytes) {
  if (/\.gltf$/i.test(path)) return JSON.parse(new TextDecoder().decode(bytes));
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (bytes.byteLength < 20 || view.getUint32(0, true) !== 0x46546c67 || view.getUint32(16, true) !== 0x4e4f534a)
    return null;  // the loader says what is wrong with it
  return JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + view.getUint32(12, true))));
}

// The page's Draco decoder (draco_libs.js), loaded once, at the first model that needs it.
let draco = null;
function loadDraco() {
  draco = draco || lazyScript("kit-draco.js", "kitCreateDraco").then((create) => create("kit-draco-decoder.wasm"))
    .then((decoder) => {
      window.Module.kitDraco = decoder;
      return decoder;
    }, (e) => {
      draco = null;  // the next model tries again
      throw e;
    });
  return draco;
}

// A .gltf's buffers and images (its JSON: gltfJson) that the drop does not hold.
function missingGltfFiles(page, dir, path, gltf) {
  const folder = path.includes("/") ? path.slice(0, path.lastIndexOf("/") + 1) : "";
  return [...(gltf.buffers || []), ...(gltf.images || [])].map((x) => x.uri)
    .filter((u) => u && !u.startsWith("data:")).map((u) => decodeURIComponent(u))
    .filter((u) => !fsExists(page, `${dir}/${folder}${u}`));
}

async function loadModel(page, sources) {
  if (!sources.length) return;
  const ui = page.ui;
  let files;
  try {
    files = await readAll(sources);
  } catch (e) {
    say(page, `Your model could not be read: ${e.message || e}`, "error");
    return;
  }
  const main = mainModel(files.map(([path]) => path));
  if (!main) {
    say(page, `Not a model: ${files.map(([p]) => p).join(", ") || "no files"}. Drop a .glb, a .gltf with its .bin ` +
        "and images, or an .obj with its .mtl and textures (the files, their folder or a .zip of them).", "error");
    return;
  }
  const name = main.split("/").pop();
  page.droppedCount += 1;
  const dir = `/work/dropped/${page.droppedCount}`;
  for (const [path, bytes] of files) {
    page.FS.mkdirTree(`${dir}/${path}`.replace(/\/[^/]*$/, ""));
    page.FS.writeFile(`${dir}/${path}`, bytes);
  }
  // The glTF's JSON, read once: the files a .gltf needs, and whether the Draco decoder is.
  let json = null;
  if (/\.(gltf|glb)$/i.test(main)) {
    const gltf = /\.gltf$/i.test(main);
    try {
      json = gltfJson(main, files.find(([p]) => p === main)[1]);
      const missing = gltf ? missingGltfFiles(page, dir, main, json) : [];
      if (missing.length) {
        say(page, `${name} needs ${missing.join(", ")}: drop or pick them together with it.`, "error");
        return;
      }
    } catch (e) {
      if (gltf) {
        say(page, `${name} is not glTF's JSON: ${e.message || e}`, "error");
        return;
      }
      json = null;  // a .glb's chunk that does not parse: the loader says what is wrong with it
    }
  }
  // A Draco-compressed model: the decoder first (kit-web's loader calls it: draco_mesh_web.cpp).
  if (json && (json.extensionsUsed || []).includes("KHR_draco_mesh_compression")) {
    try {
      say(page, `${name} is Draco-compressed: loading the page's Draco decoder\u2026`);
      await loadDraco();
    } catch (e) {
      say(page, `${name} is Draco-compressed, and the page could not load its Draco decoder: ${e.message || e}. ` +
          "Reload the page, or export the model without mesh compression.", "error");
      return;
    }
  }
  const previous = ui.scene;
  ui.scene = `${dir}/${main}`;
  if (!canDraw(page)) {
    ui.scene = previous;
    return;
  }
  if (configure(page, name)) {
    page.droppedScenes.push({path: ui.scene, label: name});
    fillScenes(page);
    // What the loader left out, as the desktop's tools print it (a missing .mtl or texture).
    const warnings = (page.lastAnswer && page.lastAnswer.scene_warnings) || [];
    if (warnings.length)
      say(page, `Drawing your model ${name}, without what its loader left out:`, "", warnings.join("\n"));
    else say(page, `Drawing your model ${name}.`, "ok");
  } else {
    // kit-web keeps the scene it was given: back to the one before, the message kept.
    ui.scene = previous;
    fillScenes(page);
    const why = page.kitPage.lastError;
    if (!kitCall(configureCommand(page)).error) fitCanvas(page);
    say(page, `${name} could not be drawn: ${why}`, "error");
  }
}

// Files dragged over the page show the drop overlay; dropped or picked, they are loaded.
export function wireModels(page) {
  $("model-file").addEventListener("change", () => {
    const files = [...$("model-file").files];
    $("model-file").value = "";
    loadModel(page, files);
  });
  const overlay = $("drop-overlay");
  let depth = 0;
  const hasFiles = (e) => e.dataTransfer && [...e.dataTransfer.types].includes("Files");
  window.addEventListener("dragenter", (e) => {
    if (!hasFiles(e)) return;
    depth += 1;
    overlay.hidden = false;
  });
  window.addEventListener("dragleave", () => {
    depth = Math.max(0, depth - 1);
    if (!depth) overlay.hidden = true;
  });
  window.addEventListener("dragover", (e) => {
    if (hasFiles(e)) e.preventDefault();
  });
  window.addEventListener("drop", (e) => {
    depth = 0;
    overlay.hidden = true;
    if (!e.dataTransfer || !e.dataTransfer.files.length) return;
    e.preventDefault();
    // A dropped folder is an entry to walk; the entries are only there during the event.
    const items = [...e.dataTransfer.items].filter((i) => i.kind === "file");
    const entries = items.map((i) => (i.webkitGetAsEntry ? i.webkitGetAsEntry() : null));
    const sources = entries.some((x) => x && x.isDirectory)
      ? entries.map((x, n) => (x && x.isDirectory ? x : items[n].getAsFile())).filter((x) => x)
      : [...e.dataTransfer.files];
    loadModel(page, sources);
  });
}
