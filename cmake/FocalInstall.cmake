# Install rules (docs/embedding.md): headers, the static libraries, the CMake package
# (find_package(focal): focal::focal, focal::raster, focal::dof, focal::scenes) and focal.pc;
# with the apps also the focal program (focal::focal-cli) and focal_add_golden_test.
include(CMakePackageConfigHelpers)

set(FOCAL_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/focal" CACHE STRING
    "Where the CMake package files are installed, relative to the prefix")

install(DIRECTORY raster/include/ dof/include/ scenes/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT focal_development)
install(TARGETS focal_raster focal_dof focal_scenes focal_library EXPORT focalTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT focal_development)
install(EXPORT focalTargets NAMESPACE focal:: DESTINATION ${FOCAL_INSTALL_CMAKEDIR}
        COMPONENT focal_development)

if(FOCAL_BUILD_APPS)
  install(TARGETS focal EXPORT focalCliTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
          COMPONENT focal_cli)
  install(EXPORT focalCliTargets NAMESPACE focal:: DESTINATION ${FOCAL_INSTALL_CMAKEDIR}
          COMPONENT focal_cli)
  install(FILES cmake/FocalGolden.cmake cmake/FocalGoldenCheck.cmake
          DESTINATION ${FOCAL_INSTALL_CMAKEDIR} COMPONENT focal_cli)
endif()

# FOCAL_PACKAGE_CLI tells focalConfig.cmake whether this install holds the program (a fixed
# answer, not a test for a file that an older install may have left behind).
set(FOCAL_PACKAGE_CLI ${FOCAL_BUILD_APPS})
configure_package_config_file(cmake/focalConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/focalConfig.cmake
                              INSTALL_DESTINATION ${FOCAL_INSTALL_CMAKEDIR})
# 0.x: a new minor version may change the API.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/focalConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/focalConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/focalConfigVersion.cmake
        DESTINATION ${FOCAL_INSTALL_CMAKEDIR} COMPONENT focal_development)

# pkg-config: the prefix is found from the .pc file's own place, so the package still works when
# installed with `cmake --install --prefix` somewhere else than CMAKE_INSTALL_PREFIX.
# (Absolute install directories pin the prefix instead.)
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(FOCAL_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  file(RELATIVE_PATH _focal_pc_to_prefix "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
  string(REGEX REPLACE "/$" "" _focal_pc_to_prefix "${_focal_pc_to_prefix}")
  set(FOCAL_PC_PREFIX "\${pcfiledir}/${_focal_pc_to_prefix}")
endif()
cmake_path(ABSOLUTE_PATH CMAKE_INSTALL_LIBDIR BASE_DIRECTORY "\${prefix}"
           OUTPUT_VARIABLE FOCAL_PC_LIBDIR)
cmake_path(ABSOLUTE_PATH CMAKE_INSTALL_INCLUDEDIR BASE_DIRECTORY "\${prefix}"
           OUTPUT_VARIABLE FOCAL_PC_INCLUDEDIR)
if(FOCAL_NO_SIMD)
  set(FOCAL_PC_CFLAGS "-DFOCAL_NO_SIMD")
endif()
configure_file(cmake/focal.pc.in ${CMAKE_CURRENT_BINARY_DIR}/focal.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/focal.pc
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT focal_development)
