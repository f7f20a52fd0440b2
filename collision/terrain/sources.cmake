# Voxel terrain collision (issue 6): included by collision/CMakeLists.txt.
set(BW_TERRAIN_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/voxel_terrain.cpp
  ${CMAKE_CURRENT_LIST_DIR}/chunk_bitmask.cpp
  ${CMAKE_CURRENT_LIST_DIR}/bitmask_broadphase.cpp
  ${CMAKE_CURRENT_LIST_DIR}/chunk_mesher.cpp
  ${CMAKE_CURRENT_LIST_DIR}/loose_kd_tree.cpp
  ${CMAKE_CURRENT_LIST_DIR}/chunk_cache.cpp
  ${CMAKE_CURRENT_LIST_DIR}/terrain.cpp
  ${CMAKE_CURRENT_LIST_DIR}/terrain_queries.cpp
  ${CMAKE_CURRENT_LIST_DIR}/triangle_contacts.cpp
  ${CMAKE_CURRENT_LIST_DIR}/terrain_contacts.cpp
  ${CMAKE_CURRENT_LIST_DIR}/terrain_generator.cpp
  ${CMAKE_CURRENT_LIST_DIR}/vox_reader.cpp
)
