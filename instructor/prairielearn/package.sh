#!/usr/bin/env bash
# ./kit prairielearn-package DIR [--labs 1,2] [--image NAME] [--timeout S]
#
# Writes what an instructor copies into a PrairieLearn course (instructor/prairielearn/README.md):
#   DIR/questions/deferred-kit/labNN-name/   one question per lab: info.json (external grading),
#                                            question.html (pl-file-upload of the lab's files),
#                                            tests/lab.json (the lab, its files, kit-grade's limits)
#   DIR/serverFilesCourse/deferred-kit/      entrypoint.py, platform_results.py and kit/, the
#                                            grading data (solutions, shaders, references,
#                                            grading.json): private to the course
#   DIR/image/                               Dockerfile and kit/ (the student copy for lab 1: no
#                                            solution), the grading image's build context
# Each question's solution is graded through the entrypoint as written (a temporary /grade,
# this build's kit-grade): it must score 1.0, and its wall time goes into info.json beside
# the timeout.
#
# Environment: KIT_GRADE_BIN  the kit-grade to measure with (default: build/default's)
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
LABS=""
IMAGE="YOUR_DOCKERHUB_USER/deferred-kit-grader:latest"
TIMEOUT=60
DEST=""
GRADER="${KIT_GRADE_BIN:-$ROOT/build/default/tools/kit-grade}"

say() { printf 'prairielearn-package: %s\n' "$*" >&2; }
die() { say "$*"; exit 1; }
usage() {
  cat <<'USAGE'
usage: ./kit prairielearn-package DIR [--labs LIST] [--image NAME] [--timeout S]
  DIR           where to write the course files (must not exist, or be empty)
  --labs LIST   labs to write questions for, comma separated (default: every lab)
  --image NAME  the grading image as PrairieLearn pulls it (default YOUR_DOCKERHUB_USER/deferred-kit-grader:latest)
  --timeout S   each question's grading timeout, 10-600 s (default 60); kit-grade stops a
                renderer after S*2/3 s of wall time or S/3 s of CPU, so an endless loop is
                reported before PrairieLearn kills the job
USAGE
}

while [ $# -gt 0 ]; do
  case "$1" in
    --labs) [ $# -ge 2 ] || die "--labs needs a value"; LABS="$2"; shift 2 ;;
    --image) [ $# -ge 2 ] || die "--image needs a value"; IMAGE="$2"; shift 2 ;;
    --timeout) [ $# -ge 2 ] || die "--timeout needs a value"; TIMEOUT="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    -*) usage >&2; die "unknown option '$1'" ;;
    *) [ -z "$DEST" ] || die "one DIR only"; DEST="$1"; shift ;;
  esac
done
[ -n "$DEST" ] || { usage >&2; die "DIR is missing"; }
[[ "$TIMEOUT" =~ ^[0-9]+$ ]] && [ "$TIMEOUT" -ge 10 ] && [ "$TIMEOUT" -le 600 ] ||
  die "--timeout must be 10-600 s (PrairieLearn's limit is 600 s)"
[ -x "$GRADER" ] || die "no kit-grade at $GRADER (./kit setup builds it)"
case "$DEST" in /*) ;; *) DEST="$PWD/$DEST" ;; esac
if [ -e "$DEST" ] && [ -n "$(ls -A "$DEST" 2>/dev/null)" ]; then die "$DEST exists and is not empty"; fi

# The labs: every lab of the kit unless --labs names some.
FOLDERS_TEXT="$(python3 "$ROOT/instructor/platforms/platform_results.py" folders --kit "$ROOT" --labs "$LABS")" || die "no questions written"
mapfile -t FOLDERS <<<"$FOLDERS_TEXT"

mkdir -p "$DEST"
MEASURE="$(mktemp -d)"
ok=0
cleanup() { rm -rf "$MEASURE"; [ "$ok" = 1 ] || { say "failed: nothing written"; rm -rf "$DEST"; }; }
trap cleanup EXIT

# 1. The image's build context: sources without any solution (student-copy checks that).
python3 "$ROOT/instructor/student_copy/student_copy.py" 1 "$DEST/image/kit" --no-git >/dev/null 2>"$DEST/student-copy.log" ||
  { cat "$DEST/student-copy.log" >&2; die "student-copy failed"; }
rm -f "$DEST/student-copy.log"
cp "$HERE/Dockerfile" "$DEST/image/Dockerfile"

# 2. serverFilesCourse: the entrypoint, the shared results module and the grading data,
#    the files git knows (so nothing ignored or built goes in).
SFC="$DEST/serverFilesCourse/deferred-kit"
mkdir -p "$SFC/kit"
install -m 0755 "$HERE/entrypoint.py" "$SFC/entrypoint.py"
install -m 0644 "$ROOT/instructor/platforms/platform_results.py" "$SFC/platform_results.py"
(cd "$ROOT" && git ls-files -z --cached --others --exclude-standard -- solutions shaders labs tools/grade/grading.json tools/grade/lab_functions.json \
   tools/grade/references 2>/dev/null || find solutions shaders labs tools/grade/grading.json tools/grade/lab_functions.json tools/grade/references -type f -print0) |
  while IFS= read -r -d '' f; do
    [ -f "$ROOT/$f" ] && [ ! -L "$ROOT/$f" ] && printf '%s\0' "$f"
  done | (cd "$ROOT" && xargs -0 -r cp -p --parents -t "$SFC/kit")
[ -f "$SFC/kit/tools/grade/grading.json" ] && [ -f "$SFC/kit/tools/grade/lab_functions.json" ] || die "the grading data was not copied"

# 3. One question per lab, its solution graded through the entrypoint to measure it.
WALL=$((TIMEOUT * 2 / 3)); CPU=$((TIMEOUT / 3))
for folder in "${FOLDERS[@]}"; do
  n=$((10#${folder%%-*})); name="${folder#*-}"
  q="$DEST/questions/deferred-kit/lab$(printf '%02d' "$n")-$name"
  mkdir -p "$q/tests"
  mapfile -t files < <(cd "$ROOT/solutions/$folder" && ls)
  python3 - "$q/tests/lab.json" "$n" "$folder" "$TIMEOUT" "$WALL" "$CPU" "${files[@]}" <<'PY'
import json, sys
path, n, folder, timeout, wall, cpu, *files = sys.argv[1:]
json.dump({"lab": int(n), "folder": folder, "files": files, "timeout": int(timeout),
           "wall_limit": int(wall), "cpu_limit": int(cpu)}, open(path, "w"), indent=2)
PY
  # Measure: the solution, uploaded as pl-file-upload leaves it, graded as PrairieLearn would.
  g="$MEASURE/$folder"
  mkdir -p "$g/student" "$g/tests"
  cp "$ROOT/solutions/$folder"/* "$g/student/"
  cp "$q/tests/lab.json" "$g/tests/"
  t0=$(date +%s.%N)
  GRADE_ROOT="$g" KIT_GRADE_BIN="$GRADER" python3 "$SFC/entrypoint.py" 2>"$g/log" || { cat "$g/log" >&2; die "lab $n: the entrypoint failed"; }
  t1=$(date +%s.%N)
  score="$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1])).get("score"))' "$g/results/results.json")"
  [ "$score" = "1.0" ] || { tail -5 "$g/log" >&2; die "lab $n: the reference solution scored $score, not 1.0, through the entrypoint"; }
  secs="$(python3 -c "print(f'{$t1 - $t0:.1f}')")"
  renderer="$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1])).get("output","").splitlines()[-1].removeprefix("Rendered with "))' "$g/results/results.json")"
  python3 - "$q" "$n" "$name" "$folder" "$IMAGE" "$TIMEOUT" "$secs" "$WALL" "$CPU" "$renderer" "$(nproc)" "${files[@]}" <<'PY'
import html, json, sys, uuid
q, n, name, folder, image, timeout, secs, wall, cpu, renderer, cores, *files = sys.argv[1:]
info = {
    # Stable across rewrites of the package, so PrairieLearn keeps the question's history.
    "uuid": str(uuid.uuid5(uuid.NAMESPACE_URL, f"deferred-rendering-kit/prairielearn/{folder}")),
    "title": f"Lab {n}: {name}",
    "topic": "Deferred rendering",
    "tags": ["deferred-kit", f"lab{int(n)}"],
    "type": "v3",
    "singleVariant": True,
    "gradingMethod": "External",
    "externalGradingOptions": {
        "enabled": True,
        "image": image,
        "entrypoint": "/grade/serverFilesCourse/deferred-kit/entrypoint.py",
        "serverFilesCourse": ["deferred-kit/"],
        "timeout": int(timeout),
        "comment": (f"Measured by ./kit prairielearn-package: the reference solution graded through the entrypoint "
                    f"in {secs} s (wall, {cores} cores, {renderer.rstrip('.')}). kit-grade stops a renderer after "
                    f"{wall} s of wall time or {cpu} s of CPU (tests/lab.json), so an endless loop is reported before "
                    f"this {timeout} s timeout (PrairieLearn's limit: 600 s)."),
    },
}
json.dump(info, open(f"{q}/info.json", "w"), indent=2)
names = ", ".join(files)
listed = ", ".join(f"<code>{html.escape(f)}</code>" for f in files)
open(f"{q}/question.html", "w").write(f"""<pl-question-panel>
  <p>Lab {n} ({html.escape(name)}): upload your {listed} from <code>labs/{html.escape(folder)}/</code>.</p>
  <p>The autograder renders your lab with the kit's grader and compares it with the reference renders:
    the same checks, tolerances and messages as <code>./kit grade labs --labs {n}</code> on your machine.
    For every check that fails you see your render, the reference and their difference.
    A submission without one of the files is not graded and costs no attempt.</p>
  <pl-file-upload file-names="{html.escape(names)}"></pl-file-upload>
</pl-question-panel>

<pl-submission-panel>
  <pl-external-grader-results></pl-external-grader-results>
  <pl-file-preview></pl-file-preview>
</pl-submission-panel>
""")
PY
  say "lab $n: $(basename "$q"): the solution scores 1.0 in $secs s (timeout $TIMEOUT s)"
done
cp "$HERE/README.md" "$DEST/README.md"
ok=1
say "wrote $DEST: ${#FOLDERS[@]} question(s); build and push image/ (README.md), then copy questions/ and serverFilesCourse/ into the course"
echo "$DEST"
