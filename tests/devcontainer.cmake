# The development container (.devcontainer/): its configuration, and the viewer on a TigerVNC
# display as desktop-lite runs it, screenshot through VNC (tests/devcontainer_test.py).
# Included from tests/CMakeLists.txt.
if(TARGET kit-view)
  add_test(NAME devcontainer
    COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/devcontainer_test.py
            $<TARGET_FILE:kit-view> $<TARGET_FILE:kit-render> ${CMAKE_CURRENT_BINARY_DIR}/devcontainer)
  set_tests_properties(devcontainer PROPERTIES
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    LABELS "window"
    TIMEOUT 120)
endif()
