// The URL: kit-render's options (stage, scene, view, size, shaders, camera) become the first
// frame's arguments and the controls' first state, and the controls keep it up to date, so a
// handout can link to a view (index.html says which lab files the first frame draws).
import {findStage, hasLabs, missingEarlier} from "./kit.js";

// kit-web's arguments, as kit-render takes them (--solution comes in firstFrameArguments).
export function kitArguments(page) {
  const query = page.query, args = [];
  for (const [key, flag] of [["stage", "--stage"], ["scene", "--scene"], ["view", "--view"], ["size", "--size"],
                             ["camera", "--camera"]]) {
    if (query.has(key)) args.push(flag, query.get(key));
  }
  const size = /^(\d+)x(\d+)$/.exec(query.get("size") || "");
  if (size) {
    // Exactly that many pixels, shown one canvas pixel to one CSS pixel.
    page.canvas.style.width = size[1] + "px";
    page.canvas.style.height = size[2] + "px";
  }
  return args;
}

// Before main(), once the file system tells whether the site has the lab's files and its
// solution: the stage, where the URL names none, and --solution. emscripten passes this same
// array to main(): the flags are added in place.
export function firstFrameArguments(page, args) {
  const query = page.query, catalogue = page.ui.catalogue;
  let stage = catalogue.stages ? findStage(page, query.get("stage") || "gbuffer") : null;
  if (!query.has("stage") && catalogue.stages) {
    // No stage in the URL: the first lab this site has the student's files of and can
    // draw (a class's site: the class's lab; the instructors': lab 1, as kit-render).
    const own = catalogue.stages.find((s) => hasLabs(page, s) && !missingEarlier(page, s));
    if (own && own !== stage) {
      stage = own;
      args.push("--stage", own.name);
    }
  }
  if (query.get("shaders") !== "labs") {
    if (stage && !stage.solution && hasLabs(page, stage)) page.fellBackToLabs = true;
    else args.push("--solution");
  }
}

// The controls' first state: what the first frame drew (its report), else the URL's.
export function initialState(page, report) {
  const ui = page.ui, query = page.query;
  const fromUrl = query.get("stage");
  ui.stage = findStage(page, report.stage || fromUrl || "gbuffer") || ui.catalogue.stages[0];
  if (report.solution !== undefined) ui.solution = report.solution;
  else if (hasLabs(page, ui.stage)) ui.solution = query.get("shaders") !== "labs" && ui.stage.solution;
  else ui.solution = ui.stage.solution;
  ui.scene = report.scene || query.get("scene") || "default";
  ui.view = report.view || query.get("view") || "final";
  const size = /^(\d+)x(\d+)$/.exec(report.size || query.get("size") || "");
  if (size) [ui.width, ui.height] = [Number(size[1]), Number(size[2])];
}

export function updateURL(page) {
  const ui = page.ui;
  const params = new URLSearchParams(window.location.search);
  params.set("stage", ui.stage.name);
  if (!ui.scene.startsWith("/")) params.set("scene", ui.scene);  // a dropped model is not on the next visit
  params.set("view", ui.view);
  params.set("size", `${ui.width}x${ui.height}`);
  if (ui.solution) params.delete("shaders");
  else params.set("shaders", "labs");
  const url = `${window.location.pathname}?${params.toString().replace(/%2F/g, "/")}${window.location.hash}`;
  window.history.replaceState(null, "", url);
}
