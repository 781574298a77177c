// The controls beside the frame (lab, shaders, scene, view, size, kit-view's settings): they
// mirror page.ui, offer only what the lab can draw, and each change goes into page.ui and
// asks for a frame (view.js), which also puts it in the URL.
import {findStage, hasLabs, missingEarlier} from "./kit.js";
import {ensureScene} from "./packages.js";
import {$, MAP_VIEWS, SIZES, VIEW_LABELS} from "./state.js";
import {openStageFiles} from "./tabs.js";
import {requestDraw} from "./view.js";

function option(value, text, disabled = false) {
  const o = document.createElement("option");
  o.value = value;
  o.textContent = text;
  o.disabled = disabled;
  return o;
}

function fillStages(page) {
  const select = $("stage");
  select.replaceChildren();
  for (const s of page.ui.catalogue.stages) {
    const missing = missingEarlier(page, s);
    const label = `${s.number} ${s.name}` + (missing ? ` (needs lab ${missing.number}'s solution)` : "");
    select.append(option(s.name, label, Boolean(missing)));
  }
  select.value = page.ui.stage.name;
}

function fillViews(page) {
  const ui = page.ui;
  const select = $("view");
  select.replaceChildren();
  // As kit-view offers them: HDR from the first lit stage, lab 6's maps in lab 6.
  const allowed = (v) => (v !== "hdr" || ui.stage.number >= 2) &&
                         (!MAP_VIEWS.includes(v) || ui.stage.name === "ibl");
  for (const v of ui.catalogue.views) if (allowed(v)) select.append(option(v, VIEW_LABELS[v] || v));
  if (![...select.options].some((o) => o.value === ui.view)) ui.view = "final";
  select.value = ui.view;
}

export function fillScenes(page) {
  const ui = page.ui;
  const select = $("scene");
  select.replaceChildren();
  const kit = document.createElement("optgroup");
  kit.label = "The kit's scenes";
  for (const name of ui.catalogue.scenes) kit.append(option(name, name));
  select.append(kit);
  if (page.droppedScenes.length) {
    const own = document.createElement("optgroup");
    own.label = "Your models";
    for (const d of page.droppedScenes) own.append(option(d.path, d.label));
    select.append(own);
  }
  if (![...select.querySelectorAll("option")].some((o) => o.value === ui.scene)) {
    select.append(option(ui.scene, ui.scene));
  }
  select.value = ui.scene;
}

function fillSizes(page) {
  const select = $("size");
  select.replaceChildren();
  const sizes = [...SIZES];
  const current = `${page.ui.width}x${page.ui.height}`;
  if (!sizes.includes(current)) sizes.unshift(current);
  for (const s of sizes) select.append(option(s, s.replace("x", " x ")));
  select.value = current;
}

function syncShaders(page) {
  const labsThere = hasLabs(page, page.ui.stage);
  $("shaders-labs").disabled = !labsThere;
  $("shaders-solution").disabled = !page.ui.stage.solution;
  $("shaders-labs").checked = !page.ui.solution;
  $("shaders-solution").checked = page.ui.solution;
}

function syncSettings(page) {
  let shown = 0;
  for (const row of document.querySelectorAll("[data-from-lab]")) {
    row.hidden = page.ui.stage.number < Number(row.dataset.fromLab);
    if (!row.hidden) shown += 1;
  }
  $("settings-none").hidden = shown > 0;
  $("bloom-threshold").disabled = !page.ui.settings.postprocess;
}

export function syncControls(page) {
  fillStages(page);
  syncShaders(page);
  fillScenes(page);
  fillViews(page);
  fillSizes(page);
  syncSettings(page);
  const s = page.ui.settings;
  $("postprocess").checked = s.postprocess;
  $("custom-effect").checked = s.custom_effect;
  $("gamma").value = s.gamma;
  $("gamma-value").textContent = Number(s.gamma).toFixed(2);
  $("bloom-threshold").value = s.bloom_threshold;
  $("bloom-threshold-value").textContent = Number(s.bloom_threshold).toFixed(2);
  $("extra-lights").value = s.extra_lights;
  $("extra-lights-value").textContent = String(s.extra_lights);
  for (const radio of document.querySelectorAll('input[name="attenuation"]'))
    radio.checked = Number(radio.value) === s.attenuation_model;
  $("check").disabled = !hasLabs(page, page.ui.stage) || Boolean(missingEarlier(page, page.ui.stage));
}

export function wireControls(page) {
  const ui = page.ui;
  for (const id of ["stage", "scene", "view", "size", "postprocess", "custom-effect", "gamma", "bloom-threshold",
                    "extra-lights", "model-file", "shaders-labs", "shaders-solution"])
    $(id).disabled = false;
  for (const radio of document.querySelectorAll('input[name="attenuation"]')) radio.disabled = false;

  $("stage").addEventListener("change", () => {
    ui.stage = findStage(page, $("stage").value);
    // A student's default is their own files; a lab that is over shows its solution.
    ui.solution = !hasLabs(page, ui.stage) && ui.stage.solution;
    syncControls(page);
    openStageFiles(page);
    requestDraw(page);
  });
  for (const id of ["shaders-labs", "shaders-solution"]) {
    $(id).addEventListener("change", () => {
      ui.solution = $("shaders-solution").checked;
      openStageFiles(page);
      requestDraw(page);
    });
  }
  // A scene the site keeps in a package of its own is fetched first; the frame keeps the
  // scene it has until then, and keeps it if the fetch fails.
  $("scene").addEventListener("change", async () => {
    const scene = $("scene").value;
    if (await ensureScene(page, scene)) {
      ui.scene = scene;
      requestDraw(page);
    } else {
      $("scene").value = ui.scene;
    }
  });
  $("view").addEventListener("change", () => {
    ui.view = $("view").value;
    requestDraw(page);
  });
  $("size").addEventListener("change", () => {
    [ui.width, ui.height] = $("size").value.split("x").map(Number);
    requestDraw(page);
  });
  $("postprocess").addEventListener("change", () => {
    ui.settings.postprocess = $("postprocess").checked;
    syncSettings(page);
    requestDraw(page);
  });
  $("custom-effect").addEventListener("change", () => {
    ui.settings.custom_effect = $("custom-effect").checked;
    requestDraw(page);
  });
  const slider = (id, key, digits) => {
    $(id).addEventListener("input", () => {
      ui.settings[key] = Number($(id).value);
      $(id + "-value").textContent = ui.settings[key].toFixed(digits);
      requestDraw(page);
    });
  };
  slider("gamma", "gamma", 2);
  slider("bloom-threshold", "bloom_threshold", 2);
  slider("extra-lights", "extra_lights", 0);
  for (const radio of document.querySelectorAll('input[name="attenuation"]')) {
    radio.addEventListener("change", () => {
      ui.settings.attenuation_model = Number(radio.value);
      requestDraw(page);
    });
  }
}
