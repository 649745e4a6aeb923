# libdeflate (Debian's libdeflate-dev), which compresses the PNG files that the program writes
# (OpenABLE/io/image_codec.cc). Debian 12's libdeflate 1.14 ships no CMake package (its
# pkg-config file only), so this module finds the header and the library and defines the
# imported target Libdeflate::Libdeflate. The build (CMakeLists.txt) and the installed package
# (OpenABLEConfig.cmake: the installed static libraries link it) both use it.
find_path(LIBDEFLATE_INCLUDE_DIR libdeflate.h)
find_library(LIBDEFLATE_LIBRARY NAMES deflate)
mark_as_advanced(LIBDEFLATE_INCLUDE_DIR LIBDEFLATE_LIBRARY)
if(NOT LIBDEFLATE_INCLUDE_DIR OR NOT LIBDEFLATE_LIBRARY)
  set(Libdeflate_FOUND FALSE)
  if(Libdeflate_FIND_REQUIRED)
    message(FATAL_ERROR "libdeflate not found (libdeflate.h and libdeflate.so): install the "
                        "Debian package libdeflate-dev (examples/setup.sh installs it)")
  endif()
  return()
endif()
set(Libdeflate_FOUND TRUE)
if(NOT TARGET Libdeflate::Libdeflate)
  add_library(Libdeflate::Libdeflate UNKNOWN IMPORTED)
  set_target_properties(Libdeflate::Libdeflate PROPERTIES
    IMPORTED_LOCATION "${LIBDEFLATE_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${LIBDEFLATE_INCLUDE_DIR}")
endif()
