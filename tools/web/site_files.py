#!/usr/bin/env python3
"""The files a browser site holds, packed apart from the program (one list for every site).

    site_files.py pack KIT_ROOT SCENES OUT_DIR
        The files kit-web reads, under /kit as kitcore's KIT_SOURCE_DIR and KIT_SCENE_DIR say,
        in packages by when the page needs them:
          kit-web.data, kit-web-data.js   what the first frame draws with, loaded before
              kit-web.js starts (emscripten's file_packager): the framework's shaders, the
              labs, the solutions the kit holds, the grader's tolerances and the labs'
              contract (grading.json, lab_functions.json), the first visit's scene (default)
              and the environments;
          kit-web-scene-NAME.zip          each other scene, fetched when it is chosen (or
              named in the URL, before the first frame);
          kit-web-references.zip          the grader's references and mistake signatures,
              fetched when the student first asks for a check;
          kit-web-packages.json           what each zip holds and weighs, and the scenes.
        A student copy's site is the instructor's program with the copy's files packed
        (./kit web --student-copy N).
    site_files.py extract SITE_DIR OUT_DIR
        The packed files back out of a site, every package, into OUT_DIR/<path without /kit/>:
        what a student-copy site gives away is checked there like a student copy is.

Exit status 0, or 1 with the reason.
"""
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import zipfile
import zlib

# The packages past the first: zips of paths relative to /kit, which the page unzips with
# fflate (already bundled for "Download my labs") and writes into kit-web's file system with
# FS.mkdirTree and FS.writeFile. Why not more file_packager packages: a file_packager script
# loaded after main() has run writes its files when they arrive but tells no one (it only
# drops a run dependency, which then waits for nothing), and its loader's code differs
# between Debian 12's emscripten 3.1.6 and later ones; the FS calls the page makes are the
# same in both.
MANIFEST = "kit-web-packages.json"
REFERENCES_ZIP = "kit-web-references.zip"
SCENE_ZIP = "kit-web-scene-{}.zip"
# The scenes in the first package: the one a first visit shows, and the environments that
# lab 6's frames read whatever the scene (44 KB).
FIRST_SCENES = ("default", "environments")
# Zip entries are deflated where that saves a tenth; the references (EXR, PNG) are stored.
DEFLATE_GAIN = 0.9


# What the first frame reads, by where it reads it (common/CMakeLists.txt's KIT_SOURCE_DIR is /kit).
def first_mappings(root, scenes):
    return [(root / "shaders", "/kit/shaders"), (root / "labs", "/kit/labs"), (root / "solutions", "/kit/solutions"),
            (root / "tools/grade/grading.json", "/kit/tools/grade/grading.json"),
            (root / "tools/grade/lab_functions.json", "/kit/tools/grade/lab_functions.json")] + \
           [(scenes / name, f"/kit/scenes/{name}") for name in FIRST_SCENES]


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


def write_zip(path, source, prefix):
    """source's files as prefix/<relative path> in a zip, in name order, dated 1980: the same
    files give the same bytes. Its entry in the manifest."""
    files = sorted(p for p in source.rglob("*") if p.is_file())
    with zipfile.ZipFile(path, "w") as archive:
        for file in files:
            data = file.read_bytes()
            info = zipfile.ZipInfo(f"{prefix}/{file.relative_to(source).as_posix()}", date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            deflate = len(zlib.compress(data, 6)) < DEFLATE_GAIN * len(data)
            info.compress_type = zipfile.ZIP_DEFLATED if deflate else zipfile.ZIP_STORED
            archive.writestr(info, data, compresslevel=6)
    return {"file": path.name, "bytes": path.stat().st_size, "files": len(files)}


def pack_first(root, scenes, out):
    args = []
    for source, target in first_mappings(root, scenes):
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


def pack(root, scenes, out):
    out.mkdir(parents=True, exist_ok=True)
    for stale in [*out.glob(SCENE_ZIP.format("*")), out / REFERENCES_ZIP, out / MANIFEST]:
        stale.unlink(missing_ok=True)
    pack_first(root, scenes, out)
    references = root / "tools/grade/references"
    if not references.is_dir():
        raise SystemExit(f"site_files: {references} is missing")
    packages = {"references": write_zip(out / REFERENCES_ZIP, references, "tools/grade/references")}
    for folder in sorted(p for p in scenes.iterdir() if p.is_dir() and p.name not in FIRST_SCENES):
        zip_path = out / SCENE_ZIP.format(folder.name)
        packages["scene:" + folder.name] = write_zip(zip_path, folder, f"scenes/{folder.name}")
    # The scenes the page offers: kit-web lists those of its file system (kit_web.cpp's
    # catalogue), which holds only the first package's until the others are fetched.
    offered = sorted(p.name for p in scenes.iterdir() if (p / f"{p.name}.gltf").is_file())
    manifest = {"first_scenes": list(FIRST_SCENES), "scenes": offered, "packages": packages}
    (out / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")


def extract_zip(path, out):
    count = 0
    with zipfile.ZipFile(path) as archive:
        for name in archive.namelist():
            parts = pathlib.PurePosixPath(name).parts
            if name.startswith("/") or ".." in parts or not parts:
                raise SystemExit(f"site_files: {path}: {name}: outside /kit")
            if name.endswith("/"):
                continue
            target = out.joinpath(*parts)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(archive.read(name))
            count += 1
    return count


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
    count = len(metadata["files"])
    # Every zip of the site, listed or not: what the site gives away is all of it.
    manifest = site / MANIFEST
    listed = json.loads(manifest.read_text(encoding="utf-8"))["packages"] if manifest.is_file() else {}
    zips = sorted({site / p["file"] for p in listed.values()} | set(site.glob("kit-web-*.zip")))
    for path in zips:
        count += extract_zip(path, out)
    print(f"site_files: {count} files of {site} ({1 + len(zips)} packages) in {out}")


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
