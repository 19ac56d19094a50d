# SPDX-License-Identifier: Apache-2.0
# Test pgo_same_packings (tests/CMakeLists.txt): runs PROG, the training
# program linked to the profile-optimised library, and fails unless it
# prints what the instrumented training run wrote to WANT.
file(READ "${WANT}" want)
execute_process(COMMAND ${PROG} RESULT_VARIABLE rc OUTPUT_VARIABLE got ERROR_VARIABLE err)
message("${got}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the training program failed (${rc}): ${err}")
endif()
if(NOT got STREQUAL want)
  message(FATAL_ERROR "the profile-optimised library packs differently; the training run gave:\n${want}")
endif()
string(REGEX MATCHALL "digest" lines "${got}")
list(LENGTH lines n)
if(n LESS 8)
  message(FATAL_ERROR "expected 8 packings, found ${n}")
endif()
message("same ${n} packings as the instrumented training run")
