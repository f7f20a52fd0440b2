# Every dependency comes from Debian 12 packages (setup.sh installs them).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(ZLIB REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(Threads REQUIRED)
if(BW_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(BW_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

# Debian's BulletConfig.cmake only sets variables with relative paths, so we locate the
# single-precision libraries ourselves and wrap them in one imported target.
find_path(BW_BULLET_INCLUDE_DIR btBulletCollisionCommon.h PATH_SUFFIXES bullet REQUIRED)
add_library(bw_bullet INTERFACE)
foreach(lib BulletDynamics BulletCollision LinearMath)
  find_library(BW_BULLET_${lib} NAMES ${lib} REQUIRED)
  target_link_libraries(bw_bullet INTERFACE ${BW_BULLET_${lib}})
endforeach()
target_include_directories(bw_bullet SYSTEM INTERFACE ${BW_BULLET_INCLUDE_DIR})
add_library(bw::bullet ALIAS bw_bullet)
