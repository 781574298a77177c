# kit-bench: speed against accuracy of the pipeline's methods (tools/bench/). Included
# from tools/CMakeLists.txt; the methods themselves live in kitcore (common/bench_*),
# so the tests can render them too.
file(GLOB kit_bench_sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/bench/*.cpp)
add_executable(kit-bench ${kit_bench_sources} ${CMAKE_CURRENT_LIST_DIR}/cli.cpp)
target_include_directories(kit-bench PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bench)
target_link_libraries(kit-bench PRIVATE kitcore)
# The bench renders the generated scenes.
add_dependencies(kit-bench kit_scene_files)
