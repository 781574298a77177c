# The grader's self-check (instructor/grading/self_check.py): every entry of
# instructor/grading/catalogue.json graded with this build's kit-grade. Plausible
# mistakes must lose points and equivalent solutions must keep full marks.
# Included from tests/CMakeLists.txt.
if(TARGET kit-grade)
  # Debian's interpreter (the script needs only the standard library), else any python3.
  find_program(KIT_SELF_CHECK_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
  find_program(KIT_SELF_CHECK_PYTHON NAMES python3 REQUIRED)
  # Seconds: every catalogue entry is applied to the solutions; a stale one is named at once.
  add_test(NAME grade_catalogue_entries
           COMMAND ${KIT_SELF_CHECK_PYTHON} ${CMAKE_SOURCE_DIR}/instructor/grading/self_check.py --validate)
  # About a minute on two cores: one kit-grade --batch run per lab.
  add_test(NAME grade_self_check
           COMMAND ${KIT_SELF_CHECK_PYTHON} ${CMAKE_SOURCE_DIR}/instructor/grading/self_check.py
                   --kit-grade $<TARGET_FILE:kit-grade> --jobs 2
                   --json ${CMAKE_BINARY_DIR}/test-tmp/self_check.json)
  set_tests_properties(grade_self_check PROPERTIES LABELS slow
    TIMEOUT 600
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    # Started early (after student_copy), beside the others: its batches end with a
    # core idle while the last submission renders.
    COST 1500
    FIXTURES_REQUIRED kit_grade_seed
    FIXTURES_SETUP kit_self_check_rows)
  # The handouts' figures that follow from grading (instructor/handout_figures.py): the
  # grading settings' at once, a mistake's cost from the self-check's rows; the witness, a
  # copy of a handout with a figure changed, fails naming it.
  add_test(NAME handout_figures
           COMMAND ${KIT_SELF_CHECK_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/handout_figures_test.py
                   ${CMAKE_BINARY_DIR}/test-tmp/handout_figures)
  add_test(NAME handout_figures_costs
           COMMAND ${KIT_SELF_CHECK_PYTHON} ${CMAKE_SOURCE_DIR}/instructor/handout_figures.py
                   --self-check-json ${CMAKE_BINARY_DIR}/test-tmp/self_check.json)
  set_tests_properties(handout_figures_costs PROPERTIES LABELS slow FIXTURES_REQUIRED kit_self_check_rows)
endif()
