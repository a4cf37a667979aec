# Installs the libraries, the public headers and a CMake package with components, so that an
# engine embeds the water with find_package(siviflow COMPONENTS water) and links siviflow::water
# alone, pulling in no file-format library; siviflow::scene, ::headless and ::capture come with
# their components (all of them when none is named); and the embedding example as source.
include(CMakePackageConfigHelpers)

# Exported as siviflow::sim, siviflow::water, ... — the same names as the in-tree aliases.
foreach(target common sim water scene headless capture shaders warnings)
  set_target_properties(siviflow_${target} PROPERTIES EXPORT_NAME ${target})
endforeach()
# One export set per component: water (with what it links), scene (with the headless host), capture.
install(TARGETS siviflow_common siviflow_sim siviflow_water siviflow_shaders siviflow_warnings
        EXPORT siviflowWaterTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS siviflow_scene siviflow_headless
        EXPORT siviflowSceneTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS siviflow_capture
        EXPORT siviflowCaptureTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
foreach(component Water Scene Capture)
  install(EXPORT siviflow${component}Targets NAMESPACE siviflow:: FILE siviflow${component}Targets.cmake
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/siviflow)
endforeach()
# Every public header lies under include/siviflow/ (a system include folder holds nothing else of
# ours), each library's where its own include/ puts it: the engine's, common's, and the sim
# headers that the engine's public headers include (siviflow/sim/), and the version header
# generated from project().
install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine/include/siviflow
                  ${PROJECT_SOURCE_DIR}/engine/common/include/siviflow
                  ${PROJECT_SOURCE_DIR}/sim/include/siviflow
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${PROJECT_BINARY_DIR}/include/siviflow/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/siviflow)
# The examples, as source a host builds against the installed package.
foreach(example embed modern_frame window_host)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/tools/examples/${example}
          DESTINATION ${CMAKE_INSTALL_DATADIR}/siviflow/examples)
endforeach()
# The example scene files, with the glTF files they load (docs/scenes.md), and their schema.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/scenes
        DESTINATION ${CMAKE_INSTALL_DATADIR}/siviflow/examples)
install(FILES ${PROJECT_SOURCE_DIR}/engine/scene/scene.schema.json
        DESTINATION ${CMAKE_INSTALL_DATADIR}/siviflow)
# The guides, the licence and the changes, where a distribution looks for them.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/LICENSE
              ${PROJECT_SOURCE_DIR}/CHANGELOG.md ${PROJECT_SOURCE_DIR}/CONTRIBUTING.md
              ${PROJECT_SOURCE_DIR}/third_party_notes.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

file(WRITE ${PROJECT_BINARY_DIR}/siviflowConfig.cmake.in [=[
@PACKAGE_INIT@
include(CMakeFindDependencyMacro)
set(_siviflow_components ${siviflow_FIND_COMPONENTS})
if(NOT _siviflow_components)
  set(_siviflow_components water scene headless capture)
endif()
# water: Vulkan headers and GLM; scene (and headless, which needs it): glTF, JSON, PNG, JPEG;
# capture: OpenEXR and PNG.
find_dependency(glm)
find_dependency(VulkanHeaders CONFIG)
include("${CMAKE_CURRENT_LIST_DIR}/siviflowWaterTargets.cmake")
set(siviflow_water_FOUND TRUE)
if("scene" IN_LIST _siviflow_components OR "headless" IN_LIST _siviflow_components)
  find_dependency(TinyGLTF CONFIG)
  find_dependency(nlohmann_json 3 CONFIG)
  find_dependency(PNG)
  find_dependency(JPEG)
  include("${CMAKE_CURRENT_LIST_DIR}/siviflowSceneTargets.cmake")
  set(siviflow_scene_FOUND TRUE)
  set(siviflow_headless_FOUND TRUE)
endif()
if("capture" IN_LIST _siviflow_components)
  find_dependency(OpenEXR 3 CONFIG)
  find_dependency(PNG)
  include("${CMAKE_CURRENT_LIST_DIR}/siviflowCaptureTargets.cmake")
  set(siviflow_capture_FOUND TRUE)
endif()
check_required_components(siviflow)
]=])
configure_package_config_file(${PROJECT_BINARY_DIR}/siviflowConfig.cmake.in
  ${PROJECT_BINARY_DIR}/siviflowConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/siviflow)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/siviflowConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/siviflowConfig.cmake ${PROJECT_BINARY_DIR}/siviflowConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/siviflow)
