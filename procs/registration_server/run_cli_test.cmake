# Runs `EXE mean --input INPUT ARGS...` and checks the exit code and a regex on stdout / stderr.
# cmake -DEXE=.. -DINPUT=.. -DEXPECT_CODE=n [-DARGS=a,b] [-DEXPECT_STDOUT=re] [-DEXPECT_STDERR=re] -P run_cli_test.cmake
string(REPLACE "," ";" ARGS "${ARGS}")  # commas: a ';' would split the add_test() argument
execute_process(COMMAND ${EXE} mean --input ${INPUT} ${ARGS}
  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "exit ${code}\nstdout: ${out}\nstderr: ${err}")
if(NOT code EQUAL EXPECT_CODE)
  message(FATAL_ERROR "expected exit code ${EXPECT_CODE}, got ${code}")
endif()
if(DEFINED EXPECT_STDOUT AND NOT out MATCHES "${EXPECT_STDOUT}")
  message(FATAL_ERROR "stdout does not match '${EXPECT_STDOUT}'")
endif()
if(DEFINED EXPECT_STDERR AND NOT err MATCHES "${EXPECT_STDERR}")
  message(FATAL_ERROR "stderr does not match '${EXPECT_STDERR}'")
endif()
