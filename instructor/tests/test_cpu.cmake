# instructor/test_cpu.py, which the figures page's CPU table comes from (test_cpu_test.sh).
# Included from instructor/tests/CMakeLists.txt.
add_test(NAME test_cpu_tool
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/test_cpu_test.sh ${CMAKE_BINARY_DIR}/test-tmp/test_cpu)
