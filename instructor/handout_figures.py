#!/usr/bin/env python3
"""The figures the handouts quote that follow from grading, checked or written again.

A handout writes such a figure between two comments, invisible once rendered:

    10 points  ->  <!--figure lab2.points-->10<!--/figure--> points

and this script knows where each key's value comes from:

  labN.points        the lab's weight (tools/grade/grading.json)
  labN.checks        how many checks the lab has, as a word ("Eight"; capitalised as written)
  labN.points_each   the points of each check, where they are all equal (weight / count)
  grade.size         the size the checks render at ("256×192", tools/grade/references/manifest.json)
  mistake.ID.cost    the points catalogue entry ID loses: max - score in a self-check's --json
                     file (./kit rebaseline runs one); unchecked without one, and counted as such
  naming.KEY         the self-check's naming measure (self_check.py naming_counts): caught,
                     named_right, distinct, with_relatives, first, within_three; unchecked
                     without a self-check of every lab
  naming.labN.KEY    the same by lab: with_relatives, first, within_three
  references.KEY     tools/grade/references/ as its manifest lists it: compared (the checks'
                     references), allowances, gbuffer (G-buffer attachments kept to describe a
                     worst pixel), light_shares, files (in the folder), megabytes (the folder's
                     bytes in MB, one decimal)

    handout_figures.py [--self-check-json FILE] [--write] [FILES...]

Without --write it exits 1 listing every figure whose text differs from its source (file:line,
key, written, now). With --write the texts are replaced by the values and the changes listed.
Default FILES: handouts/*.md and docs/*.md. An unknown key is an error either way.
"""
import argparse
import json
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
FIGURE = re.compile(r"<!--figure ([A-Za-z0-9_.-]+)-->(.*?)<!--/figure-->")
WORDS = ["zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten", "eleven",
         "twelve", "thirteen", "fourteen", "fifteen", "sixteen", "seventeen", "eighteen", "nineteen", "twenty"]


def number(value):
    """A score as the handouts write it: at most three decimals, no trailing zeros (1.25, 10, 1.429)."""
    return f"{value:.3f}".rstrip("0").rstrip(".")


class Sources:
    def __init__(self, self_check_json=None):
        self.grading = json.loads((ROOT / "tools/grade/grading.json").read_text(encoding="utf-8"))
        self.manifest = json.loads((ROOT / "tools/grade/references/manifest.json").read_text(encoding="utf-8"))
        self.costs = None
        self.naming = None
        if self_check_json:
            doc = json.loads(pathlib.Path(self_check_json).read_text(encoding="utf-8"))
            rows = doc["rows"]
            self.costs = {r["id"]: r["max_score"] - r["score"] for r in rows if r.get("score") is not None}
            # A self-check of some labs (./kit rebaseline --labs N) knows nothing of the others' mistakes.
            self.checked_labs = {r["lab"] for r in rows}
            catalogue = json.loads((ROOT / "instructor/grading/catalogue.json").read_text(encoding="utf-8"))
            self.mistake_labs = {e["id"]: e["lab"] for e in catalogue["entries"]}
            every_lab = {int(lab) for lab in self.grading["labs"]} <= self.checked_labs
            self.naming = doc.get("naming") if every_lab else None

    def value(self, key, written):
        """The key's value as text, None where it cannot be known here (a mistake's cost without a self-check),
        or raises KeyError for a key no source has."""
        parts = key.split(".")
        if parts[0].startswith("lab") and len(parts) == 2:
            lab = self.grading["labs"][parts[0][3:]]
            checks = lab["checks"]
            if parts[1] == "points":
                return number(lab["weight"])
            if parts[1] == "checks":
                word = WORDS[len(checks)]
                return word.capitalize() if written[:1].isupper() else word
            if parts[1] == "points_each":
                if len(set(checks.values())) != 1:
                    raise KeyError(f"{key}: the checks of {parts[0]} are not all worth the same")
                return number(lab["weight"] / len(checks))
        if key == "grade.size":
            width, height = self.manifest["size"]
            return f"{width}×{height}"
        if parts[0] == "mistake" and len(parts) == 3 and parts[2] == "cost":
            if self.costs is None or self.mistake_labs.get(parts[1]) not in self.checked_labs:
                return None
            if parts[1] not in self.costs:
                raise KeyError(f"{key}: no row '{parts[1]}' in the self-check's results")
            return number(self.costs[parts[1]])
        if parts[0] == "naming" and len(parts) == 2:
            if parts[1] not in ("caught", "named_right", "distinct", "with_relatives", "first", "within_three"):
                raise KeyError(f"{key}: no such naming measure")
            return None if self.naming is None else str(self.naming[parts[1]])
        if parts[0] == "naming" and len(parts) == 3 and re.fullmatch(r"lab[1-9][0-9]*", parts[1]):
            if parts[2] not in ("with_relatives", "first", "within_three"):
                raise KeyError(f"{key}: no such naming measure of a lab")
            if self.naming is None:
                return None
            lab = self.naming["by_lab"].get(parts[1][3:])
            if lab is None:
                raise KeyError(f"{key}: no mistake of that lab has a relative")
            return str(lab[parts[2]])
        if parts[0] == "references" and len(parts) == 2:
            images = self.manifest["images"]
            folder = ROOT / "tools/grade/references"
            counts = {
                "compared": sum(1 for i in images if not i.get("describes_pixels_only")),
                "allowances": len(self.manifest["filter_allowance"]["images"]),
                "gbuffer": sum(1 for i in images if i.get("describes_pixels_only") and not i.get("light_shares")),
                "light_shares": sum(1 for i in images if i.get("light_shares")),
                "files": sum(1 for f in folder.iterdir() if f.is_file()),
            }
            if parts[1] == "megabytes":
                return f"{sum(f.stat().st_size for f in folder.iterdir() if f.is_file()) / 1e6:.1f}"
            if parts[1] not in counts:
                raise KeyError(f"{key}: no such count of the references")
            return str(counts[parts[1]])
        raise KeyError(f"{key}: no such figure (handout_figures.py lists the keys)")


def figures(path):
    """(line number, key, written text, match) of each figure in the file."""
    text = path.read_text(encoding="utf-8")
    for m in FIGURE.finditer(text):
        yield text.count("\n", 0, m.start()) + 1, m.group(1), m.group(2), m


def shown(path):
    return path.relative_to(ROOT) if path.is_relative_to(ROOT) else path


def run(files, sources, write):
    """(differences, unchecked count, errors); rewrites the files with --write."""
    differences, unchecked, errors = [], 0, []
    for path in files:
        text, out, at = path.read_text(encoding="utf-8"), [], 0
        for line, key, written, m in figures(path):
            if m.start() == 0 or text[m.start() - 1] == "\n":
                # CommonMark reads a line that starts with "<!--" as an HTML block: GitHub would show
                # the rest of the line, links and all, as raw text.
                errors.append(f"{shown(path)}:{line}: {key}: a figure starts the line (an HTML block in "
                              "Markdown: the rest of the line is not rendered); put a word before it")
            try:
                now = sources.value(key, written)
            except KeyError as e:
                errors.append(f"{shown(path)}:{line}: {e.args[0]}")
                continue
            if now is None:
                unchecked += 1
            elif now != written:
                differences.append(f"{shown(path)}:{line}: {key}: written {written!r}, now {now!r}")
                out += [text[at:m.start()], f"<!--figure {key}-->{now}<!--/figure-->"]
                at = m.end()
        if write and at:
            path.write_text("".join(out) + text[at:], encoding="utf-8")
    return differences, unchecked, errors


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--self-check-json", help="a self-check's --json file: mistakes' costs are checked too")
    parser.add_argument("--write", action="store_true", help="write the figures' values into the files")
    parser.add_argument("files", nargs="*", type=pathlib.Path)
    args = parser.parse_args(argv)
    files = [p.resolve() for p in args.files] or sorted((ROOT / "handouts").glob("*.md")) + sorted(
        (ROOT / "docs").glob("*.md"))
    differences, unchecked, errors = run(files, Sources(args.self_check_json), args.write)
    total = sum(1 for p in files for _ in figures(p))
    for e in errors:
        print(f"handout figures: error: {e}")
    for d in differences:
        print(f"handout figures: {'written' if args.write else 'stale'}: {d}")
    print(f"handout figures: {total} figures, {len(differences)} {'rewritten' if args.write else 'stale'}"
          + (f", {unchecked} figures from a self-check not checked (no --self-check-json of every lab)" if unchecked else ""))
    return 1 if errors or (differences and not args.write) else 0


if __name__ == "__main__":
    sys.exit(main())
