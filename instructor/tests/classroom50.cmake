# instructor/tests/classroom50_test.sh with this build's kit-grade: lab 2's bundle graded in a clean clone of the
# student copy: result.json's schema, starter low, solution full, a tampered checkout grades
# the same, a broken set-up fails. About 4 s of CPU.
if(TARGET kit-grade)
  add_test(NAME classroom50_autograder
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/classroom50_test.sh $<TARGET_FILE:kit-grade>)
  set_tests_properties(classroom50_autograder PROPERTIES LABELS slow
    TIMEOUT 600
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    COST 20
    FIXTURES_REQUIRED kit_grade_seed)
endif()
