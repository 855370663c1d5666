# `cmake --install`: the headers, static libraries and a qvrConfig.cmake of the parts another
# engine can use on their own — the controller (LIWC) and UCA with what they stand on — so that
# find_package(qvr) gives the targets qvr::core, qvr::foveation, qvr::workload, qvr::controller,
# qvr::compose and qvr::report. The parts that need the renderer, FFmpeg or the network stay
# inside this tree (their pkg-config dependencies have no CMake package to find again).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(QVR_INSTALL_PARTS core report foveation workload controller compose)
set(QVR_INSTALLED_TARGETS "")
foreach(part ${QVR_INSTALL_PARTS})
    if(TARGET qvr_${part})
        list(APPEND QVR_INSTALLED_TARGETS qvr_${part})
        install(DIRECTORY ${PROJECT_SOURCE_DIR}/${part}/include/
                DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
    endif()
endforeach()
install(TARGETS ${QVR_INSTALLED_TARGETS} EXPORT qvrTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT qvrTargets NAMESPACE qvr:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/qvr)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/qvrConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/qvrConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/qvr)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/qvrConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/qvrConfig.cmake ${PROJECT_BINARY_DIR}/qvrConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/qvr)
