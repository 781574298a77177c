# The grader's references (tools/grade/references/) agree with its check list and
# with this machine's renders of every solution the kit holds: all of them in the
# instructor's kit, the released ones in a student copy. A student's self-check
# (./kit grade labs) is only as good as this.
#
# It is also the fixture kit_grade_seed: --check-references writes the grader's shader
# cache seed ($XDG_CACHE_HOME/kit-grade/mesa-shader-cache), which every grading run
# copies so that only a submission's own shaders are compiled. On a fresh machine
# (CI) there is none: the tests that run kit-grade (FIXTURES_REQUIRED kit_grade_seed,
# kit_test's GRADES) start after it, not beside it with every solution's shader
# compiled again in each of their runs.
add_test(NAME grade_references_reproduce COMMAND $<TARGET_FILE:kit-grade> --check-references)
set_tests_properties(grade_references_reproduce PROPERTIES
  ENVIRONMENT "KIT_SCENE_DIR=${CMAKE_BINARY_DIR}/scenes"
  FIXTURES_SETUP kit_grade_seed
  TIMEOUT 300)
# The probe shaders (shaders/probe_*.frag) are the labs' contract (tools/grade/lab_functions.json)
# as tools/grade/lab_contract.py writes them, with a witness (tests/lab_contract_test.py).
find_program(KIT_CONTRACT_PYTHON NAMES python3 REQUIRED)
add_test(NAME lab_contract_shaders
         COMMAND ${KIT_CONTRACT_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/lab_contract_test.py
                 ${CMAKE_BINARY_DIR}/test-tmp/lab_contract)
