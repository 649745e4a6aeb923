# What `cmake --install build [--prefix P]` puts where (docs/install.md):
#
#   include/openable/{OpenABLE,descriptors,matching,config}/...h   every header, paths kept
#   lib/libOpenABLE.a, lib/libopenable_*.a                          the static libraries
#   lib/openable/libopenable_{oiio,video,gui,codecs,...}.so          the run-time modules
#   lib/cmake/OpenABLE/OpenABLE{Config,ConfigVersion,Targets*}.cmake, FindLibdeflate.cmake
#   bin/Test_OpenABLE, bin/openable_evaluate, bin/openable_snaps
#
# (lib/ stands for CMAKE_INSTALL_LIBDIR.) Tests, benchmarks and fuzzers are not installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(OPENABLE_INSTALL_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}/openable")
set(OPENABLE_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/OpenABLE")
set(OPENABLE_INSTALL_MODULEDIR "${CMAKE_INSTALL_LIBDIR}/openable")

# The libraries behind OpenABLE::OpenABLE, openable_snaps_core and openable_odometry, with
# every library they link PRIVATE-ly: a static library needs those at the consumer's link
# ($<LINK_ONLY:...> in the export), so all of them are in the export set.
set(OPENABLE_EXPORTED_LIBRARIES
  openable_base openable_io openable_descriptors openable_matching openable_config
  openable_evaluation openable_stereo openable_image openable_describe openable_cluster
  openable_run openable_reports openable_tuning openable_outputs openable_app OpenABLE
  openable_snaps_core openable_odometry openable_verification)
install(TARGETS ${OPENABLE_EXPORTED_LIBRARIES}
  EXPORT OpenABLETargets
  ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
  INCLUDES DESTINATION "${OPENABLE_INSTALL_INCLUDEDIR}")
install(EXPORT OpenABLETargets
  NAMESPACE OpenABLE::
  DESTINATION "${OPENABLE_INSTALL_CMAKEDIR}")

# Headers: every .h of the four source folders under include/openable/, so that
# <OpenABLE/OpenABLE.h> and its own includes ("descriptors/descriptor.h", ...) resolve from
# that one include folder, as they do from the repository root in the build.
foreach(folder OpenABLE descriptors matching config)
  file(GLOB_RECURSE headers CONFIGURE_DEPENDS RELATIVE "${PROJECT_SOURCE_DIR}"
       "${PROJECT_SOURCE_DIR}/${folder}/*.h")
  foreach(header IN LISTS headers)
    get_filename_component(subfolder "${header}" DIRECTORY)
    install(FILES "${PROJECT_SOURCE_DIR}/${header}"
            DESTINATION "${OPENABLE_INSTALL_INCLUDEDIR}/${subfolder}")
  endforeach()
endforeach()

# Run-time modules (OpenABLE/base/module_loader.h), where module_loader.cc looks for them.
install(TARGETS openable_oiio openable_video openable_gui openable_codecs openable_dnn
  LIBRARY DESTINATION "${OPENABLE_INSTALL_MODULEDIR}")
if(TARGET openable_mpi)  # runs over several processes (docs/distributed.md)
  install(TARGETS openable_mpi LIBRARY DESTINATION "${OPENABLE_INSTALL_MODULEDIR}")
endif()
if(TARGET openable_faiss)
  install(TARGETS openable_faiss LIBRARY DESTINATION "${OPENABLE_INSTALL_MODULEDIR}")
endif()
if(TARGET openable_rosbag)  # ROS 1 bags (Frame_mode 3)
  install(TARGETS openable_rosbag LIBRARY DESTINATION "${OPENABLE_INSTALL_MODULEDIR}")
endif()

# The command-line programs of examples/.
install(TARGETS Test_OpenABLE openable_evaluate openable_snaps openable_sweep openable_map
  RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")

# find_package(OpenABLE): the config file finds the dependencies, then loads the targets.
configure_package_config_file(
  "${CMAKE_CURRENT_LIST_DIR}/OpenABLEConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/OpenABLEConfig.cmake"
  INSTALL_DESTINATION "${OPENABLE_INSTALL_CMAKEDIR}"
  PATH_VARS OPENABLE_INSTALL_MODULEDIR)
write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/OpenABLEConfigVersion.cmake"
  VERSION "${PROJECT_VERSION}"
  COMPATIBILITY SameMajorVersion)
install(FILES "${PROJECT_BINARY_DIR}/OpenABLEConfig.cmake"
              "${PROJECT_BINARY_DIR}/OpenABLEConfigVersion.cmake"
              "${CMAKE_CURRENT_LIST_DIR}/FindLibdeflate.cmake"
        DESTINATION "${OPENABLE_INSTALL_CMAKEDIR}")
