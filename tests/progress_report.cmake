# ./kit progress-report end to end (tests/progress_report_test.py): the PDF of the
# starters' labs 1-2 with a notes file (sections, images on a lab page, the notes'
# text), a lab that does not compile, no references and no notes (a student
# copy), an unwritable output, and no words over words on any page (also in a
# report of every lab with its solution, each lab's score). Uses poppler-utils (pdfinfo,
# pdftoppm, pdftotext) and Debian's python3 with WeasyPrint, pystache, markdown-it-py and
# matplotlib (it reads page images). Included from tests/CMakeLists.txt.
if(TARGET kit-grade AND TARGET kit-render)
  find_program(KIT_REPORT_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
  find_program(KIT_REPORT_PYTHON NAMES python3 REQUIRED)
  add_test(NAME progress_report
           COMMAND ${KIT_REPORT_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/progress_report_test.py
                   $<TARGET_FILE:kit-grade> $<TARGET_FILE:kit-render> ${CMAKE_BINARY_DIR}/test-tmp/progress_report)
  set_tests_properties(progress_report PROPERTIES LABELS slow
    ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
    TIMEOUT 600
    # It took 3 min on 2 cores shared with other builds (load average 20): started first, as
    # kit_test's SLOW suites are.
    COST 100
    FIXTURES_REQUIRED kit_grade_seed)
endif()
