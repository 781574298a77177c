#!/usr/bin/python3
"""The PDF progress report a student hands in: ./kit progress-report.

For each lab: the grader's checks (kit-grade on the student's labs/ folder),
each with the student's render, the reference and their difference, the
verdicts and scores, and the stage's frame time (kit-render --frames). Then
the student's notes (a Markdown file) and, first, a title page.

Written with matplotlib's PDF backend (Debian's python3-matplotlib, which
belongs to /usr/bin/python3) and numpy; nothing else outside the standard
library.
"""
import argparse
import datetime
import getpass
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import textwrap
import warnings

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LAB_FOLDER = re.compile(r"^(\d\d)-([a-z]+)$")


def kit_stages():
    """{lab number: stage name} from the kit's lab folders (NN-name, the stage table's
    folders): labs/ and solutions/ together, since a student copy for lab N holds the
    starters of labs N and later and the solutions of the others."""
    stages = {}
    for folder in ("labs", "solutions"):
        path = os.path.join(ROOT, folder)
        for m in (LAB_FOLDER.match(n) for n in (os.listdir(path) if os.path.isdir(path) else [])):
            if m:
                stages[int(m.group(1))] = m.group(2)
    return stages


STAGES = kit_stages()

# Frame time: the first frame holds llvmpipe's shader JIT and is dropped; the median of the rest.
TIMING_FRAMES = 6
TIMING_SIZE = "640x480"
TIMING_LIMIT_S = 60  # an endless loop in a shader must not hang the report

A4 = (8.27, 11.69)  # inches, portrait
MARGIN = 0.6

NOTES_TEMPLATE = """\
# Progress notes

Write here what you did in each lab, what went wrong and how you fixed it.
`./kit progress-report` puts this file at the end of the PDF; headings, paragraphs,
bullet lists, `inline code`, **bold** and *italic* are shown.

## What I did

- Lab 1: ...

## Problems and how I solved them

- ...

## Open questions

- ...
"""


class ReportError(Exception):
    pass


def say(message):
    print("progress-report: " + message, file=sys.stderr)


# ---------------------------------------------------------------- arguments

def parse_lab_list(text):
    labs = set()
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        m = re.fullmatch(r"(\d+)(?:-(\d+))?", part)
        name = [n for n, s in STAGES.items() if s == part]
        if name:
            labs.add(name[0])
        elif m:
            a, b = int(m.group(1)), int(m.group(2) or m.group(1))
            if a > b or a not in STAGES or b not in STAGES:
                raise ReportError(f"--labs: '{part}' is not a lab ({min(STAGES)} to {max(STAGES)})")
            labs.update(range(a, b + 1))
        else:
            raise ReportError(f"--labs: '{part}' is not a lab number, range (1-3) or stage name")
    if not labs:
        raise ReportError("--labs: no lab given")
    return sorted(labs)


def labs_present(labs_dir):
    if not os.path.isdir(labs_dir):
        raise ReportError(f"no labs folder at {labs_dir}")
    found = sorted(int(m.group(1)) for m in (LAB_FOLDER.match(n) for n in os.listdir(labs_dir))
                   if m and os.path.isdir(os.path.join(labs_dir, m.group(0))))
    if not found:
        raise ReportError(f"no lab folders (01-gbuffer, ...) in {labs_dir}")
    # Only the labs this kit can assemble: a stage is built on the solutions of the
    # labs before it, and a student copy for lab N has those of labs 1..N-1 alone.
    solutions = os.path.join(ROOT, "solutions")
    released = {int(m.group(1)) for m in (LAB_FOLDER.match(n) for n in os.listdir(solutions)) if m} \
        if os.path.isdir(solutions) else set()
    usable = [n for n in found if all(k in released for k in range(1, n))]
    if len(usable) < len(found):
        print(f"progress-report: labs {', '.join(str(n) for n in found if n not in usable)} left out: "
              "they are built on solutions this kit does not have yet", file=sys.stderr)
    if not usable:
        raise ReportError(f"no lab in {labs_dir} can be rendered here: the solutions they build on are missing")
    return usable


def check_output_path(out):
    if os.path.isdir(out):
        raise ReportError(f"cannot write {out}: it is a folder (give a file name, e.g. {os.path.join(out, 'report.pdf')})")
    folder = os.path.dirname(out) or "."
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as e:
        raise ReportError(f"cannot write {out}: cannot create {folder} ({e.strerror})")
    if not os.access(folder, os.W_OK | os.X_OK) or (os.path.exists(out) and not os.access(out, os.W_OK)):
        raise ReportError(f"cannot write {out}: permission denied")


# ---------------------------------------------------------------- grading and timing

def run_grader(kit_grade, labs_dir, labs, out_dir, references):
    """kit-grade into out_dir. Returns (summary, results) or, when the grader cannot
    grade here because the references are missing, (None, its message)."""
    command = [kit_grade, labs_dir, "--labs", ",".join(map(str, labs)), "--out", out_dir]
    if references:
        command += ["--references", references]
    try:
        run = subprocess.run(command, capture_output=True, text=True, errors="replace", timeout=900)
    except subprocess.TimeoutExpired:
        raise ReportError("kit-grade did not finish in 15 minutes")
    message = (run.stderr.strip() or run.stdout.strip()).replace("kit-grade: ", "")
    if run.returncode != 0 or not os.path.exists(os.path.join(out_dir, "summary.json")):
        if "references missing" in message or ("references" in message and "stale" in message):
            return None, message
        raise ReportError("kit-grade could not grade " + labs_dir + ":\n" + message)
    with open(os.path.join(out_dir, "summary.json"), encoding="utf-8") as f:
        summary = json.load(f)
    with open(os.path.join(out_dir, "results.json"), encoding="utf-8") as f:
        results = json.load(f)
    return summary, results


def measure_frame_time(kit_render, labs_dir, lab, image_out):
    """Runs the student's stage on the default scene. Returns a dict with
    median_ms, frames_ms (the ones the median is taken over), renderer and
    command, or error (kit-render's message)."""
    command = [kit_render, "--stage", str(lab), "--shaders", labs_dir, "--scene", "default",
               "--size", TIMING_SIZE, "--frames", str(TIMING_FRAMES), "--timings", "--out", image_out]
    shown = "kit-render --stage {} --shaders {} --scene default --size {} --frames {} --timings".format(
        STAGES[lab], os.path.basename(os.path.normpath(labs_dir)), TIMING_SIZE, TIMING_FRAMES)
    try:
        run = subprocess.run(command, capture_output=True, text=True, errors="replace", timeout=TIMING_LIMIT_S)
    except subprocess.TimeoutExpired:
        return {"error": f"kit-render did not finish in {TIMING_LIMIT_S} s (an endless loop?)", "command": shown}
    if run.returncode != 0:
        return {"error": run.stderr.strip().replace("kit-render: ", "") or f"kit-render exited with {run.returncode}",
                "command": shown}
    frames = re.search(r"^frame ms: (.*)$", run.stderr, re.M)
    renderer = re.search(r"^timings: .*?, write [0-9.]+s \((.*)\)$", run.stderr, re.M)
    if not frames:
        return {"error": "kit-render printed no frame times (is it older than --frames?)", "command": shown}
    times = [float(t) for t in frames.group(1).split()][1:]
    return {"median_ms": statistics.median(times), "frames_ms": times, "command": shown,
            "renderer": renderer.group(1) if renderer else "", "image": image_out}


def kit_version():
    try:
        run = subprocess.run(["git", "-C", ROOT, "describe", "--tags", "--always", "--dirty"],
                             capture_output=True, text=True, timeout=20)
        if run.returncode == 0 and run.stdout.strip():
            return run.stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        pass
    return "unknown (not a git checkout)"


def student_name(given):
    if given:
        return given
    try:
        run = subprocess.run(["git", "-C", ROOT, "config", "user.name"], capture_output=True, text=True, timeout=20)
        if run.returncode == 0 and run.stdout.strip():
            return run.stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        pass
    try:
        return getpass.getuser()
    except Exception:  # no login name in a container
        return "(unknown: use --student NAME)"


def format_score(value):
    # kit-grade's scores are exact thousandths (6.667): printed as kit-grade prints them.
    return ("%.3f" % value).rstrip("0").rstrip(".")


def format_ms(value):
    return "%.1f ms" % value if value >= 10 else "%.2f ms" % value


# ---------------------------------------------------------------- Markdown

INLINE = re.compile(r"(`+)(.+?)\1|\*\*(.+?)\*\*|__(.+?)__|(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?!\w)|"
                    r"(?<![\w_])_(?!\s)(.+?)(?<!\s)_(?!\w)|!?\[([^\]]*)\]\(([^)\s]*)[^)]*\)")


def inline_runs(text):
    """Markdown inline text -> [(text, style)], style one of normal, bold, italic, code."""
    runs, pos = [], 0
    for m in INLINE.finditer(text):
        if m.start() > pos:
            runs.append((text[pos:m.start()], "normal"))
        if m.group(2) is not None:
            runs.append((m.group(2).strip(" ") or m.group(2), "code"))
        elif m.group(3) is not None or m.group(4) is not None:
            runs.append((m.group(3) if m.group(3) is not None else m.group(4), "bold"))
        elif m.group(5) is not None or m.group(6) is not None:
            runs.append((m.group(5) if m.group(5) is not None else m.group(6), "italic"))
        else:
            label, target = m.group(7), m.group(8)
            if m.group(0).startswith("!"):
                runs.append((f"[image: {label or target}]", "italic"))
            else:
                runs.append((label, "normal"))
                if target and target != label:
                    runs.append((f" ({target})", "normal"))
        pos = m.end()
    if pos < len(text):
        runs.append((text[pos:], "normal"))
    # Backslash escapes: \* \_ \` ... show the character.
    return [(re.sub(r"\\([\\`*_{}\[\]()#+\-.!|>])", r"\1", t) if s != "code" else t, s) for t, s in runs]


def markdown_blocks(text):
    """Markdown -> blocks: (kind, level, payload). kind: heading (level 1-6, text),
    para (text), bullet (indent level, marker, text), code (lines), rule, blank."""
    blocks, para, fence = [], [], None
    code = []

    def flush():
        if para:
            blocks.append(("para", 0, " ".join(s.strip() for s in para)))
            para.clear()

    for raw in text.replace("\t", "    ").splitlines():
        line = raw.rstrip()
        if fence is not None:
            if line.strip().startswith(fence):
                blocks.append(("code", 0, code))
                fence, code = None, []
            else:
                code.append(line)
            continue
        m = re.match(r"^\s*(```+|~~~+)", line)
        if m:
            flush()
            fence = m.group(1)
            continue
        if not line.strip():
            flush()
            continue
        m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if m:
            flush()
            blocks.append(("heading", len(m.group(1)), m.group(2)))
            continue
        if re.match(r"^\s{0,3}([-*_])(\s*\1){2,}\s*$", line):
            flush()
            blocks.append(("rule", 0, ""))
            continue
        m = re.match(r"^(\s*)([-*+]|\d+[.)])\s+(.*)$", line)
        if m:
            flush()
            marker = "\u2022" if m.group(2) in "-*+" else m.group(2)
            blocks.append(("bullet", min(len(m.group(1)) // 2, 4), (marker, m.group(3))))
            continue
        if blocks and blocks[-1][0] == "bullet" and not para and raw.startswith(" "):
            kind, level, (marker, item) = blocks[-1]  # a bullet's continuation line
            blocks[-1] = (kind, level, (marker, item + " " + line.strip()))
            continue
        if line.lstrip().startswith(">"):
            line = line.lstrip()[1:]
        para.append(line)
    flush()
    if fence is not None:
        blocks.append(("code", 0, code))
    return blocks


# ---------------------------------------------------------------- PDF pages

class Pdf:
    """Pages of text and images laid out in inches from the top left corner."""

    def __init__(self, path):
        import matplotlib
        matplotlib.use("pdf")
        matplotlib.rcParams["pdf.fonttype"] = 42  # TrueType: text can be searched and copied
        matplotlib.rcParams["font.family"] = "DejaVu Sans"
        from matplotlib.backends.backend_pdf import PdfPages
        from matplotlib.font_manager import FontProperties
        from matplotlib.textpath import TextToPath
        from matplotlib.transforms import Bbox, TransformedBbox
        self.Bbox, self.TransformedBbox = Bbox, TransformedBbox
        import matplotlib.pyplot as plt
        self.plt = plt
        self.pages = PdfPages(path)
        self.measure = TextToPath()
        self.FontProperties = FontProperties
        self.figure = None
        self.count = 0
        self.widths = {}

    def new_page(self):
        self.end_page()
        self.figure = self.plt.figure(figsize=A4)
        self.count += 1
        self.text(A4[0] - MARGIN, A4[1] - 0.35, f"page {self.count}", size=7, color="#888", ha="right")

    def end_page(self):
        if self.figure is not None:
            self.pages.savefig(self.figure)
            self.plt.close(self.figure)
            self.figure = None

    def close(self):
        self.end_page()
        self.pages.close()

    def font(self, style="normal", size=10):
        family = "DejaVu Sans Mono" if style == "code" else "DejaVu Sans"
        return self.FontProperties(family=family, size=size,
                                   weight="bold" if style == "bold" else "normal",
                                   style="italic" if style == "italic" else "normal")

    def width(self, text, style="normal", size=10):
        if not text:
            return 0.0
        key = (text, style, size)
        if key not in self.widths:  # a page measures the same words many times
            w, _, _ = self.measure.get_text_width_height_descent(text, self.font(style, size), ismath=False)
            self.widths[key] = w / 72.0
        return self.widths[key]

    @staticmethod
    def line_height(size, line=1.35):
        """Inches from one line's top to the next's. DejaVu's glyph box (ascent + descent)
        is 1.17 em: line spacing below about 1.2 lays lines over each other."""
        return size * line / 72.0

    def lines(self, text, width, size=9, style="normal"):
        """text (newlines kept) broken into lines no wider than width inches, measured:
        at spaces, and inside a word only where the word alone is wider than the line."""
        out = []
        for paragraph in text.split("\n"):
            current = ""
            for word in paragraph.split():
                candidate = current + " " + word if current else word
                if self.width(candidate, style, size) <= width:
                    current = candidate
                    continue
                if current:
                    out.append(current)
                while self.width(word, style, size) > width and len(word) > 1:
                    low, high = 1, len(word) - 1  # the longest head that fits: a binary search
                    while low < high:
                        mid = (low + high + 1) // 2
                        low, high = (mid, high) if self.width(word[:mid], style, size) <= width else (low, mid - 1)
                    cut = low
                    out.append(word[:cut])
                    word = word[cut:]
                current = word
            out.append(current)
        return out

    def fitted(self, text, width, size, style="normal", max_lines=2, smallest=5.5):
        """(lines, size): text in at most max_lines lines of width inches, without breaking a
        word, at the largest size from size down to smallest (then broken wherever it must)."""
        s = size
        while True:
            lines = self.lines(text, width, s, style)
            whole = all(self.width(w, style, s) <= width for w in text.split())
            if (len(lines) <= max_lines and whole) or s <= smallest:
                return lines, s
            s = max(smallest, s - 0.5)

    def text(self, x, y_top, text, size=10, style="normal", color="#222", ha="left", va="top", **kw):
        """Text at x inches from the left, y_top inches from the top."""
        self.figure.text(x / A4[0], 1.0 - y_top / A4[1], text, fontproperties=self.font(style, size), color=color,
                         ha=ha, va=va, parse_math=False, **kw)

    def image(self, path, x, y_top, w, h, title=None, border="#999"):
        """An image fitted into the box, centred, with a thin border. Drawn as a BboxImage and a
        rectangle, not an Axes: an Axes (ticks, spines) costs about ten times as much, and a
        report of every lab has 160 images."""
        import matplotlib.image as mpimg
        from matplotlib.patches import Rectangle
        pixels = mpimg.imread(path) if path and os.path.exists(path) else None
        if pixels is not None:
            # Lab 6's maps (2:1, square, 256x252) keep their shape inside the 4:3 box.
            scale = min(w / pixels.shape[1], h / pixels.shape[0])
            dw, dh = pixels.shape[1] * scale, pixels.shape[0] * scale
            bx, by = x + (w - dw) / 2, y_top + (h - dh) / 2
        else:
            bx, by, dw, dh = x, y_top, w, h
        bounds = (bx / A4[0], (A4[1] - by - dh) / A4[1], dw / A4[0], dh / A4[1])
        if pixels is not None:
            image = mpimg.BboxImage(self.TransformedBbox(self.Bbox.from_bounds(*bounds), self.figure.transFigure),
                                    interpolation="nearest", origin="upper")
            image.set_data(pixels)
            self.figure.add_artist(image)
        else:
            self.text(x + w / 2, y_top + h / 2, "no image", size=7, color="#777", ha="center", va="center")
        self.figure.patches.append(Rectangle(bounds[:2], bounds[2], bounds[3], transform=self.figure.transFigure,
                                             facecolor="none" if pixels is not None else "#eee", edgecolor=border,
                                             linewidth=0.8, zorder=2 if pixels is not None else 0))
        if title:
            lines, size = self.fitted(title, w, 7, max_lines=1)
            self.text(x, y_top + h + 0.01, " ".join(lines), size=size, color="#555")

    def box(self, x, y_top, w, h, color):
        from matplotlib.patches import Rectangle
        self.figure.patches.append(Rectangle((x / A4[0], (A4[1] - y_top - h) / A4[1]), w / A4[0], h / A4[1],
                                             transform=self.figure.transFigure, facecolor=color, edgecolor="none"))

    def wrapped(self, x, y, width, text, size=9, style="normal", color="#222", line=1.35, max_lines=None):
        """Plain text wrapped to width inches (measured); returns the y below it. Beyond
        max_lines the last line says how many more there were."""
        lines = self.lines(text, width, size, style)
        if max_lines and len(lines) > max_lines:
            lines = lines[:max_lines - 1] + [f"[... {len(lines) - max_lines + 1} more lines]"]
        for l in lines:
            self.text(x, y, l, size=size, style=style, color=color)
            y += self.line_height(size, line)
        return y


def verdict_color(passed):
    return "#1a7f37" if passed else "#c62828"


def title_page(pdf, info, labs, summary, timings, problem):
    pdf.new_page()
    x = MARGIN + 0.2
    pdf.text(x, 1.3, "Progress report", size=28, style="bold")
    pdf.text(x, 1.85, "Deferred rendering labs (OpenGL 3.3 core)", size=13, color="#555")
    y = 2.6
    total = max_total = 0.0
    for lab in labs:
        entry = summary["labs"].get(str(lab)) if summary else None
        if entry:
            total += entry["score"]
            max_total += entry["max_score"]
    rows = [("Student", info["student"]), ("Date", info["date"]), ("Kit version", info["version"]),
            ("Labs included", ", ".join(f"{n} {STAGES[n]}" for n in labs)),
            ("Total score", f"{format_score(total)} / {format_score(max_total)}" if summary else "not graded (see below)")]
    for key, value in rows:
        pdf.text(x, y, key, size=11, color="#555")
        # A long name or version wraps in its column.
        below = pdf.wrapped(x + 1.6, y, A4[0] - MARGIN - x - 1.6, value, size=11, line=1.3,
                            style="bold" if key == "Total score" else "normal")
        y = max(y + 0.32, below + 0.12)
    y += 0.3
    pdf.text(x, y, "Labs", size=14, style="bold")
    y += 0.35
    columns = [x, x + 2.0, x + 3.1, x + 5.3]
    for cx, head in zip(columns, ["lab", "score", "result", "frame time"]):
        pdf.text(cx, y, head, size=9, style="bold", color="#555")
    y += 0.25
    for lab in labs:
        entry = summary["labs"].get(str(lab)) if summary else None
        t = timings.get(lab, {})
        pdf.text(columns[0], y, f"{lab} {STAGES[lab]}", size=10)
        if entry:
            pdf.text(columns[1], y, f"{format_score(entry['score'])} / {format_score(entry['max_score'])}", size=10,
                     color=verdict_color(entry["score"] >= entry["max_score"] - 1e-9))
            result = (f"{entry['checks_passed']} of {len(entry['checks'])} checks passed" if entry["status"] == "graded"
                      else entry["status"].replace("_", " "))
        else:
            pdf.text(columns[1], y, "not graded", size=10, color="#777")
            result = ""
        lines, size = pdf.fitted(result, columns[3] - columns[2] - 0.1, 10, max_lines=1)
        pdf.text(columns[2], y, " ".join(lines), size=size)
        pdf.text(columns[3], y, format_ms(t["median_ms"]) if "median_ms" in t else "not measured", size=10,
                 color="#222" if "median_ms" in t else "#777")
        y += 0.27
    y += 0.35
    pdf.text(x, y, "How this was made", size=14, style="bold")
    y += 0.35
    width = A4[0] - 2 * x
    if summary:
        grading = (f"Scores: kit-grade on {info['labs_dir']} (the course's autograder: the same checks, references "
                   f"and tolerances), rendered at 256x192 with {summary.get('renderer') or 'the headless renderer'}. "
                   "Each lab page shows every check: your render, the reference and the difference "
                   "(|yours - reference| x 16, inferno colour map). The grade that counts is the one your instructor "
                   "runs on your submission.")
    else:
        grading = ("Scores: none. kit-grade could not grade here: " + problem +
                   " The lab pages show your renders only; your instructor's grader grades the submission.")
    y = pdf.wrapped(x, y, width, grading, size=9) + 0.12
    renderer = next((t["renderer"] for t in timings.values() if t.get("renderer")), "the headless renderer")
    timing = (f"Frame time: kit-render renders your stage on the default scene at {TIMING_SIZE}, {TIMING_FRAMES} frames "
              f"in one process (kit-render --stage NAME --shaders labs --frames {TIMING_FRAMES} --timings); each frame "
              "is timed by the wall clock from the start of the geometry pass to glFinish after the display pass. The "
              "first frame (which holds the shader compilation of the driver) is dropped and the median of the other "
              f"{TIMING_FRAMES - 1} is shown. Renderer: {renderer}. On this software renderer the times depend on the "
              "machine and on what else runs on it: compare them with times taken on the same machine.")
    y = pdf.wrapped(x, y, width, timing, size=9) + 0.12
    if summary and (summary.get("problem") or summary.get("notes")):
        text = "Grader: " + " ".join([summary.get("problem", "")] + summary.get("notes", [])).strip()
        pdf.wrapped(x, y, width, text, size=9, color="#c62828",
                    max_lines=max(1, int((A4[1] - MARGIN - y) / pdf.line_height(9))))


def ordered_checks(lab, entry, results):
    """The lab's checks in the grader's order (results.json), each (key, check)."""
    prefix = f"lab {lab} {STAGES[lab]}: "
    order = {t["name"][len(prefix):]: i for i, t in enumerate(results.get("tests", [])) if t["name"].startswith(prefix)}
    items = list(entry["checks"].items())
    return sorted(items, key=lambda kv: order.get(kv[1].get("title", kv[0]), len(order)))


def lab_header(pdf, lab, line, color, timing):
    x = MARGIN
    title = f"Lab {lab}: {STAGES[lab]}"
    pdf.text(x, 0.75, title, size=18, style="bold")
    y = 1.2
    if x + pdf.width(title, "bold", 18) + 0.3 + pdf.width(line, "bold", 13) <= A4[0] - MARGIN:
        pdf.text(A4[0] - MARGIN, 0.78, line, size=13, style="bold", color=color, ha="right")
    else:  # a long verdict would run into the title: it gets a line of its own
        pdf.text(A4[0] - MARGIN, 1.1, line, size=13, style="bold", color=color, ha="right")
        y = 1.5
    if "median_ms" in timing:
        frames = ", ".join("%.1f" % t for t in timing["frames_ms"])
        label = f"Frame time: {format_ms(timing['median_ms'])}"
        pdf.text(x, y, label, size=10, style="bold")
        indent = max(1.75, pdf.width(label, "bold", 10) + 0.15)
        y = pdf.wrapped(x + indent, y, A4[0] - 2 * MARGIN - indent,
                        f"median of {len(timing['frames_ms'])} frames ({frames} ms) after one warm-up frame; "
                        f"default scene, {TIMING_SIZE}; {timing['command']}", size=7.5, color="#555")
    else:
        y = pdf.wrapped(x, y, A4[0] - 2 * MARGIN, "Frame time: not measured: " + timing.get("error", "the lab did not render"),
                        size=9, color="#777", max_lines=3)
    return y + 0.15


# The lab pages' check rows (inches, points): a title in bold, the verdict line, the numbers.
TITLE_SIZE, TITLE_LINE = 8.5, 1.25
VERDICT_GAP, VERDICT_H = 0.02, 0.17  # the verdict line starts VERDICT_GAP below the title; the numbers VERDICT_H below it
NUMBERS_SIZE, NUMBERS_LINE = 6.5, 1.35
PAGE_BOTTOM = A4[1] - MARGIN - 0.1
ROW_MAX, ROW_MIN = 1.42, 0.55
IMAGE_GAP = 0.1


def continued_page(pdf, lab):
    """A lab page's continuation: a small header; returns the y to go on at."""
    pdf.new_page()
    pdf.text(MARGIN, 0.75, f"Lab {lab}: {STAGES[lab]} (continued)", size=12, style="bold")
    return 1.15


def check_layout(pdf, checks, top):
    """Sizes a lab's check rows to share the page below top: the column headers, then a row per
    check, as tall as the images (the same for every row: up to ROW_MAX, less when a lab has many
    checks; lab 1 has 15) or as its text needs at least (its title, however many lines it wraps
    to, the verdict and two lines of numbers), whichever is more. The text column has the width
    the images leave. Returns (img_w, text_w, column heads [(lines, size)], the heads' height,
    [(title lines, row height)]); the rows may not fit when the text alone is too tall."""
    title_lh = pdf.line_height(TITLE_SIZE, TITLE_LINE)
    numbers_lh = pdf.line_height(NUMBERS_SIZE, NUMBERS_LINE)

    def layout(row_h):
        img_w = min((row_h - 0.18) * 4 / 3, (A4[0] - 2 * MARGIN - 2.35 - 2 * IMAGE_GAP) / 3)  # text column >= 2.3 in
        text_w = A4[0] - 2 * MARGIN - 3 * img_w - 2 * IMAGE_GAP - 0.05
        names = ("your render", "reference", "difference x16")
        size = min(pdf.fitted(h, img_w, 8, "bold")[1] for h in names)  # one size for the three
        heads = [(pdf.lines(h, img_w, size, "bold"), size) for h in names]
        head_h = max(len(lines) * pdf.line_height(size, 1.25) for lines, size in heads) + 0.07
        rows = []
        for key, c in checks:
            title = pdf.lines(c.get("title", key), text_w - 0.12, TITLE_SIZE, "bold")
            text_h = len(title) * title_lh + VERDICT_GAP + VERDICT_H + 2 * numbers_lh
            rows.append((title, max(row_h, text_h)))
        return img_w, text_w, heads, head_h, rows

    def height(l):
        return l[3] + sum(h for _, h in l[4])

    # The tallest rows that fit (the text column narrows as the images grow, so a bisection),
    # down to ROW_MIN: below that the images would be too small to see, and rows go on a new page.
    low, high = ROW_MIN, ROW_MAX
    if height(layout(high)) <= PAGE_BOTTOM - top:
        return layout(high)
    for _ in range(20):
        mid = (low + high) / 2
        low, high = (mid, high) if height(layout(mid)) <= PAGE_BOTTOM - top else (low, mid)
    return layout(low)


def column_heads(pdf, y, columns, heads, head_h):
    for cx, (lines, size) in zip(columns, heads):
        for i, l in enumerate(lines):
            pdf.text(cx, y + i * pdf.line_height(size, 1.25), l, size=size, style="bold", color="#555")
    return y + head_h


def lab_page(pdf, lab, entry, results, grade_dir, timing):
    pdf.new_page()
    graded = entry["status"] == "graded"
    if graded:
        line = (f"{format_score(entry['score'])} / {format_score(entry['max_score'])}   "
                f"({entry['checks_passed']} of {len(entry['checks'])} checks passed)")
    else:
        line = f"{format_score(entry['score'])} / {format_score(entry['max_score'])}   ({entry['status'].replace('_', ' ')})"
    y = lab_header(pdf, lab, line, verdict_color(entry["score"] >= entry["max_score"] - 1e-9), timing)
    checks = ordered_checks(lab, entry, results)
    x = MARGIN
    if not graded:
        pdf.text(x, y, "The grader's message", size=11, style="bold", color="#c62828")
        y += 0.25
        y = pdf.wrapped(x, y, A4[0] - 2 * MARGIN, entry.get("message") or "(no message)", size=7.5, style="code",
                        max_lines=45) + 0.25
        if y + 0.55 > PAGE_BOTTOM:
            y = continued_page(pdf, lab)
        pdf.text(x, y, "Checks (none rendered)", size=11, style="bold")
        y += 0.3
        for key, c in checks:
            title = pdf.lines(c.get("title", key), 3.35, 9)
            if y + len(title) * pdf.line_height(9) > PAGE_BOTTOM:
                y = continued_page(pdf, lab)
            pdf.text(x + 3.5, y, "not graded", size=9, color="#c62828")
            pdf.text(x + 5.0, y, f"{format_score(c['score'])} / {format_score(c['max_score'])}", size=9)
            y = pdf.wrapped(x, y, 3.35, c.get("title", key), size=9) + 0.22 - pdf.line_height(9)
        return
    # The grader's guess at the mistake behind the failed checks (tools/grade/diagnosis.h),
    # first in each failed check's text.
    guess = (entry["likely_text"] + " ") if entry.get("likely_text") else ""
    img_w, text_w, heads, head_h, rows = check_layout(pdf, checks, y)
    img_h = img_w * 3 / 4
    columns = [x + text_w + i * (img_w + IMAGE_GAP) for i in range(3)]
    numbers_lh = pdf.line_height(NUMBERS_SIZE, NUMBERS_LINE)
    y = column_heads(pdf, y, columns, heads, head_h)
    for (key, c), (title, row_h) in zip(checks, rows):
        passed = c["passed"]
        below = y + len(title) * pdf.line_height(TITLE_SIZE, TITLE_LINE)
        numbers_top = below + VERDICT_GAP + VERDICT_H
        words = (guess if not passed else "") + ((c.get("note") + ". ") if c.get("note") else "") + (c.get("summary") or "")
        numbers = pdf.lines(words, text_w - 0.12, NUMBERS_SIZE)
        # The numbers get the lines left in the row (two at least: one and the count of the rest);
        # a row that needs more than its share is taller, and goes to a new page if it must.
        room = max(2, int((y + row_h - numbers_top) / numbers_lh + 1e-6))
        if len(numbers) > room:
            numbers = numbers[:room - 1] + [f"[... {len(numbers) - room + 1} more lines]"]
        height = max(row_h, numbers_top - y + len(numbers) * numbers_lh)
        if y + height > PAGE_BOTTOM + 1e-6:
            y = column_heads(pdf, continued_page(pdf, lab), columns, heads, head_h)
            below = y + len(title) * pdf.line_height(TITLE_SIZE, TITLE_LINE)
            numbers_top = below + VERDICT_GAP + VERDICT_H
        pdf.box(x - 0.08, y, 0.04, img_h, verdict_color(passed))
        for i, l in enumerate(title):
            pdf.text(x, y + i * pdf.line_height(TITLE_SIZE, TITLE_LINE), l, size=TITLE_SIZE, style="bold")
        pdf.text(x, below + VERDICT_GAP, ("passed" if passed else "failed") +
                 f"   {format_score(c['score'])} / {format_score(c['max_score'])}",
                 size=TITLE_SIZE, style="bold", color=verdict_color(passed))
        for i, l in enumerate(numbers):
            pdf.text(x, numbers_top + i * numbers_lh, l, size=NUMBERS_SIZE, color="#444")
        # The toggle check compares the effect on with your own render with it off.
        ref_title = "yours, effect off" if key == "custom-on" else None
        for i, (cx, field) in enumerate(zip(columns, ["image", "reference", "diff"])):
            path = os.path.join(grade_dir, c[field]) if c.get(field) else None
            pdf.image(path, cx, y, img_w, img_h, title=ref_title if i == 1 else None)
        y += height


def ungraded_lab_page(pdf, lab, timing, problem):
    pdf.new_page()
    y = lab_header(pdf, lab, "not graded", "#777", timing)
    x = MARGIN
    y = pdf.wrapped(x, y, A4[0] - 2 * MARGIN, "Not graded here: " + problem, size=9, color="#c62828",
                    max_lines=25) + 0.2
    if "image" in timing:
        w = min(A4[0] - 2 * MARGIN, (A4[1] - MARGIN - y - 0.2) * 4 / 3)  # a long message leaves less room
        pdf.text(x, y, f"Your render: default scene, {TIMING_SIZE} (kit-render)", size=9, style="bold")
        pdf.image(timing["image"], x, y + 0.2, w, w * 3 / 4)
    elif "error" in timing:
        pdf.text(x, y, "kit-render's message", size=11, style="bold", color="#c62828")
        pdf.wrapped(x, y + 0.25, A4[0] - 2 * MARGIN, timing["error"], size=7.5, style="code",
                    max_lines=max(1, min(50, int((A4[1] - MARGIN - y - 0.25) / pdf.line_height(7.5)))))


def notes_pages(pdf, notes_text, notes_path):
    top, bottom = 1.0, A4[1] - MARGIN
    left, right = MARGIN + 0.1, A4[0] - MARGIN - 0.1
    state = {"y": top}

    def page():
        pdf.new_page()
        pdf.text(left, 0.55, "Notes", size=9, color="#888")
        pdf.text(left + max(0.5, pdf.width("Notes", "normal", 9) + 0.1), 0.55, os.path.basename(notes_path), size=9,
                 color="#888", style="code")
        state["y"] = top

    def room(height):
        if state["y"] + height > bottom:
            page()

    def flow(runs, x0, size, line_gap=1.4, first_prefix=None, base="normal"):
        """Lays out inline runs word by word between x0 and right."""
        line_h = size * line_gap / 72.0
        words = []  # (text, style, space_before)
        space = False  # a space seen and not yet placed (it may end the run before)
        for text, style in runs:
            style = base if style == "normal" else style
            for p in re.split(r"(\s+)", text):
                if not p:
                    continue
                if p.isspace():
                    space = True
                    continue
                words.append((p, style, space and bool(words)))
                space = False
        lines, current, width = [], [], 0.0
        avail = right - x0
        for word, style, space in words:
            w = pdf.width(word, style, size)
            sw = pdf.width(" ", style, size) if space and current else 0.0
            while w > avail and len(word) > 1:  # a word longer than the line: cut it
                cut = max(1, int(len(word) * (avail - width - sw) / w)) if width + sw < avail * 0.5 else 0
                if cut == 0:
                    lines.append(current)
                    current, width, sw = [], 0.0, 0.0
                    cut = max(1, int(len(word) * avail / w) - 1)
                current.append((word[:cut], style, bool(sw)))
                lines.append(current)
                current, width, sw = [], 0.0, 0.0
                word = word[cut:]
                w = pdf.width(word, style, size)
            if current and width + sw + w > avail:
                lines.append(current)
                current, width, sw = [], 0.0, 0.0
            current.append((word, style, bool(sw)))
            width += sw + w
        if current:
            lines.append(current)
        for i, line in enumerate(lines or [[]]):
            room(line_h)
            if i == 0 and first_prefix:
                pdf.text(first_prefix[0], state["y"], first_prefix[1], size=size)
            x = x0
            group, group_style = "", None
            for word, style, space in line + [("", None, False)]:
                if style != group_style or style is None:
                    if group:
                        if group_style == "code":
                            w = pdf.width(group, "code", size * 0.92)
                            pdf.box(x - 0.02, state["y"] - 0.01, w + 0.04, line_h * 0.85, "#eeeeee")
                            pdf.text(x, state["y"], group, size=size * 0.92, style="code")
                        else:
                            w = pdf.width(group, group_style, size)
                            pdf.text(x, state["y"], group, size=size, style=group_style)
                        x += w
                    if space and group:
                        x += pdf.width(" ", "normal", size)
                    group, group_style = word, style
                else:
                    group += (" " if space else "") + word
            state["y"] += line_h

    page()
    blocks = markdown_blocks(notes_text)
    if not blocks:
        pdf.text(left, state["y"], "(the notes file is empty)", size=10, color="#777")
        return
    for kind, level, payload in blocks:
        if kind == "heading":
            size = {1: 18, 2: 14, 3: 12}.get(level, 11)
            state["y"] += 0.12 if level == 1 else 0.16
            room(size * 2.6 / 72.0)  # a heading stays with the line after it
            flow(inline_runs(payload), left, size, line_gap=1.3, base="bold")
            state["y"] += 0.06
        elif kind == "para":
            flow(inline_runs(payload), left, 10)
            state["y"] += 0.1
        elif kind == "bullet":
            marker, item = payload
            indent = left + 0.25 + 0.25 * level
            flow(inline_runs(item), indent, 10, first_prefix=(indent - 0.18 - 0.05 * (len(marker) - 1), marker))
            state["y"] += 0.03
        elif kind == "code":
            line_h = 8.5 * 1.35 / 72.0
            for line in payload or [""]:
                for piece in textwrap.wrap(line, 95, drop_whitespace=False) or [""]:
                    room(line_h)
                    pdf.box(left, state["y"] - 0.01, right - left, line_h, "#f3f3f3")
                    pdf.text(left + 0.08, state["y"], piece, size=8.5, style="code")
                    state["y"] += line_h
            state["y"] += 0.1
        elif kind == "rule":
            room(0.2)
            pdf.box(left, state["y"] + 0.05, right - left, 0.01, "#bbb")
            state["y"] += 0.2


# ---------------------------------------------------------------- main

def main(argv):
    parser = argparse.ArgumentParser(
        prog="./kit progress-report",
        description="Writes a PDF progress report: your labs' grades, renders and frame times, and your notes.")
    parser.add_argument("--labs", help="labs to include, e.g. 1,2 or 1-3 (default: every lab folder in labs/)")
    parser.add_argument("--notes", help="your notes in Markdown (default: progress-notes.md at the kit root; "
                                        "created from a template when missing)")
    parser.add_argument("--out", help="the PDF to write (default: out/progress-report.pdf)")
    parser.add_argument("--student", help="the name on the title page (default: git config user.name, else the login)")
    parser.add_argument("--labs-dir", help="the folder holding your NN-name lab folders (default: labs/)")
    parser.add_argument("--kit-grade", help=argparse.SUPPRESS)
    parser.add_argument("--kit-render", help=argparse.SUPPRESS)
    parser.add_argument("--references", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)

    build_tools = os.path.join(ROOT, "build", "default", "tools")
    kit_grade = args.kit_grade or os.path.join(build_tools, "kit-grade")
    kit_render = args.kit_render or os.path.join(build_tools, "kit-render")
    for name, path in (("kit-grade", kit_grade), ("kit-render", kit_render)):
        if not (os.path.isfile(path) and os.access(path, os.X_OK)):
            raise ReportError(f"{name} is not built ({path} is missing): run ./kit setup first")
    labs_dir = os.path.abspath(args.labs_dir or os.path.join(ROOT, "labs"))
    out = os.path.abspath(args.out or os.path.join(ROOT, "out", "progress-report.pdf"))
    notes_path = os.path.abspath(args.notes or os.path.join(ROOT, "progress-notes.md"))
    labs = parse_lab_list(args.labs) if args.labs else labs_present(labs_dir)
    if not os.path.isdir(labs_dir):
        raise ReportError(f"no labs folder at {labs_dir}")
    check_output_path(out)

    if os.path.exists(notes_path):
        try:
            with open(notes_path, encoding="utf-8", errors="replace") as f:
                notes_text = f.read()
        except OSError as e:
            raise ReportError(f"cannot read the notes {notes_path}: {e.strerror}")
    else:
        notes_text = NOTES_TEMPLATE
        try:
            os.makedirs(os.path.dirname(notes_path), exist_ok=True)
            with open(notes_path, "x", encoding="utf-8") as f:
                f.write(NOTES_TEMPLATE)
            say(f"no notes file: wrote a template to {notes_path}; edit it and run this again "
                "(the PDF below holds the template)")
        except OSError as e:
            say(f"no notes file at {notes_path}, and a template could not be written there ({e.strerror}); "
                "the PDF holds the template")

    with tempfile.TemporaryDirectory(prefix="kit-progress-") as temp:
        grade_dir = os.path.join(temp, "grade")
        say(f"grading labs {', '.join(map(str, labs))} of {labs_dir} with kit-grade")
        summary, results = run_grader(kit_grade, labs_dir, labs, grade_dir, args.references)
        problem = ""
        if summary is None:
            problem = ("the grader's references are missing (a student copy of the kit does not hold "
                       "tools/grade/references/). kit-grade said: " + results)
            say("not graded: " + problem)
        timings = {}
        for lab in labs:
            entry = summary["labs"].get(str(lab)) if summary else None
            if entry and entry["status"] != "graded":
                timings[lab] = {"error": f"the lab did not render in the grader ({entry['status'].replace('_', ' ')})"}
                continue
            say(f"timing lab {lab} ({STAGES[lab]}): {TIMING_FRAMES} frames at {TIMING_SIZE}")
            timings[lab] = measure_frame_time(kit_render, labs_dir, lab, os.path.join(temp, f"lab{lab}-render.png"))

        info = {"student": student_name(args.student), "version": kit_version(), "labs_dir": os.path.relpath(labs_dir, ROOT)
                if labs_dir.startswith(ROOT + os.sep) else labs_dir,
                "date": datetime.datetime.now().strftime("%Y-%m-%d %H:%M")}
        partial = os.path.join(os.path.dirname(out), "." + os.path.basename(out) + f".{os.getpid()}.tmp")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # e.g. a glyph DejaVu lacks in the notes
                pdf = Pdf(partial)
                title_page(pdf, info, labs, summary, timings, problem)
                for lab in labs:
                    entry = summary["labs"].get(str(lab)) if summary else None
                    if entry:
                        lab_page(pdf, lab, entry, results, grade_dir, timings[lab])
                    else:
                        ungraded_lab_page(pdf, lab, timings[lab], problem or "the grader returned nothing for this lab")
                notes_pages(pdf, notes_text, notes_path)
                pages = pdf.count
                pdf.close()
            os.replace(partial, out)
        except OSError as e:
            raise ReportError(f"cannot write {out}: {e.strerror or e}")
        finally:
            if os.path.exists(partial):
                os.unlink(partial)
    total = sum(summary["labs"][str(l)]["score"] for l in labs if summary and str(l) in summary["labs"])
    max_total = sum(summary["labs"][str(l)]["max_score"] for l in labs if summary and str(l) in summary["labs"])
    say(f"{pages} pages; " + (f"total {format_score(total)}/{format_score(max_total)}" if summary else "not graded"))
    print(out)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except ReportError as e:
        say(str(e))
        sys.exit(1)
    except KeyboardInterrupt:
        sys.exit(130)
