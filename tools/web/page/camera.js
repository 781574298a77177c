// Orbiting the camera on the canvas: mouse, touch and keyboard. Moves add up until the next
// animation frame, which sends them to kit-web and draws once, however many events came.
import {kitCall} from "./kit.js";
import {canDraw, drawn} from "./view.js";

function flushCamera(page) {
  const moves = page.camera;
  moves.scheduled = false;
  if (!canDraw(page)) return;
  const [rx, ry] = moves.rotate, [px, py] = moves.pan, zoom = moves.zoom;
  moves.rotate = [0, 0];
  moves.pan = [0, 0];
  moves.zoom = 0;
  let answer = null;
  if (rx || ry) answer = kitCall({cmd: "camera", action: "rotate", dx: rx, dy: ry});
  if (px || py) answer = kitCall({cmd: "camera", action: "pan", dx: px, dy: py});
  if (zoom) answer = kitCall({cmd: "camera", action: "zoom", steps: zoom});
  if (answer) drawn(page, answer, "move", "camera moved,");
}

function moveCamera(page, action, a, b = 0) {
  const moves = page.camera;
  if (action === "zoom") moves.zoom += a;
  else {
    moves[action][0] += a;
    moves[action][1] += b;
  }
  if (!moves.scheduled) {
    moves.scheduled = true;
    requestAnimationFrame(() => flushCamera(page));
  }
}

export function wireCamera(page) {
  const canvas = page.canvas;
  const pointers = new Map();  // the pointers down on the canvas: where they were last
  let pinchDistance = 0;
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("pointerdown", (e) => {
    canvas.setPointerCapture(e.pointerId);
    pointers.set(e.pointerId, {x: e.clientX, y: e.clientY, button: e.button});
    if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      pinchDistance = Math.hypot(a.x - b.x, a.y - b.y);
    }
    canvas.focus();
    e.preventDefault();
  });
  canvas.addEventListener("pointermove", (e) => {
    const p = pointers.get(e.pointerId);
    if (!p) return;
    const dx = e.clientX - p.x, dy = e.clientY - p.y;
    p.x = e.clientX;
    p.y = e.clientY;
    if (pointers.size === 1) {
      moveCamera(page, p.button === 2 || p.button === 1 || e.shiftKey ? "pan" : "rotate", dx, dy);
    } else if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      const distance = Math.hypot(a.x - b.x, a.y - b.y);
      moveCamera(page, "zoom", (distance - pinchDistance) / 40);  // 40 px of pinch: one wheel step
      pinchDistance = distance;
    }
  });
  const up = (e) => {
    pointers.delete(e.pointerId);
  };
  canvas.addEventListener("pointerup", up);
  canvas.addEventListener("pointercancel", up);
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const perStep = e.deltaMode === 1 ? 3 : e.deltaMode === 2 ? 1 : 100;
    moveCamera(page, "zoom", -e.deltaY / perStep);
  }, {passive: false});
  canvas.addEventListener("keydown", (e) => {
    const step = 20;
    const keys = {ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step]};
    if (keys[e.key]) moveCamera(page, e.shiftKey ? "pan" : "rotate", ...keys[e.key]);
    else if (e.key === "+" || e.key === "=" || e.key === "PageUp") moveCamera(page, "zoom", 1);
    else if (e.key === "-" || e.key === "PageDown") moveCamera(page, "zoom", -1);
    else return;
    e.preventDefault();
  });
}
