# The grader's references (tools/grade/references/) agree with its check list and
# with this machine's renders of every solution the kit holds: all of them in the
# instructor's kit, the released ones in a student copy. A student's self-check
# (./kit grade labs) is only as good as this.
add_test(NAME grade_references_reproduce COMMAND $<TARGET_FILE:kit-grade> --check-references)
set_tests_properties(grade_references_reproduce PROPERTIES
  ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
  TIMEOUT 300)
