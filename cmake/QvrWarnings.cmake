# Per-target warnings (STYLE.md §10): -Wall -Wextra -Wshadow everywhere, -Werror when QVR_WERROR.
function(qvr_warnings target)
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wshadow -Wnon-virtual-dtor
                                             -Wold-style-cast -Wcast-align -Woverloaded-virtual
                                             -Wimplicit-fallthrough)
    if(QVR_WERROR)
        target_compile_options(${target} PRIVATE -Werror)
    endif()
endfunction()

# qvr_library(<part> SOURCES ... DEPS ...): the library qvr_<part> with include/ public.
function(qvr_library part)
    cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
    add_library(qvr_${part} ${ARG_SOURCES})
    add_library(qvr::${part} ALIAS qvr_${part})
    target_include_directories(qvr_${part} PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
                                                  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    # Installed as qvr::<part> (cmake/QvrInstall.cmake) when the part is in QVR_INSTALL_PARTS.
    set_target_properties(qvr_${part} PROPERTIES EXPORT_NAME ${part})
    target_link_libraries(qvr_${part} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    qvr_warnings(qvr_${part})
endfunction()
