// The student's own model, dropped on the page or picked with "Your model": its files go into
// kit-web's file system and it becomes a scene of the Scene list. kit-web reads glTF only;
// a model it cannot draw leaves the scene as it was.
import {fillScenes} from "./controls.js";
import {configureCommand, fsExists, kitCall} from "./kit.js";
import {say} from "./messages.js";
import {$} from "./state.js";
import {canDraw, configure, fitCanvas} from "./view.js";

async function loadModel(page, files) {
  if (!files.length) return;
  const ui = page.ui;
  const names = files.map((f) => f.name);
  if (names.some((n) => /\.obj$/i.test(n)) && !names.some((n) => /\.(glb|gltf)$/i.test(n))) {
    say(page, "OBJ scenes are refused in the browser build (it has no OBJ reader): export the model as glTF (.glb) " +
        "(Blender: File > Export > glTF 2.0), or draw it with ./kit render or ./kit view.", "error");
    return;
  }
  const main = files.find((f) => /\.glb$/i.test(f.name)) || files.find((f) => /\.gltf$/i.test(f.name));
  if (!main) {
    say(page, `Not a model: ${names.join(", ")}. Drop a .glb, or a .gltf together with its .bin and images.`, "error");
    return;
  }
  page.droppedCount += 1;
  const dir = `/work/dropped/${page.droppedCount}`;
  page.FS.mkdirTree(dir);
  for (const file of files) page.FS.writeFile(`${dir}/${file.name}`, new Uint8Array(await file.arrayBuffer()));
  if (/\.gltf$/i.test(main.name)) {
    try {
      const gltf = JSON.parse(await main.text());
      const uris = [...(gltf.buffers || []), ...(gltf.images || [])].map((x) => x.uri)
        .filter((u) => u && !u.startsWith("data:")).map((u) => decodeURIComponent(u));
      const missing = uris.filter((u) => !fsExists(page, `${dir}/${u}`));
      if (missing.length) {
        say(page, `${main.name} needs ${missing.join(", ")}: drop or pick them together with it.`, "error");
        return;
      }
    } catch (e) {
      say(page, `${main.name} is not glTF's JSON: ${e.message || e}`, "error");
      return;
    }
  }
  const previous = ui.scene;
  ui.scene = `${dir}/${main.name}`;
  if (!canDraw(page)) {
    ui.scene = previous;
    return;
  }
  if (configure(page, main.name)) {
    page.droppedScenes.push({path: ui.scene, label: main.name});
    fillScenes(page);
    say(page, `Drawing your model ${main.name}.`, "ok");
  } else {
    // kit-web keeps the scene it was given: back to the one before, the message kept.
    ui.scene = previous;
    fillScenes(page);
    const why = page.kitPage.lastError;
    if (!kitCall(configureCommand(page)).error) fitCanvas(page);
    say(page, `${main.name} could not be drawn: ${why}`, "error");
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
    loadModel(page, [...e.dataTransfer.files]);
  });
}
