# kit_gtest_suites(TARGET PREFIX WORKING_DIRECTORY ENVIRONMENT [SLOW] [GRADES]): one ctest
# test per GoogleTest suite of TARGET, named PREFIX<Suite> and running
# `TARGET --gtest_filter=<Suite>.*`. SLOW: the suites run the kit's programs and take
# tens of seconds, so ctest starts them first (COST), and the short ones fill the
# other core beside them instead of waiting at the end (a fresh build has no timings
# from an earlier run for ctest to order by). GRADES: they run kit-grade, so they wait
# for the grader's shader cache to be seeded (tests/grade.cmake, kit_grade_seed).
#
# Why suites and not single tests (gtest_discover_tests): a test process starts a
# headless GL context, loads the scenes its tests use and compiles their shaders, and
# one process per test would pay that start-up again for each of them. A suite shares
# the start-up, the headless context and the loaded scenes, and its name still says
# what failed; its output (shown on failure) names the test.
#
# The list is taken after each build of TARGET (as gtest_discover_tests does), so
# adding a TEST needs no new CMake run. The same file is the script that takes it
# (run with -P, LIST_MODE set).
if(NOT LIST_MODE)
  # Cached: kit_test() is also called from instructor/tests, which does not see this scope.
  set(KIT_GTEST_SUITES_SCRIPT ${CMAKE_CURRENT_LIST_FILE} CACHE INTERNAL "")

  function(kit_gtest_suites target prefix working_directory environment)
    set(cost 1)
    set(labels "")
    set(fixtures "")
    if("SLOW" IN_LIST ARGN)
      set(cost 100)
      set(labels slow)  # left out by ./kit test --quick
    endif()
    if("GRADES" IN_LIST ARGN)
      set(fixtures kit_grade_seed)
    endif()
    set(list_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites.cmake")
    add_custom_command(TARGET ${target} POST_BUILD
      COMMAND ${CMAKE_COMMAND} -D LIST_MODE=ON -D "PROGRAM=$<TARGET_FILE:${target}>" -D "PREFIX=${prefix}"
              -D "WORKING_DIRECTORY=${working_directory}" -D "ENVIRONMENT=${environment}"
              -D "COST=${cost}" -D "LABELS=${labels}" -D "FIXTURES=${fixtures}"
              -D "OUTPUT=${list_file}" -P ${KIT_GTEST_SUITES_SCRIPT}
      VERBATIM)
    # ctest reads the list through this file; before the first build it names a
    # placeholder test that fails, saying to build (as gtest_discover_tests does).
    set(include_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites_include.cmake")
    file(WRITE ${include_file}
      "if(EXISTS \"${list_file}\")\n"
      "  include(\"${list_file}\")\n"
      "else()\n"
      "  add_test(${prefix}NOT_BUILT ${target}_NOT_BUILT)\n"
      "endif()\n")
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${include_file})
  endfunction()
  return()
endif()

# --- list mode (cmake -P): writes OUTPUT, the add_test lines of PROGRAM's suites ---
execute_process(COMMAND "${PROGRAM}" --gtest_list_tests
                WORKING_DIRECTORY "${WORKING_DIRECTORY}" TIMEOUT 60
                RESULT_VARIABLE result OUTPUT_VARIABLE listing ERROR_VARIABLE errors)
if(NOT result EQUAL 0)
  file(REMOVE "${OUTPUT}")
  message(FATAL_ERROR "${PROGRAM} --gtest_list_tests failed (${result}):\n${listing}${errors}")
endif()
string(REPLACE ";" "\\;" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(script "")
set(suites 0)
function(add_listed_test name filter)
  string(APPEND script "add_test([==[${name}]==] [==[${PROGRAM}]==] [==[--gtest_filter=${filter}]==])\n"
    "set_tests_properties([==[${name}]==] PROPERTIES WORKING_DIRECTORY [==[${WORKING_DIRECTORY}]==]"
    " ENVIRONMENT [==[${ENVIRONMENT}]==] COST ${COST} LABELS [==[${LABELS}]==]"
    " FIXTURES_REQUIRED [==[${FIXTURES}]==])\n")
  set(script "${script}" PARENT_SCOPE)
endfunction()
foreach(line IN LISTS lines)
  # A suite's line starts in column 0 and ends with '.', before an optional comment
  # ("  # TypeParam = ..."); its tests' lines are indented.
  if(line MATCHES "^([^ #][^ ]*)\\.( .*)?$")
    add_listed_test("${PREFIX}${CMAKE_MATCH_1}" "${CMAKE_MATCH_1}.*")
    math(EXPR suites "${suites} + 1")
  endif()
endforeach()
if(suites EQUAL 0)
  file(REMOVE "${OUTPUT}")
  message(FATAL_ERROR "${PROGRAM} lists no test suite:\n${listing}")
endif()
file(WRITE "${OUTPUT}" "${script}")
