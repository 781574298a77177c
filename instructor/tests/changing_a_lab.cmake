# The worked example of instructor/changing_a_lab/README.md (Smith's G in lab 2) applied to
# a copy of the kit and rebaselined with this build's programs (changing_a_lab_test.sh).
# Two to three minutes on two cores: labelled slow. Included from tests/CMakeLists.txt.
if(TARGET kit-grade AND TARGET kit-render)
  add_test(NAME changing_a_lab
           COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/changing_a_lab_test.sh ${CMAKE_BINARY_DIR}
                   ${CMAKE_BINARY_DIR}/test-tmp/changing_a_lab)
  set_tests_properties(changing_a_lab PROPERTIES LABELS slow TIMEOUT 900 COST 1000
    FIXTURES_REQUIRED kit_grade_seed)
endif()
