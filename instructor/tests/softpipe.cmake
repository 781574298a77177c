# Portable verdicts: the reference solutions keep full marks with the shipped references
# when another conformant OpenGL renders them (handouts/instructors.md, Portable verdicts).
# Mesa's softpipe (GALLIUM_DRIVER=softpipe) is the other implementation every machine has:
# it rasterises, filters and rounds differently from llvmpipe, which made the references.
# Labs 1-5 only (about 15 s): softpipe takes over a minute of CPU for lab 6's maps, which
# instructors.md's figures cover instead. Included from tests/CMakeLists.txt.
if(TARGET kit-grade)
  add_test(NAME grade_solutions_softpipe
           COMMAND ${CMAKE_COMMAND} -E env GALLIUM_DRIVER=softpipe
                   ${CMAKE_CURRENT_LIST_DIR}/grade_softpipe_test.sh $<TARGET_FILE:kit-grade>
                   ${CMAKE_SOURCE_DIR}/solutions ${CMAKE_BINARY_DIR}/test-tmp/grade_softpipe)
  set_tests_properties(grade_solutions_softpipe PROPERTIES LABELS slow
    TIMEOUT 300
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    COST 150)
endif()

# GPU-like texture filtering (llvmpipe's GALLIVM_PERF approximations): the solutions keep
# full marks through the references' filter allowances, with a witness that they would not
# without them (grade_filtering_test.sh). About 15 s.
if(TARGET kit-grade)
  add_test(NAME grade_solutions_gpu_like_filtering
           COMMAND ${CMAKE_CURRENT_LIST_DIR}/grade_filtering_test.sh $<TARGET_FILE:kit-grade>
                   ${CMAKE_SOURCE_DIR}/solutions ${CMAKE_SOURCE_DIR}/tools/grade/references
                   ${CMAKE_BINARY_DIR}/test-tmp/grade_filtering)
  set_tests_properties(grade_solutions_gpu_like_filtering PROPERTIES LABELS slow
    TIMEOUT 300
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    COST 100)
endif()
