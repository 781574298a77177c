#!/usr/bin/env python3
"""Searches a student copy for the solution logic of labs N and later.

    leak_check.py COPY N [--kit KIT_ROOT]

For every file of solutions/NN-name with NN >= N, each line is a solution line
unless the students get it anyway: a starter of that lab or an earlier one holds
it (any file of labs/MM-name, MM <= NN: lab 6's reads of the G-buffer are lab 2's
starter's), or a released solution (labs before N, which the copy holds) does; a
line of those also counts without its trailing `//` comment. Trivial lines are
not solution lines either: shorter than MIN_LINE_CHARS once whitespace is
collapsed, or only punctuation and keywords (a brace, `return x;`, `#endif`).
(A later lab's starter can restate an earlier solution, as lab 4's restates lab
1's geometry pass: student_copy.py holds such starters back, so those do not count.) Every text file of
the copy is searched for each solution line, compared line by line after the
same whitespace collapsing, and long lines also as substrings (a line quoted
inside a Markdown paragraph). An HTML file (a web site's page and rendered
documents) is searched as it is and again as its text: without its tags, its
entities decoded (a code block's `a < b && c` is written `a &lt; b &amp;&amp; c`
there). Besides lines, the copy must hold no instructor/
folder and no solutions/NN-name of the labs N and later.

Exit status 0 when nothing leaks; 1 with one line per leak (file:line, the
solution file and the line); 2 on bad arguments.
"""
import argparse
import html
import re
import sys
from pathlib import Path

MIN_LINE_CHARS = 16          # shorter solution lines are too generic to call a leak
SUBSTRING_MIN_CHARS = 32     # long lines are also searched inside longer lines
BINARY_SUFFIXES = {".png", ".exr", ".jpg", ".jpeg", ".hdr", ".bin", ".glb", ".zip", ".pdf"}
TRIVIAL = re.compile(r"^[\s{}();,]*$|^(return|break|continue|else|#endif|#else)\b[\w\s.;()]*$")


def normalize(line):
    return " ".join(line.split())


def public_forms(lines):
    """The normalized lines of a file the students get, each also without its trailing
    `//` comment: a solution line equal to the code of such a line gives nothing away."""
    forms = set()
    for line in lines:
        forms.add(normalize(line))
        forms.add(normalize(line.split("//", 1)[0]))
    return forms


def lab_number(folder):
    m = re.match(r"^(\d+)-", folder)
    return int(m.group(1)) if m else None


def folder_forms(folder):
    """public_forms of every file of `folder` (none when it does not exist)."""
    forms = set()
    if folder.is_dir():
        for path in sorted(folder.iterdir()):
            if path.is_file():
                forms |= public_forms(path.read_text(encoding="utf-8").splitlines())
    return forms


def released_lines(kit, first_lab):
    """Every line of the solutions a copy for first_lab holds (labs before it)."""
    lines = set()
    for folder in sorted((kit / "solutions").iterdir()):
        n = lab_number(folder.name)
        if n is not None and n < first_lab:
            lines |= folder_forms(folder)
    return lines


def solution_lines(kit, first_lab, last_lab=None):
    """(solution file, line) for every non-trivial line of the solutions of labs
    first_lab..last_lab that neither a starter of that lab or an earlier one (any
    of its files) nor a released solution (labs before first_lab) already holds."""
    found = []
    released = released_lines(kit, first_lab)
    starters = sorted((lab_number(f.name), f) for f in (kit / "labs").iterdir() if lab_number(f.name) is not None)
    for folder in sorted((kit / "solutions").iterdir()):
        n = lab_number(folder.name)
        if n is None or n < first_lab or (last_lab is not None and n > last_lab):
            continue
        given = set(released)
        for m, starter in starters:
            if m <= n:
                given |= folder_forms(starter)
        for sol in sorted(folder.iterdir()):
            for line in sol.read_text(encoding="utf-8").splitlines():
                text = normalize(line)
                if len(text) < MIN_LINE_CHARS or TRIVIAL.match(text) or text in given:
                    continue
                found.append((f"solutions/{folder.name}/{sol.name}", text))
    return found


def copy_files(copy):
    for path in sorted(copy.rglob("*")):
        if ".git" in path.relative_to(copy).parts or not path.is_file() or path.is_symlink():
            continue
        if path.suffix.lower() in BINARY_SUFFIXES:
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue  # not text: images and the like cannot quote a line
        yield path, text.splitlines()
        if path.suffix.lower() in (".html", ".htm"):
            yield path, html.unescape(re.sub(r"<[^>]*>", "", text)).splitlines()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("copy", type=Path)
    parser.add_argument("lab", type=int)
    parser.add_argument("--kit", type=Path, default=Path(__file__).resolve().parents[2])
    args = parser.parse_args()
    if not args.copy.is_dir():
        parser.error(f"{args.copy}: not a folder")

    leaks = []
    if (args.copy / "instructor").exists():
        leaks.append("instructor/: the instructor's folder is in the copy")
    for folder in (args.copy / "solutions").glob("*"):
        n = lab_number(folder.name)
        if n is not None and n >= args.lab:
            leaks.append(f"solutions/{folder.name}/: lab {n} is not released in a copy for lab {args.lab}")

    wanted = solution_lines(args.kit, args.lab)
    exact = {}
    for source, text in wanted:
        exact.setdefault(text, source)
    long_lines = [(text, source) for text, source in exact.items() if len(text) >= SUBSTRING_MIN_CHARS]
    for path, lines in copy_files(args.copy):
        rel = path.relative_to(args.copy)
        for number, line in enumerate(lines, 1):
            text = normalize(line)
            if text in exact:
                leaks.append(f"{rel}:{number}: line of {exact[text]}: {text}")
                continue
            for needle, source in long_lines:
                if needle in text:
                    leaks.append(f"{rel}:{number}: line of {source} inside: {needle}")
                    break

    print(f"leak_check: {len(wanted)} solution lines of labs >= {args.lab} searched in {args.copy}", file=sys.stderr)
    for leak in leaks:
        print(leak)
    return 1 if leaks else 0


if __name__ == "__main__":
    sys.exit(main())
