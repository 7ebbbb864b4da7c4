# focal_add_golden_test(NAME SCENE [GOLDEN_DIR DIR] [LABELS L...] [--render-option VALUE ...])
#
# Pins a render of SCENE (a .gltf/.glb path, relative to the calling CMakeLists.txt's folder, or
# builtin:NAME) bit-exactly, as a CTest test called NAME (docs/golden-cmake.md):
#   1. `focal render SCENE -o NAME.exr -o NAME.png [render options]` into
#      <build>/focal-golden/NAME/ (relative paths in the options resolve against the source
#      folder, the test's working directory);
#   2. `focal hash NAME.exr` (a hash of the decoded float pixels, docs/hash.md), compared with the
#      16 hex digits stored in DIR/NAME.hash;
#   3. on a mismatch, `focal compare DIR/NAME.png NAME.png --max-differing 0 --diff NAME_diff.png`
#      writes a false-colour diff, and the test fails naming the hashes and the files.
# With FOCAL_UPDATE_GOLDENS=1 in the environment the test writes DIR/NAME.hash and DIR/NAME.png
# instead (review and commit them). DIR defaults to goldens/ beside the calling CMakeLists.txt;
# LABELS default to "golden".
#
# The focal executable: FOCAL_EXECUTABLE if set, else the target focal::focal-cli: in focal's
# own tree an alias of the `focal` target, in a project that did find_package(focal) the
# installed program (this file is then lib/cmake/focal/FocalGolden.cmake, included by
# focalConfig.cmake).
include_guard(GLOBAL)

set(_focal_golden_check "${CMAKE_CURRENT_LIST_DIR}/FocalGoldenCheck.cmake")

function(focal_add_golden_test name scene)
  cmake_parse_arguments(PARSE_ARGV 2 arg "" "GOLDEN_DIR" "LABELS")
  if(NOT arg_GOLDEN_DIR)
    set(arg_GOLDEN_DIR "${CMAKE_CURRENT_SOURCE_DIR}/goldens")
  endif()
  cmake_path(ABSOLUTE_PATH arg_GOLDEN_DIR BASE_DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}")
  if(NOT arg_LABELS)
    set(arg_LABELS golden)
  endif()
  if(NOT scene MATCHES "^builtin:")
    cmake_path(ABSOLUTE_PATH scene BASE_DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}")
  endif()
  if(FOCAL_EXECUTABLE)
    set(focal "${FOCAL_EXECUTABLE}")
  elseif(TARGET focal::focal-cli)
    set(focal "$<TARGET_FILE:focal::focal-cli>")
  else()
    message(FATAL_ERROR "focal_add_golden_test(${name}): no focal program: find_package(focal) "
                        "from an install built with FOCAL_BUILD_APPS=ON, or set FOCAL_EXECUTABLE")
  endif()

  # The render options go through a generated file, one bracket-quoted argument each, so that no
  # argument is split at a ';' or loses its quoting on the way to the script.
  set(options "")
  foreach(a IN LISTS arg_UNPARSED_ARGUMENTS)
    string(APPEND options " [==[${a}]==]")
  endforeach()
  set(config "${CMAKE_CURRENT_BINARY_DIR}/focal-golden/${name}.cmake")
  file(GENERATE OUTPUT "${config}" CONTENT
"set(FOCAL [==[${focal}]==])
set(NAME [==[${name}]==])
set(SCENE [==[${scene}]==])
set(GOLDEN_DIR [==[${arg_GOLDEN_DIR}]==])
set(WORK_DIR [==[${CMAKE_CURRENT_BINARY_DIR}/focal-golden/${name}]==])
set(RENDER_OPTIONS${options})
")
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -DCONFIG=${config} -P ${_focal_golden_check}
           WORKING_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR})
  set_tests_properties(${name} PROPERTIES LABELS "${arg_LABELS}")
endfunction()
