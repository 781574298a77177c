// Calls into the WebAssembly program, kit-web: every command goes through kit_call(JSON) ->
// JSON (tools/web/kit_web.cpp), and the lab's files are in its file system. The questions the
// page asks of the catalogue kit-web answers with are here too.

export function kitCall(command) {
  try {
    return JSON.parse(window.Module.ccall("kit_call", "string", ["string"], [JSON.stringify(command)]));
  } catch (e) {
    return {error: "kit-web stopped: " + (e && e.message ? e.message : e)};
  }
}

export function fsExists(page, path) {
  try {
    return page.FS.analyzePath(path).exists;
  } catch (e) {
    return false;
  }
}

export function findStage(page, nameOrNumber) {
  const stages = page.ui.catalogue ? page.ui.catalogue.stages : [];
  return stages.find((s) => s.name === nameOrNumber || String(s.number) === nameOrNumber || s.folder === nameOrNumber);
}

export const hasLabs = (page, stage) => fsExists(page, `/kit/labs/${stage.folder}`);

// The first earlier lab this site has no solution of: stage N is built on labs 1..N-1's solutions.
export function missingEarlier(page, stage) {
  for (const s of page.ui.catalogue.stages) {
    if (s.number >= stage.number) break;
    if (!s.solution) return s;
  }
  return null;
}

// The command that draws what the controls show: all of it, every time.
export function configureCommand(page) {
  const ui = page.ui;
  return {cmd: "configure", stage: ui.stage.name, solution: ui.solution, scene: ui.scene, view: ui.view,
          width: ui.width, height: ui.height, ...ui.settings};
}

// kit-web builds its renderer anew, from the files, when the stage, the shaders or the
// scene change (and after a lost context); other settings keep it.
export const buildKey = (page) => `${page.ui.stage.name}/${page.ui.solution}/${page.ui.scene}`;
