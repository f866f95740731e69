# All third-party libraries, found once. Each becomes an imported target solidtex::<name>
# so that only the translation units that need a heavy header see its include path.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(TBB REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(nlohmann_json 3 REQUIRED)
find_package(GTest REQUIRED)

# OpenImageIO: the CMake package lists /usr/include/opencv4 (absent without OpenCV), so use pkg-config.
pkg_check_modules(OIIO REQUIRED IMPORTED_TARGET OpenImageIO)
add_library(solidtex::oiio ALIAS PkgConfig::OIIO)

# FLANN: header-only use of the C++ templates; its pkg-config drags HDF5/MPI flags, so avoid it.
find_path(FLANN_INCLUDE_DIR flann/flann.hpp REQUIRED)
find_library(LZ4_LIBRARY lz4 REQUIRED)
add_library(solidtex_flann INTERFACE)
target_include_directories(solidtex_flann SYSTEM INTERFACE ${FLANN_INCLUDE_DIR})
target_link_libraries(solidtex_flann INTERFACE ${LZ4_LIBRARY})
add_library(solidtex::flann ALIAS solidtex_flann)

# OpenVDB (needs libboost-iostreams-dev and its own CMake module dir on CMAKE_MODULE_PATH).
find_package(OpenVDB QUIET)
if(OpenVDB_FOUND)
  add_library(solidtex::openvdb ALIAS OpenVDB::openvdb)
endif()

# RESTinio (header-only; standalone Asio, fmt, http_parser). Only server/http_server.cpp uses it.
find_package(fmt REQUIRED)
find_library(HTTP_PARSER_LIBRARY http_parser REQUIRED)
add_library(solidtex_restinio INTERFACE)
target_compile_definitions(solidtex_restinio INTERFACE ASIO_STANDALONE ASIO_HAS_STD_CHRONO ASIO_DISABLE_STD_STRING_VIEW)
target_link_libraries(solidtex_restinio INTERFACE fmt::fmt ${HTTP_PARSER_LIBRARY} Threads::Threads)
add_library(solidtex::restinio ALIAS solidtex_restinio)
