# instructor/tests/platforms_test.sh with this build's kit-grade: one submission through Gradescope,
# PrairieLearn and Classroom 50, the same per-check verdict. About 12 s of CPU.
if(TARGET kit-grade)
  add_test(NAME platforms_autograder
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/platforms_test.sh $<TARGET_FILE:kit-grade>)
  set_tests_properties(platforms_autograder PROPERTIES LABELS slow
    TIMEOUT 600
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    COST 60
    FIXTURES_REQUIRED kit_grade_seed)
endif()
