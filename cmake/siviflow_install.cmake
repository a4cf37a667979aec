# Installs the libraries, the public headers and a CMake package, so that an engine can embed
# SiViFlow with find_package(siviflow) and link siviflow::engine (and siviflow::capture).
include(CMakePackageConfigHelpers)

# Exported as siviflow::sim, siviflow::engine, ... — the same names as the in-tree aliases.
foreach(target sim engine capture shaders warnings)
  set_target_properties(siviflow_${target} PROPERTIES EXPORT_NAME ${target})
endforeach()
install(TARGETS siviflow_sim siviflow_engine siviflow_capture siviflow_shaders siviflow_warnings
        EXPORT siviflowTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine/include/siviflow
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/sim DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")
# The GPU layouts the sim's packing writes (included as "shaders/shared.h").
install(FILES ${PROJECT_SOURCE_DIR}/shaders/shared.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/shaders)
install(EXPORT siviflowTargets NAMESPACE siviflow:: FILE siviflowTargets.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/siviflow)

file(WRITE ${PROJECT_BINARY_DIR}/siviflowConfig.cmake.in [=[
@PACKAGE_INIT@
include(CMakeFindDependencyMacro)
find_dependency(glm)
find_dependency(VulkanHeaders CONFIG)
find_dependency(TinyGLTF CONFIG)
find_dependency(nlohmann_json 3 CONFIG)
find_dependency(OpenEXR 3 CONFIG)
find_dependency(PNG)
find_dependency(JPEG)
include("${CMAKE_CURRENT_LIST_DIR}/siviflowTargets.cmake")
]=])
configure_package_config_file(${PROJECT_BINARY_DIR}/siviflowConfig.cmake.in
  ${PROJECT_BINARY_DIR}/siviflowConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/siviflow)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/siviflowConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/siviflowConfig.cmake ${PROJECT_BINARY_DIR}/siviflowConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/siviflow)
