# Install rules, the CMake package and the pkg-config file of the library (docs/library.md).
#   cmake --install BUILD --prefix P
# gives P/include/bdptref/*.h (public headers + the generated version.h), P/lib/libbdptref.a,
# P/lib/libbdptref.so.X.Y.Z (SONAME libbdptref.so.X), P/bin/bdptref, P/share/doc/bdptref/,
# P/share/bdptref/ (the conformance suite),
# P/lib/cmake/bdptref/ (find_package(bdptref 6.0)) and P/lib/pkgconfig/bdptref.pc.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(BDPTREF_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/bdptref)

install(DIRECTORY include/bdptref DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.h")
install(FILES ${CMAKE_BINARY_DIR}/generated/bdptref/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/bdptref)
install(TARGETS bdptref RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR})
# The conformance suite of `bdptref validate` (docs/validate.md): its scenes (the shipped scenes it
# uses and scenes/conformance/), the suite file and the references, with the layout the suite's
# relative paths expect; validate finds it at BIN/../share/bdptref/scenes/conformance/suite.json.
install(DIRECTORY scenes/ DESTINATION ${CMAKE_INSTALL_DATADIR}/bdptref/scenes
        FILES_MATCHING PATTERN "*.gltf" PATTERN "*.glb" PATTERN "*.hdr" PATTERN "suite.json" PATTERN "signatures.json")
install(DIRECTORY reference-images/conformance/ DESTINATION ${CMAKE_INSTALL_DATADIR}/bdptref/reference-images/conformance
        FILES_MATCHING PATTERN "*.exr")

# Two export sets: the shared library needs only its public dependencies (glm, TBB, nlohmann_json)
# at the consumer's build time; the static one also needs the private ones at link time.
install(TARGETS bdptref_lib EXPORT bdptrefStaticTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT bdptrefStaticTargets NAMESPACE bdptref:: DESTINATION ${BDPTREF_CMAKE_DIR})
if(TARGET bdptref_shared)
  install(TARGETS bdptref_shared EXPORT bdptrefTargets
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} NAMELINK_COMPONENT Unspecified
          INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT bdptrefTargets NAMESPACE bdptref:: DESTINATION ${BDPTREF_CMAKE_DIR})
endif()

configure_package_config_file(cmake/bdptrefConfig.cmake.in ${CMAKE_BINARY_DIR}/cmake/bdptrefConfig.cmake
                              INSTALL_DESTINATION ${BDPTREF_CMAKE_DIR})
# 2.x is compatible with 2.0 (semver: the major version changes on an API or ABI break).
write_basic_package_version_file(${CMAKE_BINARY_DIR}/cmake/bdptrefConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_BINARY_DIR}/cmake/bdptrefConfig.cmake ${CMAKE_BINARY_DIR}/cmake/bdptrefConfigVersion.cmake
        DESTINATION ${BDPTREF_CMAKE_DIR})

# pkg-config: the shared library by default, `pkg-config --static` adds what libbdptref.a needs.
file(RELATIVE_PATH BDPTREF_PC_TO_PREFIX /P/${CMAKE_INSTALL_LIBDIR}/pkgconfig /P)
configure_file(cmake/bdptref.pc.in ${CMAKE_BINARY_DIR}/cmake/bdptref.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/cmake/bdptref.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
