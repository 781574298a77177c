# The GL loader, generated at configure time by the packaged glad (python3-glad),
# from the XML it ships (--reproducible: no network). Two generations are packaged:
# glad 2 (Debian 12, Ubuntu 24.04: `glad --api gl:core=4.3 ... c`, <glad/gl.h>)
# and glad 0.1 (Ubuntu 22.04: `glad --profile core --api gl=4.3 --generator c`,
# <glad/glad.h>). The kit speaks to either through common/gl/gl.h, keyed on
# KIT_GLAD_GENERATION (1 or 2).
set(KIT_GLAD_DIR ${CMAKE_BINARY_DIR}/glad)
find_program(GLAD_EXECUTABLE glad)
if(NOT GLAD_EXECUTABLE)
  message(FATAL_ERROR "glad not found: install python3-glad (./kit setup does)")
endif()
execute_process(COMMAND ${GLAD_EXECUTABLE} --help OUTPUT_VARIABLE glad_help ERROR_VARIABLE glad_help_err
                RESULT_VARIABLE glad_help_result)
if(glad_help MATCHES "--generator")
  # glad 0.1.x: --reproducible (the bundled XML, no download) where this release has it.
  set(KIT_GLAD_GENERATION 1)
  set(glad_source ${KIT_GLAD_DIR}/src/glad.c)
  set(glad_reproducible "")
  if(glad_help MATCHES "--reproducible")
    set(glad_reproducible --reproducible)
  endif()
  set(glad_command ${GLAD_EXECUTABLE} --quiet ${glad_reproducible} --profile core --api gl=4.3
                   --extensions GL_KHR_debug --generator c --out-path ${KIT_GLAD_DIR})
else()
  set(KIT_GLAD_GENERATION 2)
  set(glad_source ${KIT_GLAD_DIR}/src/gl.c)
  set(glad_command ${GLAD_EXECUTABLE} --quiet --reproducible --api gl:core=4.3
                   --extensions GL_KHR_debug --out-path ${KIT_GLAD_DIR} c)
endif()
if(NOT EXISTS ${glad_source})
  execute_process(COMMAND ${glad_command} RESULT_VARIABLE glad_result OUTPUT_VARIABLE glad_out ERROR_VARIABLE glad_err)
  if(NOT glad_result EQUAL 0 OR NOT EXISTS ${glad_source})
    message(FATAL_ERROR "glad (generation ${KIT_GLAD_GENERATION}, ${GLAD_EXECUTABLE}) failed to generate the GL loader:\n"
                        "${glad_out}${glad_err}")
  endif()
endif()
add_library(kit_glad STATIC ${glad_source})
target_include_directories(kit_glad SYSTEM PUBLIC ${KIT_GLAD_DIR}/include)
target_compile_definitions(kit_glad PUBLIC KIT_GLAD_GENERATION=${KIT_GLAD_GENERATION})
set_target_properties(kit_glad PROPERTIES POSITION_INDEPENDENT_CODE ON)
if(KIT_GLAD_GENERATION EQUAL 1)
  set(KIT_GLAD_HEADER glad/glad.h)
else()
  set(KIT_GLAD_HEADER glad/gl.h)
endif()
