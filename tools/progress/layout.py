"""The report as the command line writes it: the fields of the one layout (report.mustache,
also filled by the page's "Progress report", tools/web/page/report.js) from kit-grade's
results and kit-render's frame times, filled by pystache, the notes' Markdown rendered by
markdown-it-py (the Python port of the page's markdown-it, set up alike: the notes look the
same in both), and the HTML printed to PDF by WeasyPrint (Debian's python3-pystache,
python3-markdown-it and weasyprint)."""
import importlib.util
import os
import pathlib

from .results import STAGES, TIMING_FRAMES, TIMING_SIZE, ReportError

TEMPLATE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "report.mustache")


# The Python modules the layout needs, by the Debian package that has them.
MODULES = {"weasyprint": "weasyprint", "pystache": "python3-pystache", "markdown_it": "python3-markdown-it"}


def check_modules():
    """Before any grading: the packages the PDF needs are installed, or a clear error naming them."""
    missing = [package for module, package in MODULES.items() if importlib.util.find_spec(module) is None]
    if missing:
        raise ReportError(f"{', '.join(missing)} not installed (the PDF's layout and printing): "
                          "./kit setup installs them")


def format_score(value):
    # kit-grade's scores are exact thousandths (6.667): printed as kit-grade prints them.
    return ("%.3f" % value).rstrip("0").rstrip(".")


def format_ms(value):
    return "%.1f ms" % value if value >= 10 else "%.2f ms" % value


def score_class(score, max_score):
    return "full" if score >= max_score - 1e-9 else "short"


def ordered_checks(lab, entry, results):
    """The lab's checks in the grader's order (results.json), each (key, check)."""
    prefix = f"lab {lab} {STAGES[lab]}: "
    order = {t["name"][len(prefix):]: i for i, t in enumerate(results.get("tests", [])) if t["name"].startswith(prefix)}
    items = list(entry["checks"].items())
    return sorted(items, key=lambda kv: order.get(kv[1].get("title", kv[0]), len(order)))


def image_url(grade_dir, relative):
    path = os.path.join(grade_dir, relative) if relative else None
    return pathlib.Path(path).as_uri() if path and os.path.exists(path) else None


def check_fields(key, check, guess, grade_dir, graded):
    words = (guess if not check["passed"] else "") + ((check.get("note") + ". ") if check.get("note") else "") + \
        (check.get("summary") or "")
    return {"title": check.get("title", key), "verdict": ("passed" if check["passed"] else "failed") if graded
            else "not graded", "score": f"{format_score(check['score'])} / {format_score(check['max_score'])}",
            "words": words, "image": image_url(grade_dir, check.get("image")),
            "reference": image_url(grade_dir, check.get("reference")),
            "diff": image_url(grade_dir, check.get("diff")),
            # The toggle check compares the effect on with your own render with it off.
            "reference_caption": "yours, effect off" if key == "custom-on" else None}


def timing_fields(timing):
    if "median_ms" not in timing:
        return {"frame_ms": None, "frame_error": timing.get("error", "the lab did not render")}
    frames = ", ".join("%.1f" % t for t in timing["frames_ms"])
    return {"frame_ms": format_ms(timing["median_ms"]),
            "frame_detail": f"median of {len(timing['frames_ms'])} frames ({frames} ms) after one warm-up frame; "
                            f"default scene, {TIMING_SIZE}; {timing['command']}"}


def lab_fields(lab, entry, results, grade_dir, timing, problem):
    """One lab's fields: its line on the title page and its own section."""
    fields = {"number": lab, "stage": STAGES[lab], "graded": False, **timing_fields(timing)}
    if not entry:
        fields.update({"score": "not graded", "score_class": "muted", "result": "", "line": "not graded",
                       "not_graded": problem, "has_checks": False})
        if "image" in timing:
            fields.update({"render": pathlib.Path(timing["image"]).as_uri(),
                           "render_caption": f"default scene, {TIMING_SIZE} (kit-render)"})
        elif "error" in timing:
            fields["message"] = timing["error"]
        return fields
    graded = entry["status"] == "graded"
    score = f"{format_score(entry['score'])} / {format_score(entry['max_score'])}"
    result = (f"{entry['checks_passed']} of {len(entry['checks'])} checks passed" if graded
              else entry["status"].replace("_", " "))
    # The grader's guess at the mistake behind the failed checks (tools/grade/verdict/diagnosis.h),
    # first in each failed check's text.
    guess = (entry["likely_text"] + " ") if entry.get("likely_text") else ""
    checks = [check_fields(key, c, guess, grade_dir, graded) for key, c in ordered_checks(lab, entry, results)]
    fields.update({"graded": graded, "score": score, "score_class": score_class(entry["score"], entry["max_score"]), "result": result,
                   "line": f"{score}   ({result})", "checks": checks, "has_checks": bool(checks),
                   "message": None if graded else (entry.get("message") or "(no message)")})
    return fields


def how_made(info, summary, timings, problem):
    """The title page's "How this was made": the grading and the frame time, in words."""
    if summary:
        grading = (f"Scores: kit-grade on {info['labs_dir']} (the course's autograder: the same checks, references "
                   f"and tolerances), rendered at 256x192 with {summary.get('renderer') or 'the headless renderer'}. "
                   "Each lab's pages show every check: your render, the reference and the difference "
                   "(|yours - reference| x 16, inferno colour map). The grade that counts is the one your instructor "
                   "runs on your submission.")
    else:
        grading = ("Scores: none. kit-grade could not grade here: " + problem +
                   " The lab pages show your renders only; your instructor's grader grades the submission.")
    renderer = next((t["renderer"] for t in timings.values() if t.get("renderer")), "the headless renderer")
    timing = (f"Frame time: kit-render renders your stage on the default scene at {TIMING_SIZE}, {TIMING_FRAMES} frames "
              f"in one process (kit-render --stage NAME --shaders labs --frames {TIMING_FRAMES} --timings); each frame "
              "is timed by the wall clock from the start of the geometry pass to glFinish after the display pass. The "
              "first frame (which holds the shader compilation of the driver) is dropped and the median of the other "
              f"{TIMING_FRAMES - 1} is shown. Renderer: {renderer}. On this software renderer the times depend on the "
              "machine and on what else runs on it: compare them with times taken on the same machine.")
    return grading, timing


def notes_html(text):
    """The notes' Markdown as the page renders it (report.js): CommonMark and tables, the raw
    HTML in them shown as text."""
    from markdown_it import MarkdownIt
    return MarkdownIt("commonmark", {"html": False}).enable("table").render(text)


def report_fields(info, labs, summary, results, grade_dir, timings, problem, notes_text, notes_path):
    """Every field of report.mustache, as the page's report.js fills them too."""
    entries = {lab: (summary["labs"].get(str(lab)) if summary else None) for lab in labs}
    graded = [e for e in entries.values() if e]
    total = sum(e["score"] for e in graded)
    max_total = sum(e["max_score"] for e in graded)
    grading, timing = how_made(info, summary, timings, problem)
    note = " ".join([summary.get("problem", "")] + summary.get("notes", [])).strip() if summary else ""
    return {"student": info["student"], "date": info["date"], "version": info["version"],
            "labs_included": ", ".join(f"{n} {STAGES[n]}" for n in labs),
            "total": f"{format_score(total)} / {format_score(max_total)}" if summary else "not graded (see below)",
            "grading": grading, "timing": timing, "grader_note": note or None,
            "labs": [lab_fields(lab, entries[lab], results, grade_dir, timings[lab],
                                problem or "the grader returned nothing for this lab") for lab in labs],
            "notes_html": notes_html(notes_text),
            "notes_source": notes_path}


def render_html(fields):
    import pystache
    with open(TEMPLATE, encoding="utf-8") as f:
        template = f.read()
    return pystache.Renderer(missing_tags="ignore", escape=escape_html).render(template, fields)


def escape_html(text):
    # As mustache.js escapes (its escapeHtml): the two fillings give the same HTML.
    table = {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;", "/": "&#x2F;", "`": "&#x60;",
             "=": "&#x3D;"}
    return "".join(table.get(c, c) for c in str(text))


def write_pdf(html, path):
    """The HTML printed to a PDF at path by WeasyPrint; returns its page count. Images are
    the grader's files (file: URLs); nothing is fetched from elsewhere."""
    import logging
    import weasyprint
    logging.getLogger("weasyprint").setLevel(logging.ERROR)  # e.g. CSS it does not know: not the student's concern
    document = weasyprint.HTML(string=html, base_url=os.getcwd()).render()
    document.write_pdf(path)
    return len(document.pages)
