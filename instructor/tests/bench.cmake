# kit-bench --quick as a smoke test: it must finish, write rows and the three charts
# (the IBL family's included).
# Times are not checked (they are measured, never asserted).
add_test(NAME bench_quick
  COMMAND bash -c "out=\"$1\"; rm -rf \"$out\" && \"$0\" --quick --out \"$out\" && \
test \"$(wc -l < \"$out/results.csv\")\" -gt 1 && \
grep -q '^ibl-sh2,' \"$out/results.csv\" && \
for f in speed_accuracy.png speed_accuracy.svg lights_scaling.png lights_scaling.svg ibl_speed_accuracy.png ibl_speed_accuracy.svg; do \
test -s \"$out/$f\" || { echo \"missing $out/$f\"; exit 1; }; done"
    $<TARGET_FILE:kit-bench> ${CMAKE_BINARY_DIR}/test-tmp/bench_quick)
set_tests_properties(bench_quick PROPERTIES LABELS slow
  ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
  TIMEOUT 300
  # About 15 s: started first, as kit_test's SLOW suites are (cmake/gtest_suites.cmake).
  COST 100)
