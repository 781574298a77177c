# kit-grade: the autograder (tools/grade/). Included from tools/CMakeLists.txt;
# needs kitcore and the scenes, and OpenSSL for SHA-1. A grading run never loads
# OpenImageIO (common/images/openimageio_formats.h says why).
find_package(nlohmann_json 3 REQUIRED)
find_package(OpenSSL REQUIRED)
# tools/grade/'s parts, lowest first, as common/'s groups are (README.md has what each
# holds): a file includes only its own part and those before it, as "part/file.h"
# (common/include_order.py, ctest include_order). main.cpp, above them all, is the command line.
set(KIT_GRADE_GROUPS files frames verdict intake worker reference_store report run batch)
# How a submission is found, sanitized and fingerprinted (intake/submission.cpp, with the
# sandbox it runs unzip in): tests/test_submission_layouts calls the very functions
# kit-grade does, through the target kit_grade_submission.
file(GLOB kit_grade_submission_sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/grade/intake/*.cpp)
if(KIT_FUZZ)
  # The fuzz build fuzzes the submission code alone (instructor/fuzz/fuzz_zip_listing.cpp), not kit-grade.
  add_library(kit_grade_submission STATIC ${kit_grade_submission_sources})
  target_include_directories(kit_grade_submission PUBLIC ${CMAKE_CURRENT_LIST_DIR}/grade)
  target_link_libraries(kit_grade_submission PUBLIC kitcore OpenSSL::Crypto)
  return()
endif()
# Everything but main(): the submission code, checks, comparisons, scoring and reports,
# so instructor/tests/test_grader calls the very code kit-grade runs. One library, the
# submission code in it, so that a unity build (KIT_UNITY_BUILD) compiles the headers
# they share once; kit_grade_submission names the same library.
set(kit_grade_sources)
foreach(group ${KIT_GRADE_GROUPS})
  file(GLOB group_sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/grade/${group}/*.cpp)
  list(APPEND kit_grade_sources ${group_sources})
endforeach()
add_library(kit_grade_core STATIC ${kit_grade_sources})
set_target_properties(kit_grade_core PROPERTIES UNITY_BUILD ${KIT_UNITY_BUILD} UNITY_BUILD_BATCH_SIZE 0)
target_include_directories(kit_grade_core PUBLIC ${CMAKE_CURRENT_LIST_DIR}/grade)
target_link_libraries(kit_grade_core PUBLIC kitcore OpenSSL::Crypto nlohmann_json::nlohmann_json)
add_library(kit_grade_submission ALIAS kit_grade_core)
add_executable(kit-grade ${CMAKE_CURRENT_LIST_DIR}/grade/main.cpp)
target_link_libraries(kit-grade PRIVATE kit_grade_core)
# The references decoded, with their backgrounds and report PNGs, once when kit-grade is
# built, not in each machine's first grading run (about 0.4 s of its CPU; a run reads them
# here, reference_store/references.h). Made afresh when kit-grade or a reference changes: a file there is
# named by its reference's SHA-1 alone, and would outlive a change in how it is made.
set(KIT_PREPARED_REFERENCES_DIR ${CMAKE_BINARY_DIR}/grade-references)
# On the one file that reads it (a build's own folder: common/CMakeLists.txt says why).
set_property(SOURCE ${PROJECT_SOURCE_DIR}/tools/grade/reference_store/references.cpp APPEND PROPERTY COMPILE_DEFINITIONS
  KIT_PREPARED_REFERENCES_DIR="${KIT_PREPARED_REFERENCES_DIR}")
file(GLOB kit_grade_reference_files CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/tools/grade/references/*)
add_custom_command(
  OUTPUT ${KIT_PREPARED_REFERENCES_DIR}/prepared.stamp
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${KIT_PREPARED_REFERENCES_DIR}
  COMMAND kit-grade --prepare-references ${KIT_PREPARED_REFERENCES_DIR}
  # Stale references are left out (a new check's, before --update-references makes it): the
  # folder may not exist then, and the stamp still marks this state done.
  COMMAND ${CMAKE_COMMAND} -E make_directory ${KIT_PREPARED_REFERENCES_DIR}
  COMMAND ${CMAKE_COMMAND} -E touch ${KIT_PREPARED_REFERENCES_DIR}/prepared.stamp
  DEPENDS kit-grade ${kit_grade_reference_files}
  COMMENT "Preparing the grader's references in ${KIT_PREPARED_REFERENCES_DIR}"
  VERBATIM)
add_custom_target(kit_grade_references ALL DEPENDS ${KIT_PREPARED_REFERENCES_DIR}/prepared.stamp)
# The grader renders the generated scenes: building it builds them.
add_dependencies(kit-grade kit_scene_files)
