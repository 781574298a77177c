"""The layout of the report's title page and of a page per lab: the scores, each check's
render, reference and difference, and the frame time."""
import os

from .pdf import A4, MARGIN
from .results import STAGES, TIMING_FRAMES, TIMING_SIZE


def format_score(value):
    # kit-grade's scores are exact thousandths (6.667): printed as kit-grade prints them.
    return ("%.3f" % value).rstrip("0").rstrip(".")


def format_ms(value):
    return "%.1f ms" % value if value >= 10 else "%.2f ms" % value


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
    # The grader's guess at the mistake behind the failed checks (tools/grade/verdict/diagnosis.h),
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
