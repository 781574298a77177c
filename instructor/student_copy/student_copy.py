#!/usr/bin/env python3
"""./kit student-copy N DIR: the repository handed to students about to start lab N.

What goes in: every file of the kit (git's tracked and untracked-but-not-ignored
files, so build/ and out/ never do) except
  * instructor/ (CPU reference, bench, mistake catalogue, Gradescope packaging,
    the tests of the solutions, this script),
  * solutions/NN-name for NN >= N (stage N is assembled on the solutions of the
    labs before it, so those stay),
  * labs/NN-name for NN < N (those labs are over; their solutions are in),
  * the instructors' documents outside instructor/ (INSTRUCTOR_FILES: the grading
    notes handouts/instructors.md and the overview handouts/README.md),
and the README is replaced by one written for students (README.student.md here).
In every Markdown file the copy keeps, what lies between the markers
`<!-- instructors -->` and `<!-- /instructors -->` (whole lines or inside a line) is
left out: a handout or a docs/ page can name the instructors' tests, commands and
results there, for the instructors who read the full kit, and the students never
see it. A marker without its partner fails the copy.
The grader's reference images (tools/grade/references/) go in: a student grades
their own lab with the same checks as the instructor's grader.

DIR must not exist or be empty. It becomes a git repository with one commit, ready
to push to a template repository or zip. leak_check.py then searches the copy for
every solution line of labs N and later, and doc_check.py checks that every relative
Markdown link resolves inside the copy and that no student document names
instructor/ or an instructor command; any finding fails the command and removes DIR.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent

# Instructors' documents that live outside instructor/ (the kit's own tests read
# handouts/instructors.md where it is): never in a copy.
INSTRUCTOR_FILES = {"handouts/instructors.md", "handouts/README.md"}
# What a copy leaves out of the Markdown files it keeps (see the docstring).
INSTRUCTORS_BEGIN, INSTRUCTORS_END = "<!-- instructors -->", "<!-- /instructors -->"
_WHOLE_LINES = re.compile(r"^[ \t]*" + re.escape(INSTRUCTORS_BEGIN) + r"(?:(?!" + re.escape(INSTRUCTORS_END)
                          + r").)*" + re.escape(INSTRUCTORS_END) + r"[ \t]*(?:\n|\Z)", re.MULTILINE | re.DOTALL)
_INLINE = re.compile(re.escape(INSTRUCTORS_BEGIN) + r".*?" + re.escape(INSTRUCTORS_END), re.DOTALL)


def say(message):
    print(f"student-copy: {message}", file=sys.stderr)


def lab_folders():
    """(number, folder name) of every lab, from labs/ (the stage table's folders)."""
    out = []
    for d in sorted((ROOT / "labs").iterdir()):
        m = re.match(r"^(\d+)-", d.name)
        if d.is_dir() and m:
            out.append((int(m.group(1)), d.name))
    return out


def kit_files():
    """Relative paths of the kit's files: git's view when it is a checkout, else a walk."""
    try:
        listing = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z", "--cached", "--others",
                                  "--exclude-standard"], check=True, capture_output=True).stdout
        names = [n for n in listing.decode().split("\0") if n]
    except (OSError, subprocess.CalledProcessError):
        names = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*")
                 if p.is_file() and p.relative_to(ROOT).parts[0] not in ("build", "out", ".git")]
    return sorted(set(names))


def starters_held_back(lab, labs):
    """Later labs' starters that restate the solution of lab `lab` or a later one
    (lab 4's geometry pass is lab 1's answer with a TODO): they come with the
    release of the lab they build on. {folder: the first solution line found}."""
    sys.path.insert(0, str(HERE))
    import leak_check
    held = {}
    for n, folder in labs:
        if n <= lab:
            continue
        answers = {text: source for source, text in leak_check.solution_lines(ROOT, lab, n - 1)}
        for starter in sorted((ROOT / "labs" / folder).iterdir()):
            for line in starter.read_text(encoding="utf-8").splitlines():
                source = answers.get(leak_check.normalize(line))
                if source and folder not in held:
                    held[folder] = f"labs/{folder}/{starter.name} restates {source}"
    return held


def wanted(rel, lab, held):
    parts = Path(rel).parts
    if parts[0] == "instructor" or rel in INSTRUCTOR_FILES:
        return False
    if parts[0] in ("solutions", "labs") and len(parts) > 1:
        m = re.match(r"^(\d+)-", parts[1])
        if m:
            n = int(m.group(1))
            if parts[0] == "solutions":
                return n < lab
            return n >= lab and parts[1] not in held
    return rel != "README.md"


def without_instructor_sections(text, rel):
    """The Markdown `text` less its instructors' sections (whole lines, then inside lines)."""
    text = _INLINE.sub("", _WHOLE_LINES.sub("", text))
    for marker in (INSTRUCTORS_BEGIN, INSTRUCTORS_END):
        if marker in text:
            line = text[:text.index(marker)].count("\n") + 1
            raise RuntimeError(f"{rel}:{line}: {marker} without its partner (nothing written)")
    return text


def student_readme(lab, labs, held):
    text = (HERE / "README.student.md").read_text(encoding="utf-8")
    rows = []
    for n, folder in labs:
        if n < lab or folder in held:
            continue
        handout = f"handouts/{folder}.md"
        files = ", ".join(f"`{p.name}`" for p in sorted((ROOT / "labs" / folder).iterdir()))
        rows.append(f"| {n} | `labs/{folder}/` | {files} | [{folder}]({handout}) |")
    released = ", ".join(str(n) for n, _ in labs if n < lab) or "none yet"
    folder = dict(labs)[lab]
    return (text.replace("@FOLDER@", folder).replace("@LAB@", str(lab)).replace("@LAB_ROWS@", "\n".join(rows))
                .replace("@RELEASED@", released).replace("@LAST@", str(labs[-1][0])))


def keep_released(path, key, lab):
    """Of the grader's file `path`, the entries under `key` of labs 1..lab only: a later lab's mistake
    signatures (tools/grade/verdict/diagnosis.h, mistakes.json), described in words, would say what that lab's
    answer is, and its function probes' expected values (tools/grade/frames/function_probes.h, probes.json) what
    its functions return."""
    if not path.is_file():
        return
    doc = json.loads(path.read_text(encoding="utf-8"))
    entries = doc.get(key, [])
    if isinstance(entries, dict):
        doc[key] = {k: v for k, v in entries.items() if v.get("lab", 0) <= lab}
    else:
        doc[key] = [m for m in entries if m.get("lab", 0) <= lab]
    path.write_text(json.dumps(doc, separators=(",", ":")) + "\n", encoding="utf-8")


def main():
    parser = argparse.ArgumentParser(description="Writes the repository handed to students about to start lab N.")
    parser.add_argument("lab", type=int, help="the lab the students are about to start (1 = the first)")
    parser.add_argument("dest", type=Path, help="the new repository's folder (must not exist, or be empty)")
    parser.add_argument("--no-git", action="store_true", help="a plain folder, no git repository")
    args = parser.parse_args()

    labs = lab_folders()
    numbers = [n for n, _ in labs]
    if args.lab not in numbers:
        parser.error(f"lab {args.lab} does not exist (labs: {', '.join(map(str, numbers))})")
    dest = args.dest.resolve()
    if dest.exists() and (not dest.is_dir() or any(dest.iterdir())):
        parser.error(f"{dest} exists and is not an empty folder")
    try:  # inside the kit only where git ignores it (build/, out/), or the copy would copy itself
        inside = dest.relative_to(ROOT).parts[0] not in ("build", "out")
    except ValueError:
        inside = False
    if inside:
        parser.error(f"{dest} is inside the kit ({ROOT}): write the copy somewhere else")

    held = starters_held_back(args.lab, labs)
    for folder, why in held.items():
        say(f"labs/{folder}/ held back: {why} (it comes with that lab's release)")
    dest.mkdir(parents=True, exist_ok=True)
    copied = 0
    try:
        for rel in kit_files():
            src = ROOT / rel
            if not wanted(rel, args.lab, held) or src.is_symlink() or not src.is_file():
                continue
            target = dest / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, target)
            if target.suffix.lower() == ".md":
                text = src.read_text(encoding="utf-8")
                stripped = without_instructor_sections(text, rel)
                if stripped != text:
                    target.write_text(stripped, encoding="utf-8")
            copied += 1
        (dest / "README.md").write_text(student_readme(args.lab, labs, held), encoding="utf-8")
        references = dest / "tools" / "grade" / "references"
        keep_released(references / "mistakes.json", "mistakes", args.lab)
        keep_released(references / "probes.json", "probes", args.lab)

        leaks = subprocess.run([sys.executable, str(HERE / "leak_check.py"), str(dest), str(args.lab),
                                "--kit", str(ROOT)], capture_output=True, text=True)
        if leaks.returncode != 0:
            sys.stderr.write(leaks.stdout + leaks.stderr)
            raise RuntimeError("the copy holds solution lines of labs it must not (listed above); nothing written")
        docs = subprocess.run([sys.executable, str(HERE / "doc_check.py"), str(dest)], capture_output=True, text=True)
        if docs.returncode != 0:
            sys.stderr.write(docs.stdout + docs.stderr)
            raise RuntimeError("the copy's documents have dead links or name instructor files or commands "
                               "(listed above); nothing written")

        if not args.no_git:
            env = dict(os.environ)
            env.setdefault("GIT_AUTHOR_NAME", "Deferred rendering kit")
            env.setdefault("GIT_AUTHOR_EMAIL", "kit@localhost")
            env.setdefault("GIT_COMMITTER_NAME", env["GIT_AUTHOR_NAME"])
            env.setdefault("GIT_COMMITTER_EMAIL", env["GIT_AUTHOR_EMAIL"])
            for command in (["git", "init", "-q"], ["git", "add", "-A"],
                            ["git", "commit", "-q", "-m", f"Deferred rendering kit: lab {args.lab}"]):
                subprocess.run(command, cwd=dest, env=env, check=True, capture_output=True)
    except Exception as e:  # leave nothing half-made behind
        shutil.rmtree(dest, ignore_errors=True)
        say(str(e) if not isinstance(e, subprocess.CalledProcessError)
            else f"{' '.join(e.cmd)} failed: {e.stderr.decode(errors='replace').strip()}")
        return 1

    starters = [str(n) for n, folder in labs if n >= args.lab and folder not in held]
    say(f"{copied} files for lab {args.lab}: starters of labs {', '.join(starters)}, "
        f"solutions of labs {', '.join(str(n) for n in numbers if n < args.lab) or 'none'}; "
        f"no solution line of labs >= {args.lab} found in it, every Markdown link resolves in it")
    print(dest)
    return 0


if __name__ == "__main__":
    sys.exit(main())
