# Test of cmake/FocalGoldenCheck.cmake (run by examples/golden/CMakeLists.txt): the accum example
# checked against a golden folder holding a wrong hash and the pinhole example's image must fail,
# name both hashes and write a diff image; with FOCAL_UPDATE_GOLDENS=1 it must store the hash
# that the real golden folder holds.
cmake_minimum_required(VERSION 3.21)
include("${CONFIG}") # NAME, GOLDEN_DIR, ... of the accum example
set(real_hash_file "${GOLDEN_DIR}/${NAME}.hash")
file(REMOVE_RECURSE "${SCRATCH}")
file(MAKE_DIRECTORY "${SCRATCH}/goldens")

# A copy of the example's settings that reads and writes goldens in the scratch folder.
file(READ "${CONFIG}" settings)
string(APPEND settings "set(GOLDEN_DIR [==[${SCRATCH}/goldens]==])\n"
                       "set(WORK_DIR [==[${SCRATCH}/work]==])\n")
file(WRITE "${SCRATCH}/config.cmake" "${settings}")
function(run_check update out_code out_text)
  set(ENV{FOCAL_UPDATE_GOLDENS} "${update}")
  execute_process(COMMAND "${CMAKE_COMMAND}" -DCONFIG=${SCRATCH}/config.cmake -P "${CHECK}"
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(${out_code} "${code}" PARENT_SCOPE)
  set(${out_text} "${out}${err}" PARENT_SCOPE)
endfunction()

# 1. A wrong golden fails, naming both hashes, and writes the diff.
file(WRITE "${SCRATCH}/goldens/${NAME}.hash" "0123456789abcdef\n")
file(COPY_FILE "${WRONG_PNG}" "${SCRATCH}/goldens/${NAME}.png")
run_check(0 code text)
if(code EQUAL 0)
  message(FATAL_ERROR "the check passed against a wrong golden:\n${text}")
endif()
if(NOT text MATCHES "expected 0123456789abcdef" OR NOT EXISTS "${SCRATCH}/work/${NAME}_diff.png"
   OR NOT text MATCHES "differing_pixels")
  message(FATAL_ERROR "the failure does not name the expected hash or wrote no diff:\n${text}")
endif()

# 2. No golden at all fails and says how to create it.
file(REMOVE "${SCRATCH}/goldens/${NAME}.hash")
run_check(0 code text)
if(code EQUAL 0 OR NOT text MATCHES "FOCAL_UPDATE_GOLDENS=1")
  message(FATAL_ERROR "a missing golden did not fail with the update command:\n${text}")
endif()

# 3. The update switch stores the real golden's hash, and then the check passes.
run_check(1 code text)
file(READ "${SCRATCH}/goldens/${NAME}.hash" stored)
file(READ "${real_hash_file}" real)
if(NOT code EQUAL 0 OR NOT stored STREQUAL real)
  message(FATAL_ERROR "update stored '${stored}', the golden holds '${real}':\n${text}")
endif()
run_check(0 code text)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "the check failed right after an update:\n${text}")
endif()
