# instructor/tests/prairielearn_test.sh with this build's kit-grade: the package, then the entrypoint on a temporary /grade: solutions 1.0, starters
# under half, a missing file not gradable, a compile error and an endless loop reported, every
# results.json valid and under 1 MB. About 20 s of CPU (45 s wall on a busy 2-core machine).
if(TARGET kit-grade)
  add_test(NAME prairielearn_autograder
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/prairielearn_test.sh $<TARGET_FILE:kit-grade>)
  set_tests_properties(prairielearn_autograder PROPERTIES LABELS slow
    TIMEOUT 600
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    COST 90
    FIXTURES_REQUIRED kit_grade_seed)
endif()
