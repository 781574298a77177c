# The viewer under Xvfb: its image and its window pixels must equal kit-render's
# headless frame (instructor/tests/window_matches_headless.sh). Included from tests/CMakeLists.txt.
if(TARGET kit-view)
  add_test(NAME window_matches_headless
    COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/window_matches_headless.sh
            $<TARGET_FILE:kit-view> $<TARGET_FILE:kit-render> ${CMAKE_CURRENT_BINARY_DIR}/window_matches_headless)
  set_tests_properties(window_matches_headless PROPERTIES
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    LABELS "window;slow"
    TIMEOUT 180)
endif()
