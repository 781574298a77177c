#!/usr/bin/env python3
"""Every header of common/ and tools/ compiles on its own, and so does every source file
of the unity-built libraries (instructor/tests/headers_alone.cmake).

The unity build (KIT_UNITY_BUILD, the default on machines with the memory for it) compiles
a library's files as one translation unit, so a file that uses what another file of the
library includes still compiles there. Under 1.4 GB of memory ./kit builds file by file
(kit's plan_build_memory; Gradescope's image has 768 MB), and such a file breaks that
build only. This test compiles, with the flags the build gives them (compile_commands.json):
  1. each header as the only include of an empty file (-fsyntax-only), except a header that
     is the first line of code of its own .cpp in step 2, or of its own .cpp that the build
     compiles on its own (not in a unity file): that compile includes it first, alone,
     already (a third of the test's time saved; the headers of .cpp files built on their own, 13
     now, 142 s of the test's CPU against 151 s, median of 3 interleaved runs);
  2. each .cpp of a unity-built target alone (-fsyntax-only): what a file-by-file build
     compiles, less the code generation;
  3. witness: a planted header that uses std::string without <string>, and a planted .cpp
     that uses std::vector only through the file before it, fail, and are named.
Where the build's compiler is GCC and clang++ is installed (the fuzz build's compiler, in
./kit's package list), clang++ checks, with the same flags and GCC's own C++ library: what
a file includes is the library's headers, the same for either front end, and clang's is
faster (the test's script 125 s of CPU against 131 s with GCC, median of 3 interleaved runs;
syntax_compiler). The build itself compiles every file with GCC, whose verdict on the code
is not lost.
Run: headers_alone_test.py SOURCE_DIR BUILD_DIR WORK_DIR
"""
import concurrent.futures
import functools
import json
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys

# A unity-built target's files are the quoted includes of its unity file (CMake writes one,
# Unity/unity_N_cxx.cxx, per target built with UNITY_BUILD: kitcore and the grader's library).
UNITY_INCLUDE = re.compile(r'^#include "(.+)"$', re.M)


def compile_commands(build):
    with open(build / "compile_commands.json", encoding="utf-8") as f:
        return json.load(f)


def target_of(entry):
    found = re.search(r"CMakeFiles/([^/]+)\.dir/", entry.get("output", "") + " " + entry["command"])
    return found.group(1) if found else None


def flags_of(entry):
    """The compiler that checks that entry (syntax_compiler: clang++ for GCC where installed) and
    the entry's flags, less the input, output and dependency files."""
    words = shlex.split(entry["command"])
    # The compiler, past a launcher (CMakeLists.txt's ccache, through env): the
    # first word that names a C or C++ compiler.
    at = next((i for i, w in enumerate(words) if re.search(r"(^|/)(c\+\+|g\+\+|gcc|cc|clang\+\+|clang)(-[0-9.]+)?$", w)), 0)
    words = words[at:]
    keep, skip = [words[0]], False
    for word in words[1:]:
        if skip:
            skip = False
            continue
        if word in ("-o", "-MF", "-MT", "-MQ", "-c"):
            skip = word != "-c"
            continue
        if word in ("-MD", "-MMD") or word == entry["file"] or word.endswith((".cxx", ".cpp", ".cc")):
            continue
        keep.append(word)
    return syntax_compiler(keep), entry["directory"]


@functools.lru_cache(maxsize=None)
def is_gcc(compiler):
    try:
        return "Free Software Foundation" in subprocess.run([compiler, "--version"], capture_output=True,
                                                              text=True).stdout
    except OSError:
        return False


def syntax_compiler(flags):
    """FLAGS with clang++ for GCC where clang++ is installed (the module's docstring says why);
    -Wno-unknown-warning-option: a GCC warning flag clang lacks is not an error."""
    clang = shutil.which("clang++")
    if not clang or not is_gcc(flags[0]):
        return flags
    return [clang] + flags[1:] + ["-Wno-unknown-warning-option"]


def first_party_flags(commands, source):
    """One set of flags for the kit's own headers: the first C++ command's compiler and
    options (its -std: glad's C file comes first, and a compiler's default standard may
    be older than the build's), with the union of every first-party target's include
    folders and definitions (a header of tools/ may need both common/ and its own folder)."""
    base, directory, extra = None, None, []
    for entry in commands:
        if not entry["file"].startswith(str(source)) and "/build/" not in entry["file"]:
            continue
        if base is None and not entry["file"].endswith((".cpp", ".cxx", ".cc")):
            continue
        flags, where = flags_of(entry)
        if base is None:
            base, directory = flags, where
        words = iter(flags[1:])
        for word in words:
            if word in ("-I", "-isystem", "-D"):
                word = word + next(words, "")
            if word.startswith(("-I", "-isystem", "-D")) and word not in base and word not in extra:
                extra.append(word)
    return base + extra, directory


# The compilers with glibc's huge-page malloc, as the build's (CMakeLists.txt), unless the
# environment sets that tunable: clang's front end allocates page by page through malloc, and
# this test took 93 s of CPU against 120 s (median of 2 interleaved runs, farm-bench).
COMPILER_ENV = dict(os.environ)
if "glibc.malloc.hugetlb" not in COMPILER_ENV.get("GLIBC_TUNABLES", ""):
    COMPILER_ENV["GLIBC_TUNABLES"] = ":".join(filter(None, [COMPILER_ENV.get("GLIBC_TUNABLES"),
                                                            "glibc.malloc.hugetlb=1"]))


def check(flags, directory, text, name, language="c++"):
    """Compiles TEXT (syntax only) with FLAGS: None when it compiles, else the first errors."""
    done = subprocess.run(flags + ["-fsyntax-only", "-x", language, "-"], input=text, cwd=directory,
                          capture_output=True, text=True, env=COMPILER_ENV)
    if done.returncode == 0:
        return None
    errors = [line for line in done.stderr.splitlines() if "error" in line]
    return f"{name}: " + "\n    ".join(errors[:3] or done.stderr.splitlines()[:3])


CODE_LINE = re.compile(r'^\s*(?!//)(?!/\*)(?!\*)\S')
INCLUDE_LINE = re.compile(r'^\s*#\s*include\s+"(?:[\w./]*/)?([\w.]+)"')


def first_included(cpp):
    """The file name of `cpp`'s first line of code when that line includes a quoted header, else None."""
    if not cpp.is_file():
        return None
    for line in cpp.read_text(encoding="utf-8").splitlines():
        if CODE_LINE.match(line):
            m = INCLUDE_LINE.match(line)
            return m.group(1) if m else None
    return None


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    source, build, work = (pathlib.Path(a).resolve() for a in sys.argv[1:])
    work.mkdir(parents=True, exist_ok=True)
    commands = compile_commands(build)
    failures, passed = [], 0

    flags, directory = first_party_flags(commands, source)
    headers = [h for folder in ("common", "tools") for h in sorted((source / folder).rglob("*.h"))]
    jobs = []  # (name, flags, directory, text)
    # Each source file of a unity-built target, with that target's own flags.
    unity_targets = []
    for entry in commands:
        unity_file = pathlib.Path(entry["directory"], entry["file"])
        if "/Unity/unity_" not in entry["file"] or not unity_file.is_file():
            continue
        target_flags, target_dir = flags_of(entry)
        unity_targets.append(target_of(entry))
        for cpp in UNITY_INCLUDE.findall(unity_file.read_text(encoding="utf-8")):
            cpp = pathlib.Path(cpp)
            name = str(cpp.relative_to(source)) if cpp.is_relative_to(source) else str(cpp)
            jobs.append((name, target_flags, target_dir, f'#include "{cpp}"\n'))
    for needed in ("kitcore", "kit_grade_core"):
        if needed not in unity_targets:
            failures.append(f"{needed}: no unity file in {build}/compile_commands.json (is KIT_UNITY_BUILD on?)")
    # .cpp files compiled on their own, by the build (not in a unity file) or by step 2: the
    # first include of each is compiled alone there.
    cpp_alone = {pathlib.Path(e["directory"], e["file"]).resolve() for e in commands if "/Unity/unity_" not in e["file"]}
    cpp_alone |= {(source / name).resolve() for name, *_ in jobs}
    first_in_own = {h for h in headers
                    if h.with_suffix(".cpp").resolve() in cpp_alone and first_included(h.with_suffix(".cpp")) == h.name}
    for header in headers:
        if header not in first_in_own:
            jobs.append((str(header.relative_to(source)), flags, directory, f'#include "{header}"\n'))

    # Witnesses: what the unity build would hide is found.
    planted = work / "planted"
    planted.mkdir(exist_ok=True)
    (planted / "needs_string.h").write_text("#pragma once\ninline std::string planted_name() { return {}; }\n")
    (planted / "first.cpp").write_text("#include <vector>\nstd::vector<int> first;\n")
    (planted / "second.cpp").write_text("std::vector<int> second;\n")
    witnesses = [
        ("witness: a header using std::string without <string>", f'#include "{planted / "needs_string.h"}"\n', True),
        ("witness: the unity file of first.cpp and second.cpp",
         f'#include "{planted / "first.cpp"}"\n#include "{planted / "second.cpp"}"\n', False),
        ("witness: second.cpp alone", f'#include "{planted / "second.cpp"}"\n', True),
    ]

    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        results = list(pool.map(lambda job: check(job[1], job[2], job[3], job[0]), jobs))
        witness_results = list(pool.map(lambda w: check(flags, directory, w[1], w[0]), witnesses))
    for result in results:
        if result:
            failures.append(result)
        else:
            passed += 1
    for (name, _, should_fail), result in zip(witnesses, witness_results):
        if (result is not None) == should_fail:
            passed += 1
            print(f"ok: {name} {'fails' if should_fail else 'compiles'}")
        else:
            failures.append(f"{name} should {'fail' if should_fail else 'compile'}: {result or 'it compiled'}")

    alone = sum(1 for j in jobs if j[0].endswith(".h"))
    print(f"compiled alone: {alone} headers of common/ and tools/ on their own and {len(first_in_own)} first in "
          f"their own source file, {len(jobs) - alone} source files of {', '.join(sorted(set(unity_targets)))}")
    for failure in failures:
        print("FAIL:", failure)
    print(f"{passed} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
