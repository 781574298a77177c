#!/usr/bin/env python3
"""Checks that the kit's grouped folders include only downwards: common/ and tools/grade/.

Each folder is grouped by purpose, lowest first, as its CMake file lists the groups
(set(KIT_COMMON_GROUPS ...) in common/CMakeLists.txt, set(KIT_GRADE_GROUPS ...) in
tools/grade.cmake): a file may include a header of its own group or of a group before it,
written as "group/file.h", never one of a later group. A file at the top of the folder
(tools/grade/main.cpp) stands above every group. Prints every include that breaks that and
exits 1; run by ctest as include_order.

usage: include_order.py [FOLDER ...]   (default: the kit's common/ and tools/grade/)
"""
import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)
ROOT = pathlib.Path(__file__).resolve().parent.parent
DEFAULT_FOLDERS = [ROOT / "common", ROOT / "tools" / "grade"]


def groups(folder):
    """The folder's groups in order, as its CMakeLists.txt (or, where it has none, the .cmake
    file of its name beside it: tools/grade.cmake) lists them."""
    cmake = folder / "CMakeLists.txt"
    if not cmake.exists():
        cmake = folder.parent / (folder.name + ".cmake")
    found = re.search(r"set\(KIT_[A-Z]+_GROUPS ([a-z_ ]+)\)", cmake.read_text(encoding="utf-8")) if cmake.exists() else None
    if not found:
        sys.exit(f"include_order: no set(KIT_..._GROUPS ...) in {cmake}")
    return found.group(1).split()


def problems(folder):
    order = groups(folder)
    rank = {name: i for i, name in enumerate(order)}
    top = len(order)  # a file at the top of the folder: above every group
    found = []
    for path in sorted(folder.rglob("*")):
        if path.suffix not in (".h", ".cpp") or not path.is_file():
            continue
        rel = path.relative_to(folder)
        group = rel.parts[0] if len(rel.parts) > 1 else None
        if group is not None and group not in rank:
            found.append(f"{rel}: not in a group ({', '.join(order)})")
            continue
        own = rank[group] if group is not None else top
        text = path.read_text(encoding="utf-8")
        for number, line in enumerate(text.splitlines(), 1):
            match = INCLUDE.match(line)
            if not match:
                continue
            target = match.group(1)
            head = target.split("/")[0]
            if "/" not in target:
                if any((folder / g / target).exists() for g in order):
                    found.append(f"{rel}:{number}: includes \"{target}\": write it as \"group/{target}\"")
                continue
            if head in rank and rank[head] > own:
                found.append(f"{rel}:{number}: {group}/ includes {target}, of the later group {head}/")
    return found


def shown(folder):
    """The folder as messages name it: from the kit's root where it lies inside it."""
    return str(folder.relative_to(ROOT)) if folder.is_relative_to(ROOT) else folder.name


def main():
    folders = [pathlib.Path(a).resolve() for a in sys.argv[1:]] or DEFAULT_FOLDERS
    failed = 0
    for folder in folders:
        found = problems(folder)
        for line in found:
            print(f"{shown(folder)}/{line}")
        if found:
            failed += 1
            print(f"include_order: {shown(folder)}/: {len(found)} include(s) run from a lower group to a higher one")
        else:
            print(f"include_order: {shown(folder)}/: {' < '.join(groups(folder))}: every include runs downwards")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
