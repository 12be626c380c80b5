# partita_add_module(<name> [SOURCES_GLOB <pattern>] [PUBLIC <deps...>] [PRIVATE <deps...>]
#                    [PCH <headers...>])
# One library target per module: partita_<name> with the alias partita::<name>, headers in the
# module's include/, sources found by the glob in src/ and its subfolders (default src/*.cpp), C++20, the project warnings
# linked PRIVATE (build interface only), installed and exported for find_package(partita).
# PCH: headers most of the module's sources include (the standard library, Eigen, the module's
# own base headers), precompiled once for the module (PARTITA_PCH, on by default; a source with
# compile options of its own must set SKIP_PRECOMPILE_HEADERS). It changes no generated code.
function(partita_add_module name)
  cmake_parse_arguments(M "" "SOURCES_GLOB" "PUBLIC;PRIVATE;PCH" ${ARGN})
  if(NOT M_SOURCES_GLOB)
    set(M_SOURCES_GLOB src/*.cpp)
  endif()
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${M_SOURCES_GLOB})
  if(NOT sources)  # a module with no sources yet still needs its library target
    file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/empty.cpp "")
    set(sources ${CMAKE_CURRENT_BINARY_DIR}/empty.cpp)
  endif()
  set(target partita_${name})
  add_library(${target} ${sources})
  add_library(partita::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME ${target})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_link_libraries(${target} PUBLIC ${M_PUBLIC} PRIVATE ${M_PRIVATE} $<BUILD_INTERFACE:partita::warnings>)
  if(PARTITA_PCH AND M_PCH)
    target_precompile_headers(${target} PRIVATE ${M_PCH})
  endif()
  install(TARGETS ${target} EXPORT partitaTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
