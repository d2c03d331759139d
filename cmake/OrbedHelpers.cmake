# orbed_add_gtest(NAME name SRCS a.cc b.cc LIBS lib1 lib2 [LABELS l1 l2] [TIMEOUT sec])
#   One gtest executable, registered with ctest as one test (names are per executable, so ctest
#   output stays short and each library's test is one line). A unit test: labelled `quick`
#   (`scripts/orbed test --quick` runs the quick ones), besides any LABELS given; the integration,
#   Xvfb, Chromium and multi-process tests are registered elsewhere and are not quick.
function(orbed_add_gtest)
  cmake_parse_arguments(T "" "NAME;TIMEOUT" "SRCS;LIBS;LABELS" ${ARGN})
  add_executable(${T_NAME} ${T_SRCS})
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest_main)
  set_target_properties(${T_NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_test(NAME ${T_NAME} COMMAND ${T_NAME})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  set_tests_properties(${T_NAME} PROPERTIES TIMEOUT ${T_TIMEOUT}
    ENVIRONMENT "ORBED_SOURCE_DIR=${CMAKE_SOURCE_DIR};ORBED_BIN_DIR=${CMAKE_BINARY_DIR}/bin")
  set_tests_properties(${T_NAME} PROPERTIES LABELS "quick;${T_LABELS}")
  orbed_sanitizer_test_properties(${T_NAME})
endfunction()

# orbed_add_process(NAME orbed-foo MAIN main.cc LIBS foo_lib)
#   A thin main; also registered as three smoke tests: `--help` exits 0; an unknown flag exits 2,
#   every orbed program's usage error (base/command_line.h); `--version` prints "orbed <version>
#   (commit <hex>...)". Checked by the shell, not by WILL_FAIL, which would also turn a sanitizer
#   report in the output (a failure) into a pass.
function(orbed_add_process)
  cmake_parse_arguments(P "" "NAME;MAIN" "LIBS" ${ARGN})
  add_executable(${P_NAME} ${P_MAIN})
  target_link_libraries(${P_NAME} PRIVATE ${P_LIBS})
  add_test(NAME ${P_NAME}.help COMMAND ${P_NAME} --help)
  add_test(NAME ${P_NAME}.unknown_flag
    COMMAND sh -c "\"$0\" --no-such-flag-xyz; test $? -eq 2" $<TARGET_FILE:${P_NAME}>)
  add_test(NAME ${P_NAME}.version COMMAND ${P_NAME} --version)
  set_tests_properties(${P_NAME}.version PROPERTIES
    PASS_REGULAR_EXPRESSION "^orbed ${PROJECT_VERSION} \\(commit ([0-9a-f]+|unknown)(, modified)?\\)")
  set_tests_properties(${P_NAME}.help ${P_NAME}.unknown_flag ${P_NAME}.version PROPERTIES TIMEOUT 20 LABELS smoke)
  orbed_sanitizer_test_properties(${P_NAME}.help ${P_NAME}.unknown_flag ${P_NAME}.version)
endfunction()

# orbed_sanitizer_test_properties(TEST...)
#   In a sanitizer build (cmake/OrbedSanitizers.cmake): the runtime options into the tests'
#   environment (appended: call it after setting ENVIRONMENT), and a sanitizer report anywhere in
#   their output a failure. Every test that runs an orbed program calls it. Nothing otherwise.
function(orbed_sanitizer_test_properties)
  if(ORBED_SANITIZE)
    set_property(TEST ${ARGN} APPEND PROPERTY ENVIRONMENT ${ORBED_SANITIZER_ENV})
    set_property(TEST ${ARGN} PROPERTY FAIL_REGULAR_EXPRESSION ${ORBED_SANITIZER_REPORT})
  endif()
endfunction()
