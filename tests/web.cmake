# The browser build in Debian's headless chromium (tests/web_test.py): the site's frames of
# every stage against kit-render's, within the tolerance the script states, a witness, the
# kit's OBJ scene, and the page's check of every lab against kit-grade's; the students' page
# (tests/web_page_test.py); the handout in it and its layout (tests/web_handout_test.py); a
# student's OBJ scene dropped on it (tests/web_obj_test.py); a first visit's bytes
# (tests/web_first_visit_test.py). The site is kit-web's build folder (KIT_WEB_SITE to test
# another, such as out/web), which ./kit test configures in the kit with instructor/ (its own
# suite) and the test web_site builds, which every browser test waits for: one of them run
# alone (ctest -R web_page) tests the site as the sources are. A student
# copy's ./kit test neither builds the site nor has these tests: a student runs ./kit web
# when they want it. Label `web`. Included from tests/CMakeLists.txt.
set(KIT_WEB_BUILD ${PROJECT_SOURCE_DIR}/build/web)
set(KIT_WEB_SITE ${KIT_WEB_BUILD}/tools/web CACHE PATH "The browser build's site that ctest's web test loads")
if(TARGET kit-render AND KIT_HAS_INSTRUCTOR)
  if(KIT_WEB_SITE STREQUAL "${KIT_WEB_BUILD}/tools/web")
    # KIT_BUILD_PARALLEL: the jobs ./kit lets a build run on the memory there is (kit, plan_build_memory).
    add_test(NAME web_site
             COMMAND sh -c "[ -f '${KIT_WEB_BUILD}/build.ninja' ] || { echo 'web_site: ${KIT_WEB_BUILD} is not configured: ./kit test or ./kit web configures it'; exit 1; }; exec '${CMAKE_COMMAND}' --build '${KIT_WEB_BUILD}' \${KIT_BUILD_PARALLEL:+--parallel \"\$KIT_BUILD_PARALLEL\"}")
    # Started first (COST): the browser tests wait for it.
    set_tests_properties(web_site PROPERTIES LABELS web TIMEOUT 1200 COST 10000 FIXTURES_SETUP kit_web_site)
    set(KIT_WEB_FIXTURE FIXTURES_REQUIRED kit_web_site)
  endif()
  find_program(KIT_WEB_PYTHON NAMES python3 REQUIRED)
  add_test(NAME web_browser
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_test.py ${KIT_WEB_SITE} $<TARGET_FILE:kit-render>
                   $<TARGET_FILE:kit-grade> ${CMAKE_BINARY_DIR}/test-tmp/web)
  set_tests_properties(web_browser PROPERTIES ${KIT_WEB_FIXTURE} LABELS web TIMEOUT 300
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes")
  # The students' page (tests/web_page_test.py): its editor, compile errors at the student's
  # line, edits kept across a reload, a lost context, a dropped .glb (written from the desktop
  # build's scenes), Download my labs and Check my lab, in the same browser and site.
  add_test(NAME web_page
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_page_test.py ${KIT_WEB_SITE} ${CMAKE_BINARY_DIR}/scenes
                   $<TARGET_FILE:kit-grade> ${CMAKE_BINARY_DIR}/test-tmp/web-page)
  set_tests_properties(web_page PROPERTIES ${KIT_WEB_FIXTURE} LABELS web TIMEOUT 300
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes")
  # A shader that loops forever in the page (tests/web_runaway_test.py): drawn, every loop cut at
  # its budget, and a tab ended while it draws followed by a load without that edit. Slow
  # (seconds of SwiftShader a step): ./kit test runs it, --quick leaves it out.
  add_test(NAME web_runaway
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_runaway_test.py ${KIT_WEB_SITE}
                   ${CMAKE_BINARY_DIR}/test-tmp/web-runaway)
  set_tests_properties(web_runaway PROPERTIES ${KIT_WEB_FIXTURE} LABELS "web;slow" TIMEOUT 300)
  # The handout in the page (tests/web_handout_test.py): formulas typeset, a likely mistake's
  # link opening its section, views from a handout's links, the layout at 1280x720, 1920x1080
  # and a tablet's width, and a class's site (./kit web --student-copy 2) without an
  # instructors' section. Screenshots in its work folder.
  add_test(NAME web_handout
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_handout_test.py ${KIT_WEB_SITE}
                   ${CMAKE_BINARY_DIR}/test-tmp/web-handout)
  set_tests_properties(web_handout PROPERTIES ${KIT_WEB_FIXTURE} LABELS web TIMEOUT 400)
  # The page's Progress report (tests/web_report_test.py): each lab checked and timed in the
  # page, notes typed in, the report printed to PDF by chromium and read back by pdftotext;
  # /usr/bin/python3 for Debian's pystache, with which it fills the same layout. Slow (every lab
  # checked on SwiftShader, minutes): ./kit test runs it, --quick leaves it out.
  find_program(KIT_WEB_REPORT_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
  add_test(NAME web_report
           COMMAND ${KIT_WEB_REPORT_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_report_test.py ${KIT_WEB_SITE}
                   $<TARGET_FILE:kit-grade> ${CMAKE_BINARY_DIR}/test-tmp/web-report)
  set_tests_properties(web_report PROPERTIES ${KIT_WEB_FIXTURE} LABELS "web;slow" TIMEOUT 900
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes")
  # A student's OBJ scene (tests/web_obj_test.py): an .obj, its .mtl and a hand-made texture
  # dropped on the page (as files, a .zip and a folder) draw kit-render's frame of it, with the
  # texture's quarters where its layout puts them; without the texture or the .mtl they do not;
  # a malformed .obj is refused by name; a Draco-compressed glTF (tests/draco_gltf.mjs) draws
  # kit-render's frame of it.
  add_test(NAME web_obj
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_obj_test.py ${KIT_WEB_SITE} $<TARGET_FILE:kit-render>
                   ${CMAKE_BINARY_DIR}/test-tmp/web-obj)
  set_tests_properties(web_obj PROPERTIES ${KIT_WEB_FIXTURE} LABELS web TIMEOUT 300
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes")
  # A first visit over a 20 Mbit/s link (tests/web_first_visit_test.py): the bytes before the
  # first frame, from the kit's server and a plain one, without the grader's references, which
  # "Check my lab" fetches. The bytes are what it asserts; the time it prints is measured
  # again, alone and median of several, by its --runs (docs/performance.md).
  add_test(NAME web_first_visit
           COMMAND ${KIT_WEB_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/web_first_visit_test.py ${KIT_WEB_SITE}
                   ${CMAKE_BINARY_DIR}/test-tmp/web-first-visit)
  set_tests_properties(web_first_visit PROPERTIES ${KIT_WEB_FIXTURE} LABELS web TIMEOUT 300)
endif()
