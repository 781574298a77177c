# The kit built without OSMesa (no_osmesa_test.sh): a second, grading-only build
# configured with -DKIT_OSMESA=OFF, as on a distribution whose Mesa (25.1 and later) has
# none. It renders and grades the reference solutions, so it is the instructors' (a
# student copy lacks the later ones). Included from instructor/tests/CMakeLists.txt.
if(TARGET kit-render AND TARGET kit-grade)
  add_test(NAME no_osmesa
           COMMAND ${CMAKE_CURRENT_LIST_DIR}/no_osmesa_test.sh ${PROJECT_SOURCE_DIR} ${CMAKE_BINARY_DIR}
                   ${CMAKE_BINARY_DIR}/test-tmp/no_osmesa)
  set_tests_properties(no_osmesa PROPERTIES LABELS slow TIMEOUT 600 COST 200)
endif()
