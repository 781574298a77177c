#!/usr/bin/env python3
"""The labs' contracts (tools/grade/lab_functions.json): the functions each lab declares, the
inputs the grader probes them at, and the probe shaders written from them.

    lab_contract.py shaders [--check] [--root KIT]
        Each lab's probe shader (its "shader", in shaders/): fragment x writes the value of one of
        the lab's functions at case x, chosen by u_probe_function (its place in the lab's list),
        each call between #if lines of its own (KIT_PROBE_<NAME>), so that a file lacking one
        function still has the others probed. The shaders call the lab's functions and hold
        none of their formulas. Writes those that differ; --check exits 1 naming them instead.
    lab_contract.py sync [--root KIT]
        The contract made to follow the starters (labs/NN-name/, else solutions/NN-name/ where a
        copy has no starter): a function they no longer declare leaves it, one they declare anew,
        or with another signature, enters it at default inputs to review. Prints each change;
        writes the file only where one was made. ./kit rebaseline runs sync, then shaders.
"""
import argparse
import json
import pathlib
import re
import sys

KIT = pathlib.Path(__file__).resolve().parents[2]
CONTRACT = pathlib.Path("tools") / "grade" / "lab_functions.json"
READERS = {"float": "kit_probe_float", "vec3": "kit_probe_vec3", "Light": "kit_probe_light"}
RESULTS = {"float": "o_value.r", "vec3": "o_value.rgb"}
# A function definition at the start of a line: its result type, name and parameters.
DEFINITION = re.compile(r"^(\w+)\s+([A-Za-z_]\w*)\s*\(([^;{)]*)\)\s*\{", re.M)


def define(function):
    """The #if a function's call stands under (lab_functions.cpp's FunctionProbe::define)."""
    return "KIT_PROBE_" + function.upper()


def shader_text(lab, entry):
    """The probe shader of one lab's contract entry (its "shader", "includes" and "functions")."""
    lines = [
        "#version 330 core",
        f"// The grader's probes of lab {lab}'s functions, written by tools/grade/lab_contract.py from",
        "// the lab's contract, tools/grade/lab_functions.json (edit that, not this): fragment x",
        "// writes the value of function u_probe_function (its place in the lab's list) at case x.",
        "// Each call stands between #if lines of its own, so a file that lacks one function still",
        "// has the others probed.",
        '#include "function_probe_inputs.glsl"',
    ]
    lines += [f'#include "{name}"' for name in entry["includes"]]
    lines += ["", "out vec4 o_value;", "", "void main() {", "    int at = 0;", "    o_value = vec4(0.0);"]
    for index, f in enumerate(entry["functions"]):
        lines += [f"#if defined({define(f['function'])})", f"    if (u_probe_function == {index}) {{"]
        for name, kind in f["arguments"]:
            lines.append(f"        {kind} {name} = {READERS[kind]}(at);")
        call = f"{f['function']}({', '.join(name for name, _ in f['arguments'])})"
        lines += [f"        {RESULTS[f['result']]} = {call};", "    }", "#endif"]
    lines.append("}")
    return "\n".join(lines) + "\n"


def read_contract(root):
    return json.loads((root / CONTRACT).read_text(encoding="utf-8"))


def shaders(root):
    """{path: text} of every lab's probe shader in the kit at `root`."""
    return {root / "shaders" / entry["shader"]: shader_text(lab, entry)
            for lab, entry in sorted(read_contract(root)["labs"].items(), key=lambda item: int(item[0]))}


def write_shaders(root, check):
    written = shaders(root)
    differing = [path for path, text in written.items() if not path.is_file() or path.read_text(encoding="utf-8") != text]
    for path in differing:
        if not check:
            path.write_text(written[path], encoding="utf-8")
        verb = "differs from tools/grade/lab_functions.json (./kit rebaseline writes it)" if check else "written"
        print(f"probe shaders: {path.relative_to(root)} {verb}")
    return 1 if differing and check else 0


# --- sync: the contract follows the starters ------------------------------------------------

def declared(path):
    """[(function, [[argument, type]], result)] that the file at `path` defines, in its order."""
    text = re.sub(r"/\*.*?\*/", "", re.sub(r"//[^\n]*", "", path.read_text(encoding="utf-8")), flags=re.S)
    out = []
    for result, name, parameters in DEFINITION.findall(text):
        arguments = []
        for parameter in filter(None, (p.strip() for p in parameters.split(","))):
            words = [w for w in parameter.split() if w not in ("in", "const", "highp", "mediump", "lowp")]
            arguments.append([words[-1], words[0]] if len(words) == 2 else [parameter, "?"])
        if name != "main":
            out.append((name, arguments, result))
    return out


DIRECTIONS = ("n", "v", "l", "h", "normal", "view", "direction", "wi", "wo")


def default_values(name, kind, floats, after_light):
    """Inputs to probe a new argument at, by its type (and, for a vec3, what its name says it is)."""
    if kind == "float":
        return [0.2, 0.5, 0.9, 1] if floats <= 4 else [0.25, 1]
    if kind == "Light":
        return ["$point", "$spot_20_30", "$sun"]
    if after_light and name in ("p", "point", "position", "world_position"):
        return [{"below": [0, 1]}, {"below": [25, 2]}, {"below": [40, 4.5]}]
    if name in DIRECTIONS or name.endswith("_dir") or name.endswith("_direction"):
        return [{"direction": [0, 0]}, {"direction": [30, 0]}, {"direction": [60, 90]}]
    return [[0.8, 0.2, 0.1], [1, 0.71, 0.29], [0.5, 0.5, 0.5]]


def default_entry(function, arguments, result, file):
    floats = sum(kind == "float" for _, kind in arguments)
    loops, after_light = [], False
    for name, kind in arguments:
        loops.append([name, default_values(name, kind, floats, after_light)])
        after_light = after_light or kind == "Light"
    return {"function": function, "file": file,
            "why": "default inputs, written by ./kit rebaseline: review them (a value where the kit's guard decides "
                   "needs finite_only)",
            "arguments": arguments, "result": result, "cases": [{"for": loops}]}


def lab_folder(root, lab):
    for top in ("labs", "solutions"):
        found = sorted((root / top).glob(f"{int(lab):02d}-*"))
        if found:
            return found[0]
    return None


def sync(root):
    """Makes the contract follow the starters; returns the changes in words (the file is written when any)."""
    contract = read_contract(root)
    changes = []
    for lab, entry in contract["labs"].items():
        folder = lab_folder(root, lab)
        if folder is None:
            continue
        files = list(dict.fromkeys(f["file"] for f in entry["functions"]))
        old = {f["function"]: f for f in entry["functions"]}
        functions = []
        for file in files:
            if not (folder / file).is_file():
                continue
            for function, arguments, result in declared(folder / file):
                kept = old.get(function)
                if kept and kept["arguments"] == arguments and kept["result"] == result and kept["file"] == file:
                    functions.append(kept)
                    continue
                types = [kind for _, kind in arguments] + [result]
                if any(kind not in READERS for kind in types[:-1]) or result not in RESULTS:
                    changes.append(f"lab {lab}: {function} ({file}) is not probed: its types ({', '.join(types)}) are "
                                   "not float, vec3 or Light")
                    continue
                entry_new = default_entry(function, arguments, result, file)
                if kept and "variants" in kept:
                    entry_new["variants"] = kept["variants"]
                functions.append(entry_new)
                what = "has another signature" if kept else "is new"
                changes.append(f"lab {lab}: {function} ({file}) {what}: probed at default inputs; review them in "
                               f"{CONTRACT}, and give instructor/reference/cpu_reference.cpp's probe_functions() its "
                               "CPU value")
        for function in old:
            if function not in {f["function"] for f in functions}:
                changes.append(f"lab {lab}: {function} is no longer declared by {folder.relative_to(root)}: "
                               "it leaves the contract and is not probed")
        entry["functions"] = functions
    if changes:
        (root / CONTRACT).write_text(dump(contract) + "\n", encoding="utf-8")
    return changes


def dump(value, indent=0):
    """JSON as the contract is written: objects one key a line, a list or object on one line where it fits."""
    flat = json.dumps(value, ensure_ascii=False)
    pad = "  " * (indent + 1)
    if len(flat) + 2 * indent <= 110 or not isinstance(value, (dict, list)) or not value:
        return flat
    if isinstance(value, dict):
        items = [f"{pad}{json.dumps(k)}: {dump(v, indent + 1)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + "  " * indent + "}"
    return "[\n" + ",\n".join(pad + dump(v, indent + 1) for v in value) + "\n" + "  " * indent + "]"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=("shaders", "sync"))
    parser.add_argument("--check", action="store_true", help="shaders: only check; exit 1 where a shader differs")
    parser.add_argument("--root", type=pathlib.Path, default=KIT, help="the kit (default: this one)")
    args = parser.parse_args(argv)
    if args.command == "shaders":
        return write_shaders(args.root, args.check)
    for change in sync(args.root):
        print(f"lab contract: {change}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
