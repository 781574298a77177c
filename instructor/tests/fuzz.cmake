# The libFuzzer harnesses (instructor/fuzz/run_fuzz.sh): builds the fuzz preset
# (clang, ASan + UBSan, in build/fuzz), replays every input of
# instructor/fuzz/regressions/, and fuzzes the glTF loader, the shader assembler
# and the grader's zip listing parser for 10 s each from seeds made of this
# build's scenes, the kit's shaders and zips listed by unzip. Without clang it
# fails and says to run ./kit setup. One process at a time (the build with one
# job, then each harness), so it shares the cores with the other tests; the first
# build is most of its time. Longer runs: run_fuzz.sh --minutes N.
add_test(NAME fuzz
  COMMAND bash ${CMAKE_SOURCE_DIR}/instructor/fuzz/run_fuzz.sh --seconds 10
          --scenes ${CMAKE_BINARY_DIR}/scenes --out ${CMAKE_BINARY_DIR}/test-tmp/fuzz)
# COST: the longest test that can share the machine starts first, so the short ones
# fill the other core beside it instead of waiting at the end (a fresh clone has no
# timings from an earlier run for ctest to order by).
set_tests_properties(fuzz PROPERTIES LABELS slow TIMEOUT 900 COST 1000)
