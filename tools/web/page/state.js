// The page's one state object, made once (main.js) and handed to every module: what the page
// shows (ui, which the controls mirror and every configure sends), and what the modules must
// share while it runs (kit-web's file system, the editor, the GPU context's state, the
// student's folder...). Kept in one place so no module holds state of its own.

export const $ = (id) => document.getElementById(id);

export const SIZES = ["320x240", "640x480", "800x600", "1024x768", "1280x720"];
export const VIEW_LABELS = {
  final: "final image", position: "G-buffer: position", normal: "G-buffer: normal", albedo: "G-buffer: albedo",
  material: "G-buffer: material", emission: "G-buffer: emission", depth: "depth", hdr: "HDR (before tone mapping)",
  irradiance: "lab 6: irradiance map", prefiltered: "lab 6: prefiltered environment", "brdf-lut": "lab 6: BRDF table",
};
// Lab 6's maps: small sizes of their own, shown magnified.
export const MAP_VIEWS = ["irradiance", "prefiltered", "brdf-lut"];

// kit-view's and kit-render's settings as they start (the progress report times each lab with them).
export const DEFAULT_SETTINGS = {gamma: 2.2, attenuation_model: 0, postprocess: true, custom_effect: false,
                                 bloom_threshold: 1.0, extra_lights: 0};

export function createPage() {
  return {
    startedAt: performance.now(),
    query: new URLSearchParams(window.location.search),
    canvas: $("canvas"),
    // What the page shows; the controls mirror it and every configure sends all of it.
    ui: {
      catalogue: null,
      stage: null,             // the catalogue's stage
      solution: false,         // the reference solution instead of the student's files
      scene: "default",        // a kit scene's name, or a dropped model's path in the file system
      view: "final",
      width: 640, height: 480,
      settings: {...DEFAULT_SETTINGS},
    },
    FS: null,                  // kit-web's file system
    labs: null,                // the student's lab files (labs.js)
    editor: null,              // the lab editor (editor.js)
    restoredPaths: [],         // the edits this browser kept, in the file system before the first frame
    fellBackToLabs: false,     // the URL asked for the solution, and the site has none of that lab
    // Drawing (view.js).
    drawRequested: false,
    lastDraw: {kind: "", at: 0},
    builtKey: "",              // stage/shaders/scene of the renderer kit-web built last
    lastAnswer: null,          // kit-web's answer to the last configure (a new scene's warnings)
    lost: false, lostAfterEdit: false, editWhileLost: false, waitingForEdit: false,
    // The editor's tabs and edits (tabs.js, edits.js).
    files: [],                 // the files the editor shows for the stage
    path: null,                // the one shown
    compileErrors: new Map(),  // path -> diagnostics of the last failed compile
    pending: new Set(),        // paths edited since the last compile
    compileTimer: 0,
    // The student's folder (folder.js): {name, labsDir, files: path -> entry}.
    folder: null, folderTimer: 0, polling: false,
    // Dropped models (models.js): [{path, label}].
    droppedCount: 0, droppedScenes: [],
    // The handout pane (handout.js): the document shown, the site's documents (doc/index.json).
    handout: {open: false, doc: "", index: null, known: null},
    // Camera moves not sent yet (camera.js).
    camera: {rotate: [0, 0], pan: [0, 0], zoom: 0, scheduled: false},
    // For the page's test (tests/web_page_test.py) and the curious: counters and state.
    kitPage: window.kitPage = {ready: false, frames: 0, errors: 0, lastError: "", lastDownload: null,
                               messages: [], lastCheck: null, lastReport: null},
  };
}
