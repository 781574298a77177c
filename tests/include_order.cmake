# common/'s groups and tools/grade/'s include only downwards (common/include_order.py), with
# witnesses: a planted upward include is reported in each, an unqualified one in common/.
# Included from tests/CMakeLists.txt.
find_program(KIT_INCLUDE_ORDER_PYTHON NAMES python3 REQUIRED)
add_test(NAME include_order
         COMMAND ${KIT_INCLUDE_ORDER_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/include_order_test.py
                 ${CMAKE_BINARY_DIR}/test-tmp/include_order)
