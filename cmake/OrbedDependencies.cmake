# Finds every dependency once. All are Debian packages that `scripts/orbed setup` installs.
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(OpenSSL 3 REQUIRED COMPONENTS Crypto)  # SHA-256 (base/sha256.h)
find_package(GTest REQUIRED)
find_package(PkgConfig REQUIRED)

# LCM 1.3.1 on Debian ships neither a CMake config nor a usable lcm.pc (it requires glib's -dev).
find_program(LCM_GEN_EXECUTABLE lcm-gen REQUIRED)
find_library(LCM_LIBRARY lcm REQUIRED)
find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp REQUIRED)
add_library(orbed_lcm INTERFACE)
target_include_directories(orbed_lcm INTERFACE ${LCM_INCLUDE_DIR})
target_link_libraries(orbed_lcm INTERFACE ${LCM_LIBRARY} Threads::Threads)

# The lcm-spy jar and the tests' tools are part of the product: missing ones are errors, not
# silently skipped tests (scripts/orbed setup installs them all).
find_package(Java 11 REQUIRED COMPONENTS Development)
find_file(LCM_JAR lcm.jar PATHS /usr/share/java NO_DEFAULT_PATH REQUIRED)
find_program(CHECK_URDF_EXECUTABLE check_urdf REQUIRED)
find_program(XVFB_RUN_EXECUTABLE xvfb-run REQUIRED)
if(ORBED_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs highgui)
find_package(urdfdom REQUIRED)
# TinyXML, the parser urdfdom 3 uses: the robot model reads a URDF's joints with it before urdfdom.
find_path(TINYXML_INCLUDE_DIR tinyxml.h REQUIRED)
find_library(TINYXML_LIBRARY tinyxml REQUIRED)
# Bullet in double precision only; never link the single-precision libraries beside it.
pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet-float64)
find_package(fcl QUIET)
# libavcodec (FFmpeg) with Debian's libx264 and libx265 for the emulated HoloLens 2's PV video
# (procs/hl2ss/pv_encoder.h); its decoder is the independent reader in the tests.
pkg_check_modules(LIBAV REQUIRED IMPORTED_TARGET libavcodec libavutil)

# OpenIGTLink 1.11 (protocol v2) for orbed-igtl-bridge. Debian's config file is pre-target CMake
# (variables only), so the library is found by hand; the example sources the integration test
# builds its receiver from come with openigtlink-examples.
find_library(OPENIGTLINK_LIBRARY OpenIGTLink REQUIRED)
find_path(OPENIGTLINK_INCLUDE_DIR igtlTransformMessage.h PATH_SUFFIXES openigtlink REQUIRED)
add_library(orbed_openigtlink INTERFACE)
target_include_directories(orbed_openigtlink SYSTEM INTERFACE ${OPENIGTLINK_INCLUDE_DIR})
target_link_libraries(orbed_openigtlink INTERFACE ${OPENIGTLINK_LIBRARY} Threads::Threads)
find_path(OPENIGTLINK_EXAMPLES_DIR Receiver/ReceiveClient.cxx
          PATHS /usr/share/doc/openigtlink-examples/examples NO_DEFAULT_PATH REQUIRED)

# websocketpp 0.8 (header-only) on standalone asio, for orbed-foxglove-bridge.
find_path(WEBSOCKETPP_INCLUDE_DIR websocketpp/server.hpp REQUIRED)
find_path(ASIO_INCLUDE_DIR asio.hpp REQUIRED)
add_library(orbed_websocketpp INTERFACE)
target_include_directories(orbed_websocketpp SYSTEM INTERFACE ${WEBSOCKETPP_INCLUDE_DIR} ${ASIO_INCLUDE_DIR})
target_compile_definitions(orbed_websocketpp INTERFACE ASIO_STANDALONE)
target_link_libraries(orbed_websocketpp INTERFACE Threads::Threads)
