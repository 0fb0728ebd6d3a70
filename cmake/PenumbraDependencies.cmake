# Finds Penumbra's dependencies from Debian 12's packages (see scripts/install-deps.sh) and smooths
# over their packaging quirks (docs/dependencies.md).
find_package(embree 3 REQUIRED)
find_package(TBB REQUIRED)
find_package(glm REQUIRED)
find_package(fmt REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(Threads REQUIRED)

# OpenImageIO's exported target lists /usr/include/opencv4, which exists only with OpenCV's headers.
find_package(OpenImageIO REQUIRED)
get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
list(FILTER _oiio_inc EXCLUDE REGEX "opencv4")
set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_inc}")

# Debian's OpenColorIOConfig.cmake exports a broken include path: use pkg-config instead.
find_package(PkgConfig REQUIRED)
pkg_check_modules(OCIO REQUIRED IMPORTED_TARGET OpenColorIO)

# tinygltf ships no CMake package; its implementation lives in libtinygltf.so.
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
find_library(TINYGLTF_LIBRARY tinygltf REQUIRED)
add_library(tinygltf::tinygltf UNKNOWN IMPORTED)
set_target_properties(tinygltf::tinygltf PROPERTIES IMPORTED_LOCATION ${TINYGLTF_LIBRARY}
                      INTERFACE_INCLUDE_DIRECTORIES ${TINYGLTF_INCLUDE_DIR})
