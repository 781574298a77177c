# common/'s groups include only downwards (common/include_order.py), with a witness: a
# planted upward include and an unqualified one are reported. Included from
# tests/CMakeLists.txt.
find_program(KIT_INCLUDE_ORDER_PYTHON NAMES python3 REQUIRED)
add_test(NAME common_include_order
         COMMAND ${KIT_INCLUDE_ORDER_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/include_order_test.py
                 ${CMAKE_BINARY_DIR}/test-tmp/include_order)
