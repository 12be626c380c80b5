# FindCHOLMOD: SuiteSparse's CHOLMOD (supernodal sparse Cholesky) without a CMake config file
# (Debian 12's libsuitesparse-dev, SuiteSparse 5.12, ships none).
#
# Result variables:
#   CHOLMOD_FOUND         true when cholmod.h and every library below were found
#   CHOLMOD_INCLUDE_DIRS  the folder of cholmod.h (Debian: /usr/include/suitesparse)
#   CHOLMOD_LIBRARIES     full paths: cholmod, then what it calls (amd camd colamd ccolamd
#                         suitesparseconfig; metis when present, for CHOLMOD's METIS ordering)
#   CHOLMOD_VERSION       from CHOLMOD_MAIN_VERSION.CHOLMOD_SUB_VERSION.CHOLMOD_SUBSUB_VERSION
# and the imported target CHOLMOD::CHOLMOD.
#
# Full paths rather than the imported target are what an installed static partita library
# records, so that find_package(partita) needs no FindCHOLMOD of its own.
# Hints: CHOLMOD_ROOT (CMake's <Package>_ROOT), or CMAKE_PREFIX_PATH.

find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse include/suitesparse
          DOC "folder of cholmod.h")
find_library(CHOLMOD_LIBRARY cholmod DOC "libcholmod")
set(_cholmod_deps amd camd colamd ccolamd suitesparseconfig)
set(_cholmod_dep_vars)
foreach(_dep IN LISTS _cholmod_deps)
  string(TOUPPER ${_dep} _DEP)
  find_library(CHOLMOD_${_DEP}_LIBRARY ${_dep} DOC "lib${_dep} (for CHOLMOD)")
  list(APPEND _cholmod_dep_vars CHOLMOD_${_DEP}_LIBRARY)
endforeach()
# METIS: optional (CHOLMOD built without its Partition module does not need it). Debian's
# libmetis5 ships only libmetis.so.5 unless libmetis-dev is installed: look for both names.
find_library(CHOLMOD_METIS_LIBRARY NAMES metis libmetis.so.5 DOC "libmetis (CHOLMOD's METIS ordering)")

# the version macros are in cholmod_core.h (SuiteSparse 5) or cholmod.h (SuiteSparse 7)
foreach(_header cholmod_core.h cholmod.h)
  if(CHOLMOD_INCLUDE_DIR AND NOT CHOLMOD_VERSION AND EXISTS "${CHOLMOD_INCLUDE_DIR}/${_header}")
    file(STRINGS "${CHOLMOD_INCLUDE_DIR}/${_header}" _cholmod_version_lines
         REGEX "#define[ \t]+CHOLMOD_(MAIN|SUB|SUBSUB)_VERSION[ \t]+[0-9]+")
    if(_cholmod_version_lines)
      foreach(_part MAIN SUB SUBSUB)
        string(REGEX REPLACE ".*#define[ \t]+CHOLMOD_${_part}_VERSION[ \t]+([0-9]+).*" "\\1"
               _cholmod_${_part} "${_cholmod_version_lines}")
      endforeach()
      set(CHOLMOD_VERSION "${_cholmod_MAIN}.${_cholmod_SUB}.${_cholmod_SUBSUB}")
    endif()
  endif()
endforeach()

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(CHOLMOD
  REQUIRED_VARS CHOLMOD_LIBRARY CHOLMOD_INCLUDE_DIR ${_cholmod_dep_vars}
  VERSION_VAR CHOLMOD_VERSION)

if(CHOLMOD_FOUND)
  set(CHOLMOD_INCLUDE_DIRS ${CHOLMOD_INCLUDE_DIR})
  set(CHOLMOD_LIBRARIES ${CHOLMOD_LIBRARY})
  foreach(_var IN LISTS _cholmod_dep_vars)
    list(APPEND CHOLMOD_LIBRARIES ${${_var}})
  endforeach()
  if(CHOLMOD_METIS_LIBRARY)
    list(APPEND CHOLMOD_LIBRARIES ${CHOLMOD_METIS_LIBRARY})
  endif()
  if(NOT TARGET CHOLMOD::CHOLMOD)
    add_library(CHOLMOD::CHOLMOD INTERFACE IMPORTED)
    set_target_properties(CHOLMOD::CHOLMOD PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIRS}"
      INTERFACE_LINK_LIBRARIES "${CHOLMOD_LIBRARIES}")
  endif()
endif()
mark_as_advanced(CHOLMOD_INCLUDE_DIR CHOLMOD_LIBRARY CHOLMOD_METIS_LIBRARY ${_cholmod_dep_vars})
