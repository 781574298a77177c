# ./kit student-copy end to end (instructor/tests/student_copy_test.sh): copies for
# every lab hold no solution line of their lab or later (with a planted leak as
# witness), and the copy for lab 2 builds from a fresh clone without OSMesa (as Mesa
# 25.1 and later are), passes its own ./kit demo and ./kit test on EGL, renders what the
# kit renders, refuses --backend osmesa, and its grader scores the starter low and the
# solution full. It builds a second kit (the copy's), so it takes minutes.
add_test(NAME student_copy
  COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/student_copy_test.sh $<TARGET_FILE:kit-grade> ${CMAKE_BINARY_DIR}/test-tmp/student_copy)
set_tests_properties(student_copy PROPERTIES LABELS slow
  TIMEOUT 1500
  # The longest test: started first, the others fill the cores beside it. Its own steps
  # leave a core idle in turn (configure, scene generation, the copy's ctest, grading),
  # so it does not run alone: sharing costs its build a little and saves the whole run more.
  COST 2000)
