#!/usr/bin/env python3
"""A student's OBJ scene in the page (tools/web/page/models.js), in Debian's headless chromium on SwiftShader.

Writes a textured quad as a student brings one: quad.obj, quad.mtl naming tiles.png, and tiles.png,
a hand-made texture of four coloured quarters (red top left, green top right, blue bottom left,
yellow bottom right). Serves the site as web_page_test.py does, loads lab 2's reference solution,
and proves:
  1. the three files dropped together draw what kit-render draws of quad.obj (--scene, same stage
     and size), within web_test.py's tolerance for the browser against the desktop;
  2. the texture is where its layout puts it (the known answer, from the PNG written here and OBJ's
     convention that v = 1 is the image's top row, not from the kit): each colour's pixels lie in
     its quarter of the quad on the canvas (the witness: upside down, they do not);
  3. the same files in one .zip draw the same frame, and a folder of them dropped as a folder does;
  4. witnesses: without tiles.png, and without quad.mtl, the frame differs from kit-render's
     beyond the tolerance, and the page names what its loader left out;
  5. a malformed .obj gets the loader's named error, the scene stays, and the page draws again;
  6. Draco-compressed glTF (tests/draco_gltf.mjs: a textured sphere encoded by npm's draco3d),
     positions quantized to 10 bits or not, draws kit-render's frame of the same files (libdraco
     decodes them there, draco3d's WebAssembly in the page); bytes that are no Draco mesh get the
     decoder's named error.

usage: web_obj_test.py SITE_DIR KIT_RENDER WORK_DIR
Builds nothing: without a site or chromium it fails, saying what to install or build.
"""
import json
import pathlib
import shutil
import subprocess
import sys
import time
import zipfile

from png_rgb import read_png, write_png
from web_page_test import DIFFERENT, SAME, Expectations, Page, mean_difference, serve
from web_test import FAR_LEVELS, KIT_ROOT, MAX_FAR_PIXELS, MAX_MEAN_DIFFERENCE, Chromium, compare, site_problem

SIZE = (320, 240)
URL_QUERY = f"stage=lighting&size={SIZE[0]}x{SIZE[1]}"
TILE = 32  # a quarter of the texture, in texels
QUARTERS = {  # colour: (its RGB, its quarter of the image: column, row)
    "red": ((230, 20, 20), (0, 0)), "green": ((20, 200, 20), (1, 0)),
    "blue": ((20, 20, 230), (0, 1)), "yellow": ((230, 220, 20), (1, 1)),
}
# A quad in z = 0 facing +z, 2 by 1.5; vt (0, 1) is its top-left corner, the image's top-left texel.
QUAD_OBJ = """# a textured quad, as a student's exporter writes one
mtllib quad.mtl
o quad
v -1.0 -0.75 0
v  1.0 -0.75 0
v  1.0  0.75 0
v -1.0  0.75 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl tiles
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
"""
QUAD_MTL = """newmtl tiles
Kd 1 1 1
Ks 0.04 0.04 0.04
Ns 10
map_Kd tiles.png
"""
# A face naming a vertex the file does not have: the loader names the file, object and index.
BAD_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"


def tiles_rgb():
    rgb = bytearray()
    for y in range(2 * TILE):
        for x in range(2 * TILE):
            colour = next(c for c, (_, quarter) in QUARTERS.items() if quarter == (x // TILE, y // TILE))
            rgb += bytes(QUARTERS[colour][0])
    return bytes(rgb)


def colour_centres(rgba, width, height):
    """Where each quarter's colour lies on the canvas: {colour: (mean x, mean y, pixels) or None}. A pixel
    is red, green or blue where that channel is over twice the others, yellow where red and green are."""
    tests = {"red": lambda r, g, b: r > 2 * g + 20 and r > 2 * b + 20,
             "green": lambda r, g, b: g > 2 * r + 20 and g > 2 * b + 20,
             "blue": lambda r, g, b: b > 2 * r + 20 and b > 2 * g + 20,
             "yellow": lambda r, g, b: r > 2 * b + 20 and g > 2 * b + 20 and abs(r - g) < 0.3 * r}
    centres = {}
    for colour, test in tests.items():
        points = [(p % width, p // width) for p in range(width * height) if test(*rgba[4 * p:4 * p + 3])]
        centres[colour] = (sum(x for x, _ in points) / len(points), sum(y for _, y in points) / len(points),
                           len(points)) if points else None
    return centres


def quarters_in_place(centres, pixels):
    """Whether each colour covers 2 % of the frame, red left of green and above blue, yellow right of blue and
    below green: the texture's layout."""
    if not all(centres.values()) or any(c[2] < 0.02 * pixels for c in centres.values()):
        return False
    (rx, ry, _), (gx, gy, _), (bx, by, _), (yx, yy, _) = (centres[c] for c in ("red", "green", "blue", "yellow"))
    return rx < gx and bx < yx and ry < by and gy < yy


def draco_models(site, folder, texture):
    """tests/draco_gltf.mjs's Draco-compressed spheres in `folder`, encoded by the page's own npm
    package (draco3d, in the site's build folder), and a copy of the lossless one whose Draco bytes
    start with another name than DRACO: no Draco mesh."""
    modules = site / "page-npm" / "node_modules"
    subprocess.run(["node", str(KIT_ROOT / "tests" / "draco_gltf.mjs"), str(modules), str(folder), str(texture)],
                   check=True)
    gltf = json.loads((folder / "sphere.gltf").read_text())
    gltf["buffers"][0]["uri"] = "broken.bin"
    (folder / "broken.gltf").write_text(json.dumps(gltf))
    (folder / "broken.bin").write_bytes(b"NOTDRACO" + (folder / "sphere.bin").read_bytes()[8:])


def drop_files(page, urls_and_names):
    """A DragEvent dropping Files made of the bytes at each url, as a student drops several at once."""
    page.js(f"""(async () => {{
      const data = new DataTransfer();
      for (const [url, name] of {json.dumps(urls_and_names)})
        data.items.add(new File([await (await fetch(url)).arrayBuffer()], name));
      document.getElementById("canvas").dispatchEvent(
        new DragEvent("drop", {{bubbles: true, cancelable: true, dataTransfer: data}}));
    }})()""")


def drop_folder(chromium, folder):
    """The folder dropped as the browser drops one from a file manager (DevTools' drag of real files)."""
    # Anywhere on the page takes a drop: the middle of the window (the canvas may lie below it).
    x, y = chromium.evaluate("[innerWidth / 2, innerHeight / 2]")
    data = {"items": [], "files": [str(folder)], "dragOperationsMask": 1}
    for kind in ("dragEnter", "dragOver", "drop"):
        chromium.call("Input.dispatchDragEvent", type=kind, x=x, y=y, data=data)


def main():
    if len(sys.argv) != 4:
        raise SystemExit(__doc__)
    site, kit_render, work = pathlib.Path(sys.argv[1]), sys.argv[2], pathlib.Path(sys.argv[3])
    problem = site_problem(site, ("index.html", "kit-page.js", "kit-web.js", "kit-web.wasm", "kit-web.data"))
    if problem:
        print(f"web_obj_test: FAILED: {problem}")
        return 1
    shutil.rmtree(work, ignore_errors=True)
    files = work / "files"
    model = files / "quad"
    model.mkdir(parents=True)
    (model / "quad.obj").write_text(QUAD_OBJ)
    (model / "quad.mtl").write_text(QUAD_MTL)
    write_png(model / "tiles.png", 2 * TILE, 2 * TILE, tiles_rgb())
    with zipfile.ZipFile(files / "quad.zip", "w") as z:
        for name in ("quad.obj", "quad.mtl", "tiles.png"):
            z.write(model / name, f"quad/{name}")
    (files / "bad.obj").write_text(BAD_OBJ)
    draco = files / "draco"
    draco_models(site, draco, model / "tiles.png")
    def kit_render_frame(scene, name):
        out = work / f"kit-render-{name}.png"
        subprocess.run([kit_render, "--stage", "lighting", "--solution", "--scene", str(scene),
                        "--size", f"{SIZE[0]}x{SIZE[1]}", "--out", str(out)], check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        return read_png(out)
    width, height, reference_rgb = kit_render_frame(model / "quad.obj", "quad")

    server, origin = serve(site, files)
    start = time.monotonic()
    expect = Expectations()

    def against_reference(frame, rgb=reference_rgb):
        mean, far = compare(frame, width, height, rgb)
        return mean, far, mean <= MAX_MEAN_DIFFERENCE and far <= MAX_FAR_PIXELS

    chromium = Chromium(str(work))
    page = Page(chromium)

    def dropped(drop, what):
        """The frame and the last message after a drop has drawn or failed."""
        before = page.counters()
        drop()
        page.wait(f"kitPage.frames > {before['frames']} || kitPage.errors > {before['errors']} || "
                  "(kitPage.messages.length && /could not be read|Not a model/.test(kitPage.messages.at(-1)))", what)
        return page.frame()[2], page.last_message()

    quad = [(f"/test-files/quad/{name}", name) for name in ("quad.obj", "quad.mtl", "tiles.png")]
    try:
        page.load(f"{origin}/index.html?{URL_QUERY}")
        _, _, frame_default = page.frame()

        # 1. The OBJ, its MTL and its texture dropped together: kit-render's frame.
        frame_quad, message = dropped(lambda: drop_files(page, quad), "frame of the OBJ")
        mean, far, ok = against_reference(frame_quad)
        expect(ok and page.js("kitPage.ui.scene").endswith("/quad.obj") and message == "Drawing your model quad.obj.",
               "quad.obj + quad.mtl + tiles.png dropped draw kit-render's frame of quad.obj",
               f"mean difference {mean:.3f} levels (at most {MAX_MEAN_DIFFERENCE}), {100 * far:.2f}% of pixels off by "
               f"more than {FAR_LEVELS} (at most {100 * MAX_FAR_PIXELS:.1f}%); {message!r}")

        # 2. Each quarter's colour where the hand-made layout puts it on the quad.
        centres = colour_centres(frame_quad, width, height)
        # Witness: the frame upside down (as a v left unflipped would draw the texture) is not in place.
        upside_down = b"".join(frame_quad[row * width * 4:(row + 1) * width * 4] for row in reversed(range(height)))
        expect(quarters_in_place(centres, width * height)
               and not quarters_in_place(colour_centres(upside_down, width, height), width * height),
               "the texture's quarters lie where its layout puts them (red top left ... yellow bottom right)",
               ", ".join(f"{c} at {v[0]:.0f},{v[1]:.0f} ({v[2]} px)" if v else f"{c}: none" for c, v in centres.items())
               + "; upside down they are not")

        # 3. The same files in a .zip, and as a dropped folder.
        frame_zip, message = dropped(lambda: drop_files(page, [("/test-files/quad.zip", "quad.zip")]), "frame of the zip")
        expect(mean_difference(frame_zip, frame_quad) < SAME and page.js("kitPage.ui.scene").endswith("/quad/quad.obj"),
               "the files in a .zip draw the same frame",
               f"{mean_difference(frame_zip, frame_quad):.3f} from the dropped files' frame; {message!r}")
        frame_folder, message = dropped(lambda: drop_folder(chromium, model), "frame of the folder")
        expect(mean_difference(frame_folder, frame_quad) < SAME and page.js("kitPage.ui.scene").endswith("/quad/quad.obj"),
               "the model's folder dropped as a folder draws the same frame",
               f"{mean_difference(frame_folder, frame_quad):.3f} from the dropped files' frame; {message!r}")

        # 4. Witnesses: no texture, no MTL. Drawn with the loader's fallback, each differs from
        # kit-render's frame of the textured quad, and the page names what was left out.
        for left_out in ("tiles.png", "quad.mtl"):
            frame, message = dropped(lambda: drop_files(page, [q for q in quad if q[1] != left_out]),
                                     f"frame without {left_out}")
            mean, far, ok = against_reference(frame)
            named = [line for line in message.splitlines() if left_out in line and "file not found" in line]
            expect(not ok and mean_difference(frame, frame_default) > DIFFERENT and named and "left out" in message,
                   f"witness: without {left_out} the frame is not kit-render's, and the page says why",
                   f"mean difference {mean:.3f}, {100 * far:.2f}% far (must fail the tolerance); "
                   f"{(named or message.splitlines())[-1]!r}")

        # 5. A malformed OBJ: the loader's error by name; the scene stays; the page draws again.
        scene = page.js("kitPage.ui.scene")
        _, message = dropped(lambda: drop_files(page, [("/test-files/bad.obj", "bad.obj")]), "error of bad.obj")
        kept = page.js("kitPage.ui.scene") == scene
        before = page.counters()
        page.js("document.getElementById('view').value = 'albedo'; "
                "document.getElementById('view').dispatchEvent(new Event('change'))")
        page.wait(f"kitPage.frames > {before['frames']} || kitPage.errors > {before['errors']}", "frame after bad.obj")
        drew = page.counters()["errors"] == before["errors"]
        expect(message.startswith("bad.obj could not be drawn: ") and "bad.obj" in message[len("bad.obj could"):]
               and "face 1" in message and kept and drew,
               "a malformed .obj gets the loader's named error, and the page keeps drawing",
               f"{message!r}; scene {'kept' if kept else 'CHANGED'}; {'drew' if drew else 'did NOT draw'} the next view")

        # 6. Draco-compressed glTF, encoded by draco3d: the page loads its decoder (draco3d's
        # WebAssembly) and draws what kit-render (libdraco) draws of the same files, positions
        # quantized or not; bytes that are no Draco mesh get the decoder's named error. The
        # final view again (step 5 left the albedo view on).
        before = page.counters()
        page.js("document.getElementById('view').value = 'final'; "
                "document.getElementById('view').dispatchEvent(new Event('change'))")
        page.wait(f"kitPage.frames > {before['frames']} || kitPage.errors > {before['errors']}", "final view again")
        for name in ("sphere", "sphere-q10"):
            names = (f"{name}.gltf", f"{name}.bin", "texture.png")
            frame, message = dropped(lambda: drop_files(page, [(f"/test-files/draco/{n}", n) for n in names]),
                                     f"frame of {name}.gltf")
            _, _, rgb = kit_render_frame(draco / f"{name}.gltf", name)
            mean, far, ok = against_reference(frame, rgb)
            expect(ok and message == f"Drawing your model {name}.gltf." and mean_difference(frame, frame_default) > DIFFERENT,
                   f"Draco-compressed {name}.gltf draws kit-render's frame of it",
                   f"mean difference {mean:.3f} levels (at most {MAX_MEAN_DIFFERENCE}), {100 * far:.2f}% far; {message!r}")
        broken = [(f"/test-files/draco/{n}", n) for n in ("broken.gltf", "broken.bin", "texture.png")]
        _, message = dropped(lambda: drop_files(page, broken), "error of broken.gltf")
        expect(message.startswith("broken.gltf could not be drawn: ") and "Draco cannot decode its mesh" in message,
               "bytes that are no Draco mesh get the decoder's named error", message)
    finally:
        chromium.close()
        server.shutdown()
    return expect.result("web_obj_test", time.monotonic() - start)


if __name__ == "__main__":
    sys.exit(main())
