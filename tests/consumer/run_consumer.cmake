# Installs the build into a scratch prefix; checks that every installed header lies under
# include/siviflow and compiles alone against the prefix (tests/consumer/headers); builds the
# embedding example from its installed copy (share/siviflow/examples/embed) against the prefix,
# at C++17, runs it, and checks its binary needs no file-format library.
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

# The example as a host gets it, in a target at C++17 (the package raises it to what it needs).
execute_process(COMMAND ${CMAKE_COMMAND} -S ${prefix}/share/siviflow/examples/embed
                        -B ${WORK}/build -G Ninja -DCMAKE_PREFIX_PATH=${prefix}
                        -DCMAKE_CXX_STANDARD=17 -DCMAKE_BUILD_TYPE=Release
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the installed example against the installed package failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK}/build RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the installed example failed")
endif()
execute_process(COMMAND ${WORK}/build/embed_example RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the example's frame failed")
endif()
# The binary of an engine that links siviflow::water alone needs no file-format library.
execute_process(COMMAND readelf -d ${WORK}/build/embed_example OUTPUT_VARIABLE dynamic RESULT_VARIABLE rc)
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
