#!/usr/bin/env python3
"""The labs' probe shaders are what tools/grade/lab_contract.py writes from their contract
(tools/grade/lab_functions.json), with a witness: a contract whose argument was renamed, in a
copy, is reported naming its shader, and writing the shaders again makes them agree.

    lab_contract_test.py WORK_DIR
"""
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "tools" / "grade" / "lab_contract.py"
work = pathlib.Path(sys.argv[1])
failures = 0


def check(ok, what, detail=""):
    global failures
    print(("ok: " if ok else "FAIL: ") + what + ("" if ok else f"\n    {detail}"))
    failures += not ok


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


kit = run("shaders", "--check")
check(kit.returncode == 0, "the kit's probe shaders are its contract's", kit.stdout + kit.stderr)

shutil.rmtree(work, ignore_errors=True)
(work / "tools" / "grade").mkdir(parents=True)
(work / "shaders").mkdir()
shutil.copy(ROOT / "tools/grade/lab_functions.json", work / "tools/grade/")
for shader in (ROOT / "shaders").glob("probe_*.frag"):
    shutil.copy(shader, work / "shaders")
contract = work / "tools/grade/lab_functions.json"
contract.write_text(contract.read_text(encoding="utf-8").replace('["v_dot_h", "float"], ["f0", "vec3"]',
                                                                 '["cos_theta", "float"], ["f0", "vec3"]'))
stale = run("shaders", "--check", "--root", work)
check(stale.returncode == 1 and "shaders/probe_brdf.frag" in stale.stdout and "probe_attenuation" not in stale.stdout,
      "witness: a renamed argument makes probe_brdf.frag differ, and only it", stale.stdout + stale.stderr)
written = run("shaders", "--root", work)
again = run("shaders", "--check", "--root", work)
check(written.returncode == 0 and again.returncode == 0 and
      "float cos_theta = kit_probe_float(at);" in (work / "shaders/probe_brdf.frag").read_text(),
      "writing them again reads the argument by its new name", written.stdout + again.stdout)
print(f"{3 - failures} passed, {failures} failed")
sys.exit(1 if failures else 0)
