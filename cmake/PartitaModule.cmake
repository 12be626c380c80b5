# partita_install_module(<target> <include dir>): install a module library and its headers.
function(partita_install_module target incdir)
  install(TARGETS ${target} EXPORT partitaTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(DIRECTORY ${incdir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
