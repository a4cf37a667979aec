# Fails when a binary imports any global vk* function: the engine must reach Vulkan only through
# its private table, and the standalone host through the loader it opens at run time.
execute_process(COMMAND nm -D --undefined-only ${BINARY} OUTPUT_VARIABLE symbols RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${BINARY}")
endif()
string(REGEX MATCHALL "[ \t]vk[A-Za-z0-9_]+" imported "${symbols}")
if(imported)
  message(FATAL_ERROR "${BINARY} imports global Vulkan symbols:${imported}")
endif()
message(STATUS "${BINARY}: no global vk* imports")
