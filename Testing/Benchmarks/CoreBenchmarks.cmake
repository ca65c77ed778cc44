# The benchmark programs that need only the core (no VTK): built by the plugin project and by the standalone core
# build (Filters/Core), which is what a GPU machine without ParaView builds (gpu_check.sh).
foreach (bench IN ITEMS BenchApproximation BenchSPH BenchSPHFront BenchElasticSolid BenchSurfaceScan BenchCloudNormals)
  add_executable(${bench} "${CMAKE_CURRENT_LIST_DIR}/${bench}.cxx")
  target_link_libraries(${bench} PRIVATE MeshFree::Core)
  target_include_directories(${bench} PRIVATE "${CMAKE_CURRENT_LIST_DIR}/../Common")
endforeach ()
