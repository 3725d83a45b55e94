# Installs libg2p as a CMake package (find_package(g2p)) and a pkg-config module.
include(CMakePackageConfigHelpers)

set(G2P_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/g2p)

# Public headers: the hand-written ones plus the generated version.h.
# complete_cgal.h belongs to the optional component g2p::cgal (below).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/libg2p/include/g2p
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.h" PATTERN "complete_cgal.h" EXCLUDE)
install(FILES ${PROJECT_BINARY_DIR}/libg2p/generated/include/g2p/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/g2p)
install(FILES ${PROJECT_SOURCE_DIR}/libg2p/data/materials.json ${PROJECT_SOURCE_DIR}/libg2p/data/refine_prompt.txt
              ${PROJECT_SOURCE_DIR}/libg2p/data/objects.json ${PROJECT_SOURCE_DIR}/libg2p/data/objects.schema.json
              ${PROJECT_SOURCE_DIR}/libg2p/data/objects.md ${PROJECT_SOURCE_DIR}/libg2p/data/wordnet_kinds.json
        DESTINATION ${CMAKE_INSTALL_DATADIR}/g2p)
if(EXISTS ${PROJECT_SOURCE_DIR}/libg2p/data/models)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/libg2p/data/models DESTINATION ${CMAKE_INSTALL_DATADIR}/g2p)
endif()

install(TARGETS g2p EXPORT g2pTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime NAMELINK_COMPONENT development
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

# The optional GPL component, in the same export set: find_package(g2p
# COMPONENTS cgal) then gives g2p::cgal.
if(TARGET g2p_cgal)
  install(TARGETS g2p_cgal EXPORT g2pTargets
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime NAMELINK_COMPONENT development
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(FILES ${PROJECT_SOURCE_DIR}/libg2p/include/g2p/complete_cgal.h
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/g2p)
endif()

install(EXPORT g2pTargets NAMESPACE g2p:: DESTINATION ${G2P_INSTALL_CMAKEDIR})

# Static builds make the private dependencies part of the link interface.
if(BUILD_SHARED_LIBS)
  set(G2P_STATIC_DEPENDENCIES "")
else()
  set(G2P_STATIC_DEPENDENCIES
      "find_dependency(assimp)\nfind_dependency(draco)\nfind_dependency(meshoptimizer)\nfind_dependency(embree 3)\nfind_dependency(TBB)\nfind_dependency(CURL)\nfind_dependency(OpenCV COMPONENTS core imgproc dnn ml)\nfind_dependency(PNG)\nfind_dependency(JPEG)\nfind_dependency(TIFF)\nfind_dependency(nlohmann_json)\nfind_dependency(Threads)\nfind_dependency(urdfdom)\nfind_dependency(Qhull)")
  if(G2P_WITH_MUJOCO)
    string(APPEND G2P_STATIC_DEPENDENCIES "\nfind_dependency(mujoco 2.2)")
  endif()
  if(TARGET g2p_cgal)
    string(APPEND G2P_STATIC_DEPENDENCIES "\nfind_dependency(CGAL 5.5)")
  endif()
endif()

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/g2pConfig.cmake.in
  ${PROJECT_BINARY_DIR}/g2pConfig.cmake INSTALL_DESTINATION ${G2P_INSTALL_CMAKEDIR}
  PATH_VARS CMAKE_INSTALL_DATADIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/g2pConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/g2pConfig.cmake ${PROJECT_BINARY_DIR}/g2pConfigVersion.cmake
        DESTINATION ${G2P_INSTALL_CMAKEDIR})

# The .pc file finds its prefix relative to itself, so the install tree is relocatable.
file(RELATIVE_PATH G2P_PC_TO_PREFIX "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
configure_file(${PROJECT_SOURCE_DIR}/cmake/g2p.pc.in ${PROJECT_BINARY_DIR}/g2p.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/g2p.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
