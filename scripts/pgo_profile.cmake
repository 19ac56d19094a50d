# SPDX-License-Identifier: Apache-2.0
# Run by the build (VP_PGO in CMakeLists.txt): removes the profile (.gcda)
# of an earlier run, runs the instrumented training program TRAIN, checks
# that it wrote the profiles the real library's build reads (PGO/rsa.c.gcda
# and PGO/rsa_split.c.gcda, named after the -dumpbase both compiles of each
# get), keeps its report
# in PGO/train.txt, and touches STAMP.
file(GLOB old "${PGO}/*.gcda")
if(old)
  file(REMOVE ${old})
endif()
file(MAKE_DIRECTORY "${PGO}")
execute_process(COMMAND ${TRAIN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "PGO training run failed (${rc}):\n${out}\n${err}\n"
    "Configure with -DVP_PGO=OFF to build without profile feedback.")
endif()
# its report, for the test pgo_same_packings
file(WRITE "${PGO}/train.txt" "${out}")
file(GLOB profiles "${PGO}/*.gcda")
if(NOT profiles)
  message(FATAL_ERROR "PGO training run wrote no profile under ${PGO}")
endif()
message(STATUS "PGO: training done, profile ${profiles}")
file(TOUCH "${STAMP}")
