#!/usr/bin/env bash
# Builds the libFuzzer harnesses (preset fuzz: clang, ASan + UBSan, build/fuzz),
# replays every input of instructor/fuzz/regressions/<harness>/, then runs each
# harness for a bounded time from seeds the kit generates. Exit status 0: no
# finding; 1: a regression input or the fuzzing found a problem (named on
# stderr, with how to reproduce it); 2: a usage or set-up error.
#
#   run_fuzz.sh                      20 s per harness (the ctest `fuzz`)
#   run_fuzz.sh --minutes 10         a longer run: 10 minutes per harness
#   options: --seconds N | --minutes N   time per harness
#            --only NAME[,NAME]          gltf, shader, zip_listing (default: all three)
#            --scenes DIR                the generated scenes (default build/default/scenes)
#            --out DIR                   corpora, findings and logs (default build/fuzz/runs)
#            --build-jobs N              ninja jobs for the build (default 1)
# See instructor/fuzz/README.md.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
FUZZ_DIR="$ROOT/instructor/fuzz"
BIN_DIR="$ROOT/build/fuzz/instructor/fuzz"
seconds=20
only="gltf,shader,zip_listing"
scenes="$ROOT/build/default/scenes"
out="$ROOT/build/fuzz/runs"
build_jobs=1

say() { printf 'run_fuzz: %s\n' "$*" >&2; }
usage_error() { say "$*"; exit 2; }

while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --minutes) seconds=$(( $2 * 60 )); shift 2 ;;
    --only) only="$2"; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --build-jobs) build_jobs="$2"; shift 2 ;;
    -h|--help) sed -n '2,15p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) usage_error "unknown option '$1' (--help lists them)" ;;
  esac
done
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || usage_error "--seconds/--minutes: a positive whole number, not '$seconds'"
IFS=, read -r -a harnesses <<<"$only"
for h in "${harnesses[@]}"; do
  case "$h" in gltf|shader|zip_listing) ;; *) usage_error "--only: unknown harness '$h' (gltf, shader, zip_listing)" ;; esac
done

# --- clang with libFuzzer: missing means the kit was not set up, never a skip ---
need_setup() {
  say "FAILED: $* - the fuzz tests need clang with libFuzzer: run ./kit setup (it installs clang and libFuzzer: libclang-rt-dev)"
  exit 1
}
command -v clang >/dev/null || need_setup "clang is not installed"
command -v clang++ >/dev/null || need_setup "clang++ is not installed"
probe_dir="$(mktemp -d)"
trap 'rm -rf "$probe_dir"' EXIT
printf 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }\n' >"$probe_dir/probe.cpp"
clang++ -fsanitize=fuzzer,address,undefined "$probe_dir/probe.cpp" -o "$probe_dir/probe" 2>"$probe_dir/probe.log" ||
  need_setup "clang++ -fsanitize=fuzzer cannot link ($(head -c 300 "$probe_dir/probe.log"))"
[ -f "$scenes/sphere/sphere.gltf" ] ||
  usage_error "no generated scenes in $scenes (build the kit first: ./kit setup; or pass --scenes DIR)"

# --- build (one run at a time: two suites' ctests share build/fuzz) ---
mkdir -p "$out" "$ROOT/build"
out="$(cd "$out" && pwd)"
exec 9>"$ROOT/build/fuzz.lock"
flock 9
say "building the fuzz preset (build/fuzz; log in $out/build.log)"
if ! (cd "$ROOT" && cmake --preset fuzz && cmake --build --preset fuzz -- -j "$build_jobs") >"$out/build.log" 2>&1; then
  tail -n 40 "$out/build.log" >&2
  say "FAILED: the fuzz preset did not build (log: $out/build.log)"
  exit 1
fi

export KIT_SCENE_DIR="$scenes"
export TMPDIR="$out/tmp"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
mkdir -p "$TMPDIR"

# --- seeds, generated from the kit's own files each run ---
seeds="$out/seeds"
rm -rf "$seeds"
mkdir -p "$seeds/gltf" "$seeds/shader" "$seeds/zip_listing"
for f in "$scenes"/*/*.gltf; do cp "$f" "$seeds/gltf/"; done
# A .glb of the grazing scene (the smallest buffer): its JSON chunk with the buffer inlined as the BIN chunk.
python3 - "$scenes/grazing/grazing.gltf" "$seeds/gltf/grazing.glb" <<'PY'
import json, struct, sys, os
src, dst = sys.argv[1], sys.argv[2]
doc = json.load(open(src))
data = open(os.path.join(os.path.dirname(src), doc["buffers"][0]["uri"]), "rb").read()
del doc["buffers"][0]["uri"]
text = json.dumps(doc, separators=(",", ":")).encode()
text += b" " * (-len(text) % 4)
data += b"\0" * (-len(data) % 4)
body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(data), 0x004E4942) + data
open(dst, "wb").write(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)
PY
# The shader harness writes its own seeds (labs/, solutions/ and shaders/
# texts behind the byte that picks the lab file they stand in for).
KIT_FUZZ_WRITE_SEEDS="$seeds/shader" "$BIN_DIR/fuzz_shader" >"$out/seeds-shader.log" 2>&1 ||
  { cat "$out/seeds-shader.log" >&2; say "FAILED: fuzz_shader could not write its seeds"; exit 1; }
# Zip listings: `unzip -Z1` of archives in the layouts the grader accepts and refuses.
zips="$out/zips"
rm -rf "$zips"
mkdir -p "$zips"
(
  cd "$zips"
  mkdir -p a/labs/02-lighting a/labs/01-gbuffer b/alice/Labs/02-Lighting c d/x/y/z/w/03-attenuation e/__MACOSX
  for f in lighting.frag brdf.glsl; do echo "// $f" >"a/labs/02-lighting/$f"; echo "// $f" >"b/alice/Labs/02-Lighting/$f"; echo "// $f" >"c/$f"; done
  echo "// v" >a/labs/01-gbuffer/gbuffer.vert
  echo "// t" >d/x/y/z/w/03-attenuation/tonemap.glsl
  echo "// m" >e/__MACOSX/._x
  echo "notes" >c/README.md
  for z in a b c d e; do (cd "$z" && zip -qr "../$z.zip" .); done
)
listing_seed() {  # listing_seed NAME LABS-BYTE ZIP
  { printf "$2"; unzip -Z1 "$3"; } >"$seeds/zip_listing/$1"
}
listing_seed a-all '\x1f' "$zips/a.zip"
listing_seed a-lab2 '\x02' "$zips/a.zip"
listing_seed b-lab2 '\x02' "$zips/b.zip"
listing_seed c-loose-lab2 '\x02' "$zips/c.zip"
listing_seed c-loose-labs-1-2 '\x03' "$zips/c.zip"
listing_seed d-too-deep '\x04' "$zips/d.zip"
listing_seed e-macosx '\x1f' "$zips/e.zip"
printf '\x02../02-lighting/brdf.glsl\n/etc/passwd\n02-lighting/brdf.glsl\n02-lighting/brdf.glsl\n' >"$seeds/zip_listing/unsafe"

status=0
report=()

# --- regression inputs: every input that ever crashed a harness, replayed ---
for h in "${harnesses[@]}"; do
  dir="$FUZZ_DIR/regressions/$h"
  [ -d "$dir" ] || continue
  mapfile -t inputs < <(find "$dir" -type f ! -name 'README*' | sort)
  [ ${#inputs[@]} -gt 0 ] || continue
  if "$BIN_DIR/fuzz_$h" -rss_limit_mb=2048 -timeout=10 "${inputs[@]}" >"$out/regressions-$h.log" 2>&1; then
    say "fuzz_$h: ${#inputs[@]} regression inputs replayed, no finding"
  else
    tail -n 30 "$out/regressions-$h.log" >&2
    say "FAILED: fuzz_$h fails on a regression input of instructor/fuzz/regressions/$h/ (log: $out/regressions-$h.log)"
    status=1
  fi
done

# --- fuzzing ---
for h in "${harnesses[@]}"; do
  corpus="$out/corpus/$h"
  findings="$out/findings/$h"
  mkdir -p "$corpus" "$findings"
  extra=()
  # Long lines and long files are where the shader reader had its problems.
  [ "$h" = shader ] && extra=(-max_len=65536 -dict="$FUZZ_DIR/shader.dict")
  say "fuzz_$h: fuzzing for $seconds s (log: $out/fuzz-$h.log)"
  TIMEFORMAT='%U %S'
  set +e
  { time "$BIN_DIR/fuzz_$h" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 "${extra[@]}" \
      -print_final_stats=1 -artifact_prefix="$findings/" "$corpus" "$seeds/$h" >"$out/fuzz-$h.log" 2>&1; } 2>"$out/time-$h"
  rc=$?
  set -e
  runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/fuzz-$h.log" | tail -n 1)"
  cpu="$(awk '{ printf "%.0f", $1 + $2 }' "$out/time-$h" 2>/dev/null || echo '?')"
  line="fuzz_$h: ${runs:-?} executions, ${cpu} s CPU, corpus $(find "$corpus" -type f | wc -l) inputs"
  if [ "$rc" -ne 0 ]; then
    status=1
    grep -E 'ERROR: |runtime error|==ERROR|Test unit written' "$out/fuzz-$h.log" | head -n 8 >&2 || true
    for f in "$findings"/*; do
      [ -f "$f" ] || continue
      say "FINDING: $f"
      say "  reproduce: KIT_SCENE_DIR=$scenes $BIN_DIR/fuzz_$h $f"
      say "  keep it:   cp $f $FUZZ_DIR/regressions/$h/ (then fix, and replay with this script)"
    done
    line="$line - FINDING (log: $out/fuzz-$h.log)"
  fi
  report+=("$line")
done

for line in "${report[@]}"; do say "$line"; done
[ "$status" -eq 0 ] && say "no finding" || say "FAILED: see the findings above"
exit "$status"
