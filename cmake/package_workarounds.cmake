# Workarounds for distribution packages whose CMake or pkg-config files are broken.
# Each names the package and version where it was found; none pins or replaces a library.

# kit_keep_existing_include_dirs(TARGET HEADER): drops from an imported TARGET's
# INTERFACE_INCLUDE_DIRECTORIES every entry that is relative or does not exist (CMake
# refuses such a target at generate time), then makes sure the folder holding HEADER
# is searched, found with find_path in the system's include folders.
#   Debian 13's libtinygltf-dev 2.9.5: TinyGLTFTargets.cmake computes _IMPORT_PREFIX
#   from its own location, which comes out empty, so TinyGLTF::TinyGLTF lists "include".
#   Debian 13's libdraco-dev 1.5.6: draco.pc says "Cflags: -Iinclude" (no ${prefix}).
function(kit_keep_existing_include_dirs target header)
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  set(kept "")
  set(dropped "")
  if(dirs)
    foreach(dir IN LISTS dirs)
      if(IS_ABSOLUTE "${dir}" AND EXISTS "${dir}")
        list(APPEND kept "${dir}")
      else()
        list(APPEND dropped "${dir}")
      endif()
    endforeach()
  endif()
  string(MAKE_C_IDENTIFIER "KIT_${header}_DIR" var)
  find_path(${var} NAMES ${header})
  if(NOT ${var})
    message(FATAL_ERROR "kit: ${header} (for ${target}) not found in the system's include folders")
  endif()
  # A folder the compiler searches anyway (/usr/include) is not added: as -isystem it
  # would reorder the compiler's own folders and break libstdc++'s #include_next.
  if(NOT "${${var}}" IN_LIST CMAKE_CXX_IMPLICIT_INCLUDE_DIRECTORIES)
    list(APPEND kept "${${var}}")
  endif()
  list(REMOVE_DUPLICATES kept)
  set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${kept}")
  if(dropped)
    message(STATUS "kit: ${target}: ignored include folders that do not exist (${dropped}); "
                   "${header} is in ${${var}}")
  endif()
endfunction()
