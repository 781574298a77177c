# The browser build in Debian's headless chromium (tests/web_test.py): the site's frames of
# every stage against kit-render's, within the tolerance the script states, a witness, a
# refused OBJ scene, and the page's check of every lab against kit-grade's; the students'
# page (tests/web_page_test.py); a first visit's bytes (tests/web_first_visit_test.py). They
# build nothing: the site is kit-web's build folder, which
# ./kit test builds in the kit with instructor/ (its own suite; KIT_WEB_SITE to test another,
# such as out/web). A student copy's ./kit test neither builds the site nor has these tests:
# a student runs ./kit web when they want it.
# Label `web`. Included from tests/CMakeLists.txt.
set(KIT_WEB_SITE ${PROJECT_SOURCE_DIR}/build/web/tools/web CACHE PATH "The browser build's site that ctest's web test loads")
if(TARGET kit-render AND KIT_HAS_INSTRUCTOR)
  find_program(KIT_WEB_PYTHON NAMES python3 REQUIRED)
  add_test(NAME web_browser
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_test.py ${KIT_WEB_SITE} $<TARGET_FILE:kit-render>
                   $<TARGET_FILE:kit-grade> ${CMAKE_BINARY_DIR}/test-tmp/web)
  set_tests_properties(web_browser PROPERTIES LABELS web TIMEOUT 300
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes")
  # The students' page (tests/web_page_test.py): its editor, compile errors at the student's
  # line, edits kept across a reload, a lost context, a dropped .glb (written from the desktop
  # build's scenes), Download my labs and Check my lab, in the same browser and site.
  add_test(NAME web_page
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_page_test.py ${KIT_WEB_SITE} ${CMAKE_BINARY_DIR}/scenes
                   $<TARGET_FILE:kit-grade> ${CMAKE_BINARY_DIR}/test-tmp/web-page)
  set_tests_properties(web_page PROPERTIES LABELS web TIMEOUT 300
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes")
  # A first visit over a 20 Mbit/s link (tests/web_first_visit_test.py): the bytes before the
  # first frame, from the kit's server and a plain one, without the grader's references, which
  # "Check my lab" fetches. Alone: its SwiftShader frames would slow the other browser tests
  # that run beside it (web_browser past its limit), and the time it reports means more.
  add_test(NAME web_first_visit
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_first_visit_test.py ${KIT_WEB_SITE}
                   ${CMAKE_BINARY_DIR}/test-tmp/web-first-visit)
  set_tests_properties(web_first_visit PROPERTIES LABELS web TIMEOUT 300 RUN_SERIAL TRUE)
endif()
