#!/usr/bin/env python3
"""Checks that common/'s groups include only downwards.

common/ is grouped by purpose, lowest first (KIT_COMMON_GROUPS in common/CMakeLists.txt):
a file may include a header of its own group or of a group before it, written as
"group/file.h", never one of a later group. Prints every include that breaks that
and exits 1; run by ctest as common_include_order.

usage: include_order.py [COMMON_DIR]   (default: the folder of this script)
"""
import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def groups(common):
    """The groups in order, as common/CMakeLists.txt lists them."""
    text = (common / "CMakeLists.txt").read_text(encoding="utf-8")
    found = re.search(r"set\(KIT_COMMON_GROUPS ([a-z_ ]+)\)", text)
    if not found:
        sys.exit("include_order: no set(KIT_COMMON_GROUPS ...) in common/CMakeLists.txt")
    return found.group(1).split()


def problems(common):
    order = groups(common)
    rank = {name: i for i, name in enumerate(order)}
    found = []
    for path in sorted(common.rglob("*")):
        if path.suffix not in (".h", ".cpp") or not path.is_file():
            continue
        rel = path.relative_to(common)
        group = rel.parts[0]
        if group not in rank:
            found.append(f"{rel}: not in a group ({', '.join(order)})")
            continue
        text = path.read_text(encoding="utf-8")
        for number, line in enumerate(text.splitlines(), 1):
            match = INCLUDE.match(line)
            if not match:
                continue
            target = match.group(1)
            head = target.split("/")[0]
            if "/" not in target:
                if (common / group / target).exists() or any((common / g / target).exists() for g in order):
                    found.append(f"{rel}:{number}: includes \"{target}\": write it as \"group/{target}\"")
                continue
            if head in rank and rank[head] > rank[group]:
                found.append(f"{rel}:{number}: {group}/ includes {target}, of the later group {head}/")
    return found


def main():
    common = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent).resolve()
    found = problems(common)
    for line in found:
        print(line)
    if found:
        print(f"include_order: {len(found)} include(s) run from a lower group to a higher one")
        return 1
    print(f"include_order: {' < '.join(groups(common))}: every include runs downwards")
    return 0


if __name__ == "__main__":
    sys.exit(main())
