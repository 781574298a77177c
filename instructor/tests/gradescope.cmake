# The Gradescope autograder end to end: package, unpack into a simulated
# /autograder, run run_autograder with this build's kit-grade, validate
# results.json against Gradescope's schema (instructor/tests/gradescope_test.sh).
if(TARGET kit-grade)
  add_test(NAME gradescope_autograder
           COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/gradescope_test.sh $<TARGET_FILE:kit-grade>)
  set_tests_properties(gradescope_autograder PROPERTIES LABELS slow
    TIMEOUT 600
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    # About 16 s: started first, as kit_test's SLOW suites are (cmake/gtest_suites.cmake).
    COST 100
    FIXTURES_REQUIRED kit_grade_seed)
endif()
