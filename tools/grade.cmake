# kit-grade: the autograder (tools/grade/). Included from tools/CMakeLists.txt;
# needs kitcore (which brings OpenImageIO for the comparisons) and the scenes.
find_package(nlohmann_json 3 REQUIRED)
file(GLOB kit_grade_sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/grade/*.cpp)
add_executable(kit-grade ${kit_grade_sources})
target_link_libraries(kit-grade PRIVATE kitcore PkgConfig::OIIO nlohmann_json::nlohmann_json)
# The grader renders the generated scenes: building it builds them.
add_dependencies(kit-grade kit_scene_files)
