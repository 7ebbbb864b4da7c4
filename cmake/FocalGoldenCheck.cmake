# The test focal_add_golden_test adds (cmake/FocalGolden.cmake): run as
#   cmake -DCONFIG=<generated settings> -P FocalGoldenCheck.cmake
# Renders, hashes, compares with the stored golden (or, with FOCAL_UPDATE_GOLDENS=1, stores it).
cmake_minimum_required(VERSION 3.21)
include("${CONFIG}")

set(exr "${WORK_DIR}/${NAME}.exr")
set(png "${WORK_DIR}/${NAME}.png")
set(diff "${WORK_DIR}/${NAME}_diff.png")
set(golden_hash "${GOLDEN_DIR}/${NAME}.hash")
set(golden_png "${GOLDEN_DIR}/${NAME}.png")
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

execute_process(COMMAND "${FOCAL}" render "${SCENE}" -o "${exr}" -o "${png}" --no-progress
                        ${RENDER_OPTIONS}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "golden ${NAME}: focal render ${SCENE} failed (exit ${code}):\n${err}")
endif()
execute_process(COMMAND "${FOCAL}" hash "${exr}"
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "golden ${NAME}: focal hash failed (exit ${code}):\n${err}")
endif()
string(SUBSTRING "${out}" 0 16 actual)

if(DEFINED ENV{FOCAL_UPDATE_GOLDENS} AND NOT "$ENV{FOCAL_UPDATE_GOLDENS}" STREQUAL ""
   AND NOT "$ENV{FOCAL_UPDATE_GOLDENS}" STREQUAL "0")
  file(MAKE_DIRECTORY "${GOLDEN_DIR}")
  file(WRITE "${golden_hash}" "${actual}\n")
  file(COPY_FILE "${png}" "${golden_png}")
  message(STATUS "golden ${NAME}: stored ${actual} in ${golden_hash} and ${golden_png}")
  return()
endif()

set(update "if the change is intended, rerun with FOCAL_UPDATE_GOLDENS=1 and commit ${GOLDEN_DIR}")
if(NOT EXISTS "${golden_hash}")
  message(FATAL_ERROR "golden ${NAME}: no ${golden_hash} (render: ${png}); ${update}")
endif()
file(STRINGS "${golden_hash}" expected LIMIT_COUNT 1)
string(STRIP "${expected}" expected)
if(actual STREQUAL expected)
  return()
endif()

set(report "golden ${NAME}: hash ${actual}, expected ${expected}\n  actual:   ${png}\n")
if(EXISTS "${golden_png}")
  execute_process(COMMAND "${FOCAL}" compare "${golden_png}" "${png}" --max-differing 0
                          --diff "${diff}"
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(APPEND report "  expected: ${golden_png}\n")
  if(EXISTS "${diff}")
    string(APPEND report "  diff:     ${diff}\n")
  else()
    string(APPEND report "  (the 8-bit images are equal: the change is below 8-bit precision)\n")
  endif()
  string(APPEND report "${out}${err}")
else()
  string(APPEND report "  no golden image ${golden_png}\n")
endif()
# NOTICE prints the report as it is; FATAL_ERROR would re-flow the compare table.
message(NOTICE "${report}")
message(FATAL_ERROR "golden ${NAME} does not match (above); ${update}")
