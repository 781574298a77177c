#!/usr/bin/env python3
"""The development container (.devcontainer/), as far as it can be tried without Docker.

    devcontainer_test.py KIT_VIEW KIT_RENDER WORK_DIR

1. The configuration: devcontainer.json is plain JSON; it builds .devcontainer/'s
   Dockerfile (Debian 12 or Ubuntu 24.04) from the kit's root, every file the Dockerfile
   copies exists there, and the image gets its packages from `./kit packages` (no file of
   .devcontainer/ names one of them); it adds the desktop-lite feature, forwards the
   feature's web (noVNC) and VNC ports, sets LIBGL_ALWAYS_SOFTWARE=1 and a 24-bit desktop
   (VNC_RESOLUTION; the feature's default is 16-bit, where the stage's colours band) and runs
   `./kit setup` when the container is created.
2. The viewer on the container's kind of desktop: a TigerVNC X server (Xtigervnc, what
   desktop-lite runs) of the container's VNC_RESOLUTION, kit-view on it with the container's
   environment, and a screenshot taken as a VNC client (noVNC, a VNC viewer) gets it: the RFB
   protocol over the server's socket. The screenshot must hold kit-render's headless image of
   the same stage and size, pixel for pixel (as the viewer's window does under Xvfb).
   Witnesses: the same check fails on the screenshot of the display before the viewer
   starts, and with kit-render's image one pixel a step off on the viewer's screenshot. The
   viewer's frame rate on that display is printed (--spin --frames, as docs/performance.md
   measures it).
The screenshots are left in WORK_DIR (vnc-screenshot.png, vnc-before-viewer.png). Images are
read and written by png_rgb.py (the standard library), not by an image tool whose row order
may differ between releases.
"""
import json
import os
import re
import select
import shutil
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

from png_rgb import read_png, write_png

ROOT = Path(__file__).resolve().parents[1]
SIZE = (320, 240)
DESKTOP_LITE_RESOLUTION = "1440x768x16"  # the feature's default VNC_RESOLUTION
failures = []


def fail(message):
    failures.append(message)
    print(f"devcontainer: FAIL: {message}", flush=True)


def ok(message):
    print(f"devcontainer: ok: {message}", flush=True)


# --- 1. The configuration ------------------------------------------------------------------

def check_configuration():
    folder = ROOT / ".devcontainer"
    path = folder / "devcontainer.json"
    if not path.is_file():
        fail(f"{path} is missing")
        return {}
    try:  # JSONC allows comments; the kit keeps the file plain JSON so that this reads it
        config = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as e:
        fail(f"devcontainer.json is not plain JSON: {e}")
        return {}

    build = config.get("build", {})
    dockerfile = folder / build.get("dockerfile", "")
    context = (folder / build.get("context", ".")).resolve()
    if not build.get("dockerfile") or not dockerfile.is_file():
        fail(f"build.dockerfile names no file of .devcontainer/: {build}")
        return config
    if context != ROOT:
        fail(f"the build context is {context}, not the kit's root (\"context\": \"..\"): the image needs ./kit")
    lines = dockerfile.read_text(encoding="utf-8").splitlines()
    bases = [m.group(1) for m in (re.match(r"\s*FROM\s+(\S+)", line, re.I) for line in lines) if m]
    if bases and bases[0] in ("debian:12", "debian:bookworm", "ubuntu:24.04", "ubuntu:noble"):
        ok(f"Dockerfile FROM {bases[0]}")
    else:
        fail(f"the Dockerfile's base is {bases}, not debian:12 or ubuntu:24.04")
    for line in lines:  # COPY SRC... DEST: every SRC in the build context
        m = re.match(r"\s*(?:COPY|ADD)\s+(.*)", line, re.I)
        if m and "--from" not in line:
            sources = [s for s in m.group(1).split()[:-1] if not s.startswith("--")]
            for source in sources:
                if not (context / source).exists():
                    fail(f"the Dockerfile copies {source}, which is not in the build context {context}")

    # The packages: from ./kit packages, never a literal copy of the list.
    packages = subprocess.run([str(ROOT / "kit"), "packages"], capture_output=True, text=True, check=True).stdout.split()
    files = sorted(p for p in folder.rglob("*") if p.is_file())
    texts = {p.name: p.read_text(encoding="utf-8") for p in files}
    installer = [name for name, text in texts.items()
                 if re.search(r"kit\"?\s+packages\s*\|\s*xargs\s+(?:\S+\s+)*apt-get\s+install", text)]
    if installer:
        ok(f"the image installs `./kit packages` ({installer[0]}; {len(packages)} packages here)")
    else:
        fail("no file of .devcontainer/ installs the output of `./kit packages` (./kit packages | xargs apt-get install)")
    for name, text in texts.items():
        named = sorted(set(re.findall(r"[A-Za-z0-9][A-Za-z0-9+.-]*", text)) & set(packages))
        if named:
            fail(f".devcontainer/{name} names packages of the kit's list ({', '.join(named)}): print it, don't copy it")

    # The desktop, its ports, software OpenGL, the first set-up.
    features = config.get("features", {})
    desktop = [key for key in features if re.match(r"ghcr\.io/devcontainers/features/desktop-lite(:|$)", key)]
    if not desktop:
        fail(f"no desktop-lite feature: {list(features)}")
        return config
    options = features[desktop[0]]
    web, vnc = int(options.get("webPort", 6080)), int(options.get("vncPort", 5901))
    forwarded = [int(str(p).split(":")[-1]) for p in config.get("forwardPorts", [])]
    for port, what in ((web, "web (noVNC)"), (vnc, "VNC")):
        if port not in forwarded:
            fail(f"desktop-lite's {what} port {port} is not in forwardPorts {forwarded}")
        elif str(port) not in config.get("portsAttributes", {}):
            fail(f"port {port} has no portsAttributes (a label for the ports view)")
    if web in forwarded and vnc in forwarded:
        ok(f"{desktop[0]}: web port {web} and VNC port {vnc} forwarded")
    if config.get("containerEnv", {}).get("LIBGL_ALWAYS_SOFTWARE") == "1":
        ok("containerEnv LIBGL_ALWAYS_SOFTWARE=1")
    else:
        fail("containerEnv does not set LIBGL_ALWAYS_SOFTWARE=1 (software OpenGL)")
    resolution = config.get("containerEnv", {}).get("VNC_RESOLUTION", DESKTOP_LITE_RESOLUTION)
    if re.fullmatch(r"\d+x\d+x24", resolution):
        ok(f"containerEnv VNC_RESOLUTION={resolution}: 24-bit colour")
    else:
        fail(f"the desktop is {resolution}: not 24-bit colour (desktop-lite's default is {DESKTOP_LITE_RESOLUTION}, "
             "which bands the stage's colours): set containerEnv VNC_RESOLUTION to WxHx24")
    post = config.get("postCreateCommand", "")
    commands = post.values() if isinstance(post, dict) else [post]
    if any(re.search(r"(^|[\s;&])\./kit setup\b", c if isinstance(c, str) else " ".join(c)) for c in commands):
        ok("postCreateCommand runs ./kit setup")
    else:
        fail(f"postCreateCommand does not run ./kit setup: {post!r}")
    return config


# --- 2. The viewer on a VNC display ----------------------------------------------------------

def recv_exactly(sock, n):
    data = bytearray()
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("the VNC server closed the connection")
        data += chunk
    return bytes(data)


def vnc_screenshot(socket_path):
    """The whole framebuffer as a VNC client receives it (RFB 3.8, no authentication, raw
    encoding, 32-bit true colour): (width, height, RGB bytes)."""
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
        s.settimeout(10)
        s.connect(socket_path)
        version = recv_exactly(s, 12)
        if not version.startswith(b"RFB 003."):
            raise ConnectionError(f"not a VNC server: {version!r}")
        s.sendall(b"RFB 003.008\n")
        types = recv_exactly(s, recv_exactly(s, 1)[0])
        if 1 not in types:
            raise ConnectionError(f"the server wants authentication (security types {list(types)})")
        s.sendall(b"\x01")
        if struct.unpack(">I", recv_exactly(s, 4))[0] != 0:
            raise ConnectionError("security handshake refused")
        s.sendall(b"\x01")  # shared
        width, height = struct.unpack(">HH", recv_exactly(s, 4))
        recv_exactly(s, 16)
        recv_exactly(s, struct.unpack(">I", recv_exactly(s, 4))[0])
        # 32 bits a pixel, depth 24, little endian, true colour, 8 bits a channel: B, G, R, X.
        s.sendall(struct.pack(">B3xBBBBHHHBBB3x", 0, 32, 24, 0, 1, 255, 255, 255, 16, 8, 0))
        s.sendall(struct.pack(">BxHi", 2, 1, 0))  # encodings: raw only
        s.sendall(struct.pack(">BBHHHH", 3, 0, 0, 0, width, height))  # the whole screen
        rgb = bytearray(width * height * 3)
        while True:
            kind = recv_exactly(s, 1)[0]
            if kind == 2:  # bell
                continue
            if kind == 3:  # server cut text
                recv_exactly(s, 3)
                recv_exactly(s, struct.unpack(">I", recv_exactly(s, 4))[0])
                continue
            if kind != 0:
                raise ConnectionError(f"unexpected VNC message {kind}")
            recv_exactly(s, 1)
            for _ in range(struct.unpack(">H", recv_exactly(s, 2))[0]):
                x, y, w, h, encoding = struct.unpack(">HHHHi", recv_exactly(s, 12))
                if encoding != 0:
                    raise ConnectionError(f"unexpected encoding {encoding}")
                pixels = recv_exactly(s, w * h * 4)
                for row in range(h):
                    line = pixels[row * w * 4:(row + 1) * w * 4]
                    start = ((y + row) * width + x) * 3
                    rgb[start:start + w * 3:3] = line[2::4]
                    rgb[start + 1:start + w * 3:3] = line[1::4]
                    rgb[start + 2:start + w * 3:3] = line[0::4]
            return width, height, bytes(rgb)


def find_image(screen, image):
    """Where `image` lies in `screen`, pixel for pixel: (x, y), or None. The search runs on
    the image's most varied row, which a blank stretch of the screen cannot match."""
    sw, sh, srgb = screen
    iw, ih, irgb = image
    rows = [irgb[r * iw * 3:(r + 1) * iw * 3] for r in range(ih)]
    anchor = max(range(ih), key=lambda r: len({rows[r][i:i + 3] for i in range(0, iw * 3, 3)}))
    for y in range(anchor, sh - ih + anchor + 1):
        line = srgb[y * sw * 3:(y + 1) * sw * 3]
        at = line.find(rows[anchor])
        while at != -1:
            x, top = at // 3, y - anchor
            if at % 3 == 0 and x + iw <= sw and all(
                    srgb[((top + r) * sw + x) * 3:((top + r) * sw + x + iw) * 3] == rows[r] for r in range(ih)):
                return x, top
            at = line.find(rows[anchor], at + 1)
    return None


def start_vnc_server(work, geometry, depth):
    """Xtigervnc on a free display, its VNC socket in WORK (no TCP port, no password):
    (process, display, socket path)."""
    sock = work / "vnc.sock"
    read_fd, write_fd = os.pipe()
    server = subprocess.Popen(
        ["Xtigervnc", "-displayfd", str(write_fd), "-geometry", geometry, "-depth", depth,
         "-SecurityTypes", "None", "-rfbport", "-1", "-rfbunixpath", str(sock), "-nolisten", "tcp"],
        pass_fds=(write_fd,), stdout=open(work / "xtigervnc.log", "w"), stderr=subprocess.STDOUT)
    os.close(write_fd)
    number, deadline = b"", time.time() + 15
    while not number.endswith(b"\n") and select.select([read_fd], [], [], max(0, deadline - time.time()))[0]:
        chunk = os.read(read_fd, 16)  # the number, then a newline: the server stops if it cannot write it
        if not chunk:
            break
        number += chunk
    os.close(read_fd)
    number = number.decode().strip()
    if not number.isdigit():
        server.kill()
        raise RuntimeError(f"Xtigervnc did not start: {(work / 'xtigervnc.log').read_text()[-800:]}")
    deadline = time.time() + 10
    while not sock.exists() and time.time() < deadline:
        time.sleep(0.05)
    return server, f":{number}", str(sock)


def check_viewer_on_vnc(kit_view, kit_render, work, config):
    # The stage: lab 2's lighting where its solution is in the tree (the kit, a copy for
    # lab 3 or later); else the G-buffer, from lab 1's solution or, in a copy for lab 1,
    # its starter (which draws the base colours).
    if (ROOT / "solutions/01-gbuffer").is_dir() and (ROOT / "solutions/02-lighting").is_dir():
        args = ["--stage", "lighting", "--shaders", str(ROOT / "solutions")]
    elif (ROOT / "solutions/01-gbuffer").is_dir():
        args = ["--stage", "gbuffer", "--shaders", str(ROOT / "solutions")]
    else:
        args = ["--stage", "gbuffer", "--shaders", str(ROOT / "labs")]
    if not shutil.which("Xtigervnc"):  # a failure, never a skip: the desktop would go untested
        fail("not installed: Xtigervnc (tigervnc-standalone-server; ./kit setup installs it)")
        return
    size = f"{SIZE[0]}x{SIZE[1]}"
    headless_png = work / "headless.png"
    subprocess.run([kit_render, *args, "--size", size, "--out", str(headless_png)], check=True)
    headless = read_png(headless_png)

    # The desktop's size and depth: desktop-lite's VNC_RESOLUTION (WxHxDEPTH), as the container sets it.
    resolution = config.get("containerEnv", {}).get("VNC_RESOLUTION", DESKTOP_LITE_RESOLUTION)
    geometry, depth = resolution.rsplit("x", 1)
    server, display, sock = start_vnc_server(work, geometry, depth)
    env = dict(os.environ, DISPLAY=display, **config.get("containerEnv", {}))
    viewer = None
    try:
        before = vnc_screenshot(sock)
        write_png(work / "vnc-before-viewer.png", *before)
        if find_image(before, headless) is None:
            ok(f"witness: the display without the viewer ({before[0]}x{before[1]}) does not hold the stage")
        else:
            fail("witness: the stage was found on the display before the viewer started")

        viewer = subprocess.Popen([kit_view, *args, "--no-ui", "--size", size], env=env,
                                  stdout=open(work / "viewer.log", "w"), stderr=subprocess.STDOUT)
        started, found, shot = time.time(), None, before
        while found is None and time.time() - started < 30 and viewer.poll() is None:
            time.sleep(0.25)
            shot = vnc_screenshot(sock)
            found = find_image(shot, headless)
        write_png(work / "vnc-screenshot.png", *shot)
        # Witness: the stage with one pixel changed (the middle one, a step of its red) is not
        # found in the screenshot: the check is pixel for pixel.
        w, h, rgb = headless
        middle = ((h // 2) * w + w // 2) * 3
        changed = bytearray(rgb)
        changed[middle] = rgb[middle] + 1 if rgb[middle] < 255 else 254
        if found and find_image(shot, (w, h, bytes(changed))) is None:
            ok("witness: the stage with one pixel a step off is not found in the screenshot")
        elif found:
            fail("witness: the stage with one pixel changed was found in the screenshot too")
        if found:
            ok(f"the VNC display {display} shows the {args[1]} stage at {found}, pixel for pixel as kit-render's "
               f"{size} image ({time.time() - started:.1f} s after the viewer started)")
        else:
            why = f"the viewer exited with status {viewer.returncode}" if viewer.poll() is not None else "30 s"
            fail(f"the VNC display never showed kit-render's {args[1]} image ({why}); viewer log: "
                 f"{(work / 'viewer.log').read_text()[-800:]}")
        viewer.terminate()
        viewer.wait(10)
        viewer = None

        # The frame rate there, the camera turning (frames at half size, as while dragging).
        timings = subprocess.run([kit_view, *args, "--no-ui", "--size", "640x480", "--spin", "--frames", "30",
                                  "--timings"], env=env, capture_output=True, text=True, timeout=60)
        lines = [l for l in (timings.stdout + timings.stderr).splitlines() if "timings" in l]
        if timings.returncode == 0 and lines:
            for line in lines:
                ok(f"on the VNC display, 640x480, --spin: {line}")
        else:
            fail(f"kit-view --spin --frames 30 on the VNC display: status {timings.returncode}: {timings.stderr[-800:]}")
    finally:
        if viewer is not None:
            viewer.kill()
        server.terminate()
        try:
            server.wait(10)
        except subprocess.TimeoutExpired:
            server.kill()


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    kit_view, kit_render, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    work.mkdir(parents=True, exist_ok=True)
    for old in work.iterdir():
        if old.is_file() or old.is_socket():
            old.unlink()
    config = check_configuration()
    if config:
        try:
            check_viewer_on_vnc(kit_view, kit_render, work, config)
        except (OSError, subprocess.SubprocessError, RuntimeError) as e:
            fail(f"the viewer on a VNC display: {e}")
    if failures:
        print(f"devcontainer: {len(failures)} check(s) failed")
        return 1
    print("devcontainer: every check passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
