#!/usr/bin/env python3
"""The files a browser site holds, packed apart from the program (one list for every site).

    site_files.py pack KIT_ROOT SCENES OUT_DIR
        kit-web.data and kit-web-data.js in OUT_DIR: the framework's shaders, the labs, the
        solutions the kit holds, the scenes with their environments, and the grader's
        tolerances, references and mistake signatures (for the page's check), under /kit as
        kitcore's KIT_SOURCE_DIR and KIT_SCENE_DIR say. Packed by emscripten's file_packager,
        so the page loads them before kit-web.js starts. A student copy's site is the
        instructor's program with the copy's files packed (./kit web --student-copy N).
    site_files.py extract SITE_DIR OUT_DIR
        The packed files back out of a site into OUT_DIR/<path without /kit/>: what a
        student-copy site gives away is checked there like a student copy is.

Exit status 0, or 1 with the reason.
"""
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys

# What the program reads, by where it reads it (common/CMakeLists.txt's KIT_SOURCE_DIR is /kit).
def mappings(root, scenes):
    return [(root / "shaders", "/kit/shaders"), (root / "labs", "/kit/labs"), (root / "solutions", "/kit/solutions"),
            (scenes, "/kit/scenes"), (root / "tools/grade/grading.json", "/kit/tools/grade/grading.json"),
            (root / "tools/grade/lab_functions.json", "/kit/tools/grade/lab_functions.json"),
            (root / "tools/grade/references", "/kit/tools/grade/references")]


def file_packager():
    """emscripten's file_packager.py: beside emcc (Debian: /usr/share/emscripten/tools)."""
    emcc = shutil.which("emcc")
    candidates = [pathlib.Path("/usr/share/emscripten/tools/file_packager.py")]
    if emcc:
        candidates.insert(0, pathlib.Path(os.path.realpath(emcc)).parent / "tools/file_packager.py")
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise SystemExit("site_files: no emscripten file_packager.py (install Debian's emscripten: ./kit web does)")


def pack(root, scenes, out):
    out.mkdir(parents=True, exist_ok=True)
    args = []
    for source, target in mappings(root, scenes):
        if not source.exists():
            if source.name == "solutions":  # a kit without any solution (a lab 1 student copy)
                continue
            raise SystemExit(f"site_files: {source} is missing")
        args += [f"{source}@{target}"]
    # --no-node: the page runs in a browser only. The packer writes the data file where the
    # command runs: its name is the one kit-web-data.js fetches.
    # Its reminder to link with -sFORCE_FILESYSTEM (tools/web/CMakeLists.txt does) is not printed.
    run = subprocess.run([sys.executable, str(file_packager()), "kit-web.data", "--preload", *args,
                          "--js-output=kit-web-data.js", "--no-node"], cwd=out, capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(f"site_files: file_packager failed:\n{run.stdout}{run.stderr}")


def extract(site, out):
    script = (site / "kit-web-data.js").read_text(encoding="utf-8")
    match = re.search(r"loadPackage\((\{.*?\"files\".*?\})\);?", script, re.S)
    if not match:
        raise SystemExit(f"site_files: {site}/kit-web-data.js holds no package list")
    metadata = json.loads(match.group(1))
    data = (site / "kit-web.data").read_bytes()
    for entry in metadata["files"]:
        name = entry["filename"]
        if not name.startswith("/kit/"):
            raise SystemExit(f"site_files: {name}: outside /kit")
        path = out / name[len("/kit/"):]
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data[entry["start"]:entry["end"]])
    print(f"site_files: {len(metadata['files'])} files of {site} in {out}")


def main(argv):
    if len(argv) == 5 and argv[1] == "pack":
        pack(pathlib.Path(argv[2]).resolve(), pathlib.Path(argv[3]).resolve(), pathlib.Path(argv[4]).resolve())
    elif len(argv) == 4 and argv[1] == "extract":
        extract(pathlib.Path(argv[2]), pathlib.Path(argv[3]))
    else:
        raise SystemExit(__doc__)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
