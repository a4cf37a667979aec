# Installs the build into a scratch prefix; checks that every installed header lies under
# include/siviflow and compiles alone against the prefix (tests/consumer/headers); builds the
# examples from their installed copies (share/siviflow/examples: embed, a frame loop with two
# frames in flight; modern_frame, HDR, reverse-Z, jitter, motion, reactive and depth, each
# checked; and window_host, built here and run under Xvfb by the window tier) against the
# prefix, at C++17, runs them, and checks the embed binary needs no
# file-format library; the installed tool checks each installed example scene as it would render
# it (--dry-run: the scene came with every file it loads); and the installed guides' links resolve
# among the installed files.
file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${prefix}
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install failed")
endif()

# A system include folder shared with other packages gets one folder of ours.
file(GLOB top_level RELATIVE ${prefix}/include ${prefix}/include/*)
if(NOT top_level STREQUAL "siviflow")
  message(FATAL_ERROR "the package installs beside include/siviflow: ${top_level}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE}/headers -B ${WORK}/headers -G Ninja
                        -DCMAKE_PREFIX_PATH=${prefix} -DSIVIFLOW_INCLUDE_DIR=${prefix}/include
                        -DCMAKE_CXX_STANDARD=17 -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the installed headers' check failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK}/headers RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "an installed header does not compile alone against the installed package")
endif()

# Each example as a host gets it, in a target at C++17 (the package raises it to what it needs):
# built from its installed copy against the prefix (and run, below).
function(build_example example)
  set(build ${WORK}/${example})
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${prefix}/share/siviflow/examples/${example}
                          -B ${build} -G Ninja -DCMAKE_PREFIX_PATH=${prefix}
                          -DCMAKE_CXX_STANDARD=17 -DCMAKE_BUILD_TYPE=Release
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "configuring the installed example ${example} failed")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${build} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "building the installed example ${example} failed")
  endif()
endfunction()
function(build_and_run example program)
  build_example(${example})
  execute_process(COMMAND ${WORK}/${example}/${program} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the example ${example} failed")
  endif()
endfunction()
build_and_run(embed embed_example)
build_and_run(modern_frame modern_frame)
build_example(window_host)  # run by the window tier, which has a display (installed_window_host)

file(GLOB scenes ${prefix}/share/siviflow/examples/scenes/*.json)
list(LENGTH scenes scene_count)
if(scene_count LESS 3)
  message(FATAL_ERROR "the example scenes are not installed: ${scenes}")
endif()
file(MAKE_DIRECTORY ${WORK}/frames)
foreach(scene IN LISTS scenes)
  execute_process(COMMAND ${prefix}/bin/siviflow capture ${scene} --dry-run --out ${WORK}/frames
                  RESULT_VARIABLE rc OUTPUT_VARIABLE output ERROR_VARIABLE output)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the installed example scene ${scene} does not check: ${output}")
  endif()
endforeach()

# The installed guides link only to what is installed beside them.
execute_process(COMMAND ${CHECK_DOCS} links ${prefix}/share/doc/siviflow
                RESULT_VARIABLE rc OUTPUT_VARIABLE output ERROR_VARIABLE output)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the installed documentation links to what is not installed: ${output}")
endif()

# The binary of an engine that links siviflow::water alone needs no file-format library.
execute_process(COMMAND readelf -d ${WORK}/embed/embed_example OUTPUT_VARIABLE dynamic
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "readelf failed on the example")
endif()
string(REGEX MATCHALL "\\(NEEDED\\)[^\n]*" needed "${dynamic}")
foreach(library IN LISTS needed)
  if(library MATCHES "OpenEXR|Imath|png|jpeg|tinygltf|Iex")
    message(FATAL_ERROR "the example needs a file-format library: ${library}")
  endif()
endforeach()
if(NOT needed MATCHES "libvulkan")
  message(FATAL_ERROR "readelf found no NEEDED entries we understand: ${needed}")
endif()
message(STATUS "example needs: ${needed}")
