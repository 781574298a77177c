// The site's files past the first frame's (tools/web/site_files.py): kit-web.data holds what
// the first frame draws with; each other scene and the grader's references are zips, listed
// in kit-web-packages.json, fetched when needed (a scene when chosen or named in the URL, the
// references and the lab's scenes at the first "Check my lab") and written into kit-web's file
// system. fflate unzips them (it writes "Download my labs" too). Only FS.mkdirTree and
// FS.writeFile touch kit-web, the same in Debian 12's emscripten 3.1.6 and later ones.
import {unzipSync} from "fflate";
import {say} from "./messages.js";

const MANIFEST = "kit-web-packages.json";
const SCENE_NAME = /^[A-Za-z0-9_.-]+$/;

// At once, beside kit-web's own downloads: the list of packages. A site without one (all its
// files in kit-web.data) fetches nothing later.
export function startPackages(page) {
  const packages = {list: null, problem: "", loading: new Map()};
  packages.ready = fetch(MANIFEST).then((response) => {
    if (response.status === 404) return null;
    if (!response.ok) throw new Error(`${MANIFEST}: HTTP ${response.status}`);
    return response.json();
  }).then((list) => {
    packages.list = list;
    return list;
  }).catch((e) => {
    packages.problem = `${MANIFEST} could not be read (${e.message || e}): scenes other than the first, and the ` +
                       "check, are not available";
    return null;
  });
  page.packages = packages;
  page.kitPage.packagesLoaded = [];
}

// The package that holds a scene: its name, or a path inside the kit's scenes.
export function scenePackage(page, scene) {
  const list = page.packages.list;
  if (!list || !scene) return null;
  const inKit = /^\/kit\/scenes\/([^/]+)\//.exec(scene);
  const name = inKit ? inKit[1] : SCENE_NAME.test(scene) ? scene : null;
  const key = name && `scene:${name}`;
  return key && list.packages[key] ? key : null;
}

async function fetchBytes(entry, progress) {
  const response = await fetch(entry.file);
  if (!response.ok) throw new Error(`${entry.file}: HTTP ${response.status}`);
  if (!response.body || !progress) return new Uint8Array(await response.arrayBuffer());
  const reader = response.body.getReader(), chunks = [];
  let received = 0;
  for (;;) {
    const {done, value} = await reader.read();
    if (done) break;
    chunks.push(value);
    received += value.length;
    progress(received);
  }
  const bytes = new Uint8Array(received);
  let at = 0;
  for (const chunk of chunks) {
    bytes.set(chunk, at);
    at += chunk.length;
  }
  return bytes;
}

function writeFiles(FS, file, bytes) {
  const files = unzipSync(bytes);
  for (const [name, data] of Object.entries(files)) {
    if (name.endsWith("/")) continue;
    if (name.startsWith("/") || name.split("/").includes("..")) throw new Error(`${file}: ${name}: outside /kit`);
    const path = "/kit/" + name;
    FS.mkdirTree(path.slice(0, path.lastIndexOf("/")));
    FS.writeFile(path, data);
  }
}

// One package into the file system, once a visit; progress(bytes) as it arrives.
export function loadPackage(page, FS, key, progress) {
  const packages = page.packages;
  if (!packages.loading.has(key)) {
    const entry = packages.list.packages[key];
    const loading = fetchBytes(entry, progress).then((bytes) => {
      writeFiles(FS, entry.file, bytes);
      page.kitPage.packagesLoaded.push(key);
    });
    // A failed fetch is tried again the next time it is needed.
    loading.catch(() => packages.loading.delete(key));
    packages.loading.set(key, loading);
  }
  return packages.loading.get(key);
}

// Before main(): the URL's scene, where kit-web.data lacks it. main() waits on a run
// dependency, as it waits for kit-web.data (emscripten's file packager holds it the same way).
export function holdForFirstScene(page, Module, scene) {
  Module.addRunDependency("kit-first-scene");
  page.packages.ready.then(() => {
    const key = scenePackage(page, scene);
    return key ? loadPackage(page, Module.FS, key) : null;
  }).catch((e) => {
    page.packages.problem = `the scene ${scene} could not be fetched: ${e.message || e}`;
  }).finally(() => Module.removeRunDependency("kit-first-scene"));
}

// The scenes the page offers: kit-web's, and those the site keeps in packages.
export function offeredScenes(page, scenes) {
  const list = page.packages.list;
  return [...new Set([...scenes, ...(list ? list.scenes : [])])].sort();
}

const megabytes = (n) => (n / 1e6).toFixed(1);

// A scene the student chose: true once it is in the file system (a message while it loads).
export async function ensureScene(page, scene) {
  const key = scenePackage(page, scene);
  if (!key || page.kitPage.packagesLoaded.includes(key)) return true;
  const entry = page.packages.list.packages[key];
  say(page, `Loading the scene ${key.slice("scene:".length)} (${megabytes(entry.bytes)} MB)\u2026`);
  try {
    await loadPackage(page, page.FS, key);
    say(page, "");
    return true;
  } catch (e) {
    say(page, `The scene ${key.slice("scene:".length)} could not be loaded: ${e.message || e}`, "error");
    return false;
  }
}

// What lab `lab`'s check reads beyond kit-web.data: the references and the scenes its checks
// render (kit-web's catalogue, check_scenes). progress(received, total) in bytes, over all.
export async function loadCheckFiles(page, lab, progress) {
  await page.packages.ready;
  const list = page.packages.list;
  if (!list) {
    if (page.packages.problem) throw new Error(page.packages.problem);
    return;
  }
  const scenes = (page.ui.catalogue.check_scenes || {})[String(lab)] || [];
  const keys = ["references", ...scenes.map((s) => `scene:${s}`)]
    .filter((k) => list.packages[k] && !page.kitPage.packagesLoaded.includes(k));
  const total = keys.reduce((sum, k) => sum + list.packages[k].bytes, 0);
  const received = new Map();
  const report = () => progress && progress([...received.values()].reduce((a, b) => a + b, 0), total);
  await Promise.all(keys.map((k) => loadPackage(page, page.FS, k, (n) => {
    received.set(k, n);
    report();
  })));
}

export const checkFilesMessage = (received, total) =>
  `Loading the grader's references (${megabytes(received)} of ${megabytes(total)} MB, once a visit)\u2026`;
