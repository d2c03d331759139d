# cmake -DSOURCE_DIR=... -DOUTPUT=... -P OrbedBuildCommit.cmake
# Writes OUTPUT (a header: ORBED_BUILD_COMMIT, the 12-hex commit of SOURCE_DIR or "unknown";
# ORBED_BUILD_MODIFIED, 1 when tracked files differ from it) only when its text changes, so a build
# recompiles base/command_line.cc, and relinks, only after a commit or a change of the modified bit.
execute_process(COMMAND git -C "${SOURCE_DIR}" rev-parse --short=12 HEAD
                OUTPUT_VARIABLE commit RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
set(modified 0)
if(NOT rc EQUAL 0 OR commit STREQUAL "")
  set(commit unknown)
else()
  execute_process(COMMAND git -C "${SOURCE_DIR}" diff --quiet HEAD -- RESULT_VARIABLE diff_rc ERROR_QUIET)
  if(NOT diff_rc EQUAL 0)
    set(modified 1)
  endif()
endif()
set(text "#pragma once\n#define ORBED_BUILD_COMMIT \"${commit}\"\n#define ORBED_BUILD_MODIFIED ${modified}\n")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUTPUT}" "${text}")
endif()
