# Finds libg2p's dependencies. Every one of them is a Debian 12 package that
# scripts/install-deps.sh installs; the error messages say which.

function(g2p_require found package)
  if(NOT ${found})
    message(FATAL_ERROR "libg2p needs the Debian package '${package}'. "
                        "Run scripts/install-deps.sh (as root or with sudo).")
  endif()
endfunction()

# Public: Eigen appears in the public headers.
find_package(Eigen3 3.4 NO_MODULE QUIET)
g2p_require(Eigen3_FOUND libeigen3-dev)

# Private: none of these types appear in the public headers.
find_package(assimp QUIET)
g2p_require(assimp_FOUND libassimp-dev)

# OpenCV for image processing and ONNX inference only: its imgcodecs module
# would load some 90 more shared libraries at start (Debian builds it with
# GDAL, poppler, HDF5, ...); images are read and written with the libraries
# made for each format (libg2p/src/io/image_codecs.h).
find_package(OpenCV 4.6 QUIET COMPONENTS core imgproc dnn ml)
g2p_require(OpenCV_FOUND libopencv-dev)

find_package(PNG QUIET)
g2p_require(PNG_FOUND libpng-dev)
find_package(JPEG QUIET)
g2p_require(JPEG_FOUND libjpeg-dev)
find_package(TIFF QUIET)
g2p_require(TIFF_FOUND libtiff-dev)
find_path(G2P_WEBP_INCLUDE webp/decode.h)
find_library(G2P_WEBP_LIBRARY webp)
g2p_require(G2P_WEBP_INCLUDE libwebp-dev)
g2p_require(G2P_WEBP_LIBRARY libwebp-dev)

# Compressed glTF (libg2p/src/io/gltf_decode.cpp): Draco meshes and meshopt buffer views.
find_package(draco QUIET)
g2p_require(draco_FOUND libdraco-dev)
find_package(meshoptimizer QUIET)
g2p_require(meshoptimizer_FOUND libmeshoptimizer-dev)

find_package(embree 3 QUIET)
g2p_require(embree_FOUND libembree-dev)

find_package(TBB QUIET)
g2p_require(TBB_FOUND libtbb-dev)

find_package(CURL QUIET)
g2p_require(CURL_FOUND libcurl4-openssl-dev)

find_package(nlohmann_json 3.10 QUIET)
g2p_require(nlohmann_json_FOUND nlohmann-json3-dev)

find_package(Threads REQUIRED)

# Convex hulls of the collision geometry (decompose stage): Qhull, reentrant.
find_package(Qhull QUIET)
g2p_require(Qhull_FOUND libqhull-dev)

# The optional `hacd` decomposer (docs/decompose.md): Bullet's HACD library,
# for comparison with `voxel-cut`. Found or not; shared builds only (a static
# libg2p would have to find it for its consumers too).
find_path(G2P_HACD_INCLUDE hacdHACD.h PATH_SUFFIXES bullet/HACD)
find_library(G2P_HACD_LIBRARY NAMES HACD-float64)
if(G2P_HACD_INCLUDE AND G2P_HACD_LIBRARY AND BUILD_SHARED_LIBS)
  set(G2P_WITH_HACD ON)
  message(STATUS "libg2p: the hacd decomposer with ${G2P_HACD_LIBRARY}")
else()
  set(G2P_WITH_HACD OFF)
  message(STATUS "libg2p: no hacd decomposer (libbullet-extras-dev not found, or a static build)")
endif()

# URDF export goes through urdfdom's model and writer (which print with TinyXML 2.6).
find_package(urdfdom QUIET)
g2p_require(urdfdom_FOUND liburdfdom-dev)
find_path(G2P_TINYXML_INCLUDE tinyxml.h)
find_library(G2P_TINYXML_LIBRARY tinyxml)
g2p_require(G2P_TINYXML_INCLUDE libtinyxml-dev)
g2p_require(G2P_TINYXML_LIBRARY libtinyxml-dev)

# MuJoCo checks exported MJCF files in the engine (check_in_mujoco, g2p validate).
# Optional: without it libg2p still exports, and says so where a check is asked for.
if(G2P_WITH_MUJOCO)
  find_package(mujoco 2.2 QUIET)
  if(NOT mujoco_FOUND)
    message(WARNING "MuJoCo not found: building without the MuJoCo check (install 'libmujoco-dev "
                    "libgl-dev libopengl-dev' for it, or pass -DG2P_WITH_MUJOCO=OFF to silence this).")
    set(G2P_WITH_MUJOCO OFF CACHE BOOL "Check exported MJCF files in MuJoCo" FORCE)
  endif()
endif()

if(G2P_WITH_CGAL)
  find_package(CGAL 5.5 QUIET)
  if(NOT CGAL_FOUND)
    message(FATAL_ERROR "G2P_WITH_CGAL=ON needs the Debian package 'libcgal-dev' "
                        "(or configure with -DG2P_WITH_CGAL=OFF for a GPL-free build).")
  endif()
endif()
