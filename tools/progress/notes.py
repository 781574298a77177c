"""The student's notes at the end of the report: Markdown read into blocks and inline runs,
laid out over as many pages as they take."""
import os
import re
import textwrap

from .pdf import A4, MARGIN


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
