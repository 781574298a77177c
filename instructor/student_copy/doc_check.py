#!/usr/bin/env python3
"""Checks that a student copy's documents are whole and name nothing the copy lacks.

    doc_check.py COPY

Two rules, on the files of COPY (a folder written by ./kit student-copy):

1. Every relative link and image of every Markdown file resolves inside the copy:
   `[text](target)`, `![alt](target)`, reference definitions `[id]: target`, and
   HTML `href="..."` / `src="..."`. The target (without its `#anchor`) must be a
   file or folder under COPY; an anchor into a Markdown file (or `#anchor` alone,
   into the same file) must name one of its headings, as GitHub forms them.
   Links with a scheme (https:, mailto:) are not followed. Text in code spans and
   fenced code blocks is not a link.

2. No student-facing document names an instructor path or command. Student-facing:
   every Markdown file of the copy, and the comments of the shaders (.glsl, .frag,
   .vert) under labs/, shaders/ and solutions/. Instructor-only: the instructor/
   folder, handouts/instructors.md, the instructors' programs and scripts
   (kit-bench, measure.sh, self_check.py, ...), the commands a copy refuses
   (./kit bench, student-copy, gradescope-package, handout-images, rebaseline), kit-grade's
   --self-check and --batch, and the notes' private names ("seed 000"), which a
   student cannot look up.

Exit status 0 when the copy passes; 1 with one line per finding (file:line: what);
2 on bad arguments. student_copy.py runs it on every copy it writes, after
leak_check.py; a finding fails the copy like a leak.
"""
import argparse
import re
import sys
from pathlib import Path

SHADER_SUFFIXES = {".glsl", ".frag", ".vert"}
SHADER_FOLDERS = ("labs", "shaders", "solutions")

# What a student document must not name, with the reason printed for a hit.
FORBIDDEN = [
    (re.compile(r"(?<![\w.-])instructor/"), "names the instructor/ folder, which a copy does not have"),
    (re.compile(r"\binstructors\.md\b"), "names handouts/instructors.md, which a copy does not have"),
    (re.compile(r"--student-copy\b"), "names ./kit web --student-copy, which a copy refuses"),
    (re.compile(r"\./kit\s+(bench|student-copy|gradescope-package|handout-images|rebaseline)\b"),
     "names an instructor command, which a copy refuses"),
    (re.compile(r"(?<![\w-])kit-bench\b"), "names kit-bench, the instructors' benchmark (not in a copy)"),
    (re.compile(r"--self-check\b"), "names kit-grade --self-check, an instructor option"),
    (re.compile(r"--batch\b"), "names kit-grade --batch, an instructor option"),
    (re.compile(r"\b(measure\.sh|self_check\.py|handout_images\.sh|student_copy\.py|leak_check\.py|"
                r"doc_check\.py|catalogue\.json|package\.sh)\b"),
     "names an instructor script, which a copy does not have"),
    (re.compile(r"\bseeds? \d{3}\b", re.IGNORECASE),
     "names a 'seed' by number: say where it comes from (the lecture, LearnOpenGL) or nothing"),
]

FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
INLINE_LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE_DEFINITION = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$")
HTML_ATTRIBUTE = re.compile(r"\b(?:href|src)\s*=\s*[\"']([^\"']+)[\"']", re.IGNORECASE)
SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
HTML_ANCHOR = re.compile(r"<a\s+(?:name|id)\s*=\s*[\"']([^\"']+)[\"']", re.IGNORECASE)


def markdown_lines(text):
    """(line number, line) of the lines outside fenced code blocks, code spans blanked."""
    fence = None
    for number, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if m:
            if fence is None:
                fence = m.group(1)
            elif m.group(1) == fence:
                fence = None
            continue
        if fence is None:
            yield number, CODE_SPAN.sub(lambda s: " " * len(s.group(0)), line)


def github_slug(heading):
    """The anchor GitHub gives a heading: the rendered text, lower case, every character
    but letters, digits, '_', '-' and ' ' dropped, spaces turned into '-'."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link's text only
    text = re.sub(r"<[^>]+>", "", text)                          # HTML tags
    text = text.replace("`", "").lower()
    text = "".join(c for c in text if c.isalnum() or c in "_- ")
    return text.replace(" ", "-")


def anchors(path, cache):
    if path not in cache:
        found, seen = set(), {}
        text = path.read_text(encoding="utf-8")
        for _, line in markdown_lines(text):
            found.update(HTML_ANCHOR.findall(line))
        fence = None
        for line in text.splitlines():  # headings with their code spans (GitHub keeps their text)
            m = FENCE.match(line)
            if m:
                fence = m.group(1) if fence is None else (None if m.group(1) == fence else fence)
                continue
            h = HEADING.match(line) if fence is None else None
            if h:
                slug = github_slug(h.group(2))
                n = seen.get(slug, 0)
                seen[slug] = n + 1
                found.add(slug if n == 0 else f"{slug}-{n}")
        cache[path] = found
    return cache[path]


def link_targets(text):
    for number, line in markdown_lines(text):
        for m in INLINE_LINK.finditer(line):
            yield number, m.group(1)
        m = REFERENCE_DEFINITION.match(line)
        if m:
            yield number, m.group(1)
        for m in HTML_ATTRIBUTE.finditer(line):
            yield number, m.group(1)


def check_links(copy, md, text, cache):
    problems = []
    root = copy.resolve()
    for number, target in link_targets(text):
        if SCHEME.match(target) or target.startswith("//"):
            continue
        path_part, _, anchor = target.partition("#")
        if path_part:
            resolved = (md.parent / path_part).resolve()
            try:
                resolved.relative_to(root)
            except ValueError:
                problems.append(f"{number}: link {target} leaves the copy")
                continue
            if not resolved.exists():
                problems.append(f"{number}: link {target}: {resolved.relative_to(root)} is not in the copy")
                continue
        else:
            resolved = md.resolve()
        if anchor and resolved.is_file() and resolved.suffix.lower() == ".md":
            if anchor not in anchors(resolved, cache):
                problems.append(f"{number}: link {target}: {resolved.relative_to(root)} has no heading "
                                f"with the anchor #{anchor}")
    return problems


def shader_comments(text):
    """(line number, comment text) of a shader's // and /* */ comments."""
    in_block = False
    for number, line in enumerate(text.splitlines(), 1):
        comment = []
        rest = line
        while rest:
            if in_block:
                end = rest.find("*/")
                if end < 0:
                    comment.append(rest)
                    rest = ""
                else:
                    comment.append(rest[:end])
                    rest = rest[end + 2:]
                    in_block = False
            else:
                line_at, block_at = rest.find("//"), rest.find("/*")
                if line_at >= 0 and (block_at < 0 or line_at < block_at):
                    comment.append(rest[line_at + 2:])
                    rest = ""
                elif block_at >= 0:
                    rest = rest[block_at + 2:]
                    in_block = True
                else:
                    rest = ""
        if comment:
            yield number, " ".join(comment)


def forbidden(text):
    return [why for pattern, why in FORBIDDEN if pattern.search(text)]


def check(copy):
    findings = []
    cache = {}
    files = sorted(p for p in copy.rglob("*")
                   if p.is_file() and not p.is_symlink() and ".git" not in p.relative_to(copy).parts)
    for path in files:
        rel = path.relative_to(copy)
        if path.suffix.lower() == ".md":
            text = path.read_text(encoding="utf-8")
            findings += [f"{rel}:{p}" for p in check_links(copy, path, text, cache)]
            for number, line in enumerate(text.splitlines(), 1):
                findings += [f"{rel}:{number}: {why}: {line.strip()}" for why in forbidden(line)]
        elif path.suffix.lower() in SHADER_SUFFIXES and rel.parts[0] in SHADER_FOLDERS:
            for number, comment in shader_comments(path.read_text(encoding="utf-8")):
                findings += [f"{rel}:{number}: {why}: {comment.strip()}" for why in forbidden(comment)]
    return findings


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("copy", type=Path, help="a folder written by ./kit student-copy")
    args = parser.parse_args()
    if not args.copy.is_dir():
        parser.error(f"{args.copy}: not a folder")
    findings = check(args.copy)
    print(f"doc_check: the Markdown links and student documents of {args.copy} checked: "
          f"{len(findings)} finding(s)", file=sys.stderr)
    for finding in findings:
        print(finding)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
