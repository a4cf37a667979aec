# Fails when one of our libraries (static archives, |-separated in LIBRARIES) needs any global vk*
# function: the engine reaches Vulkan only through its private table, and the standalone host
# through the loader it opens at run time. (The siviflow tool itself links the loader for its
# live viewer, an application like any engine.)
string(REPLACE "|" ";" libraries "${LIBRARIES}")
foreach(library IN LISTS libraries)
  execute_process(COMMAND nm --undefined-only ${library} OUTPUT_VARIABLE symbols RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "nm failed on ${library}")
  endif()
  string(REGEX MATCHALL "[ \t]vk[A-Za-z0-9_]+" imported "${symbols}")
  if(imported)
    message(FATAL_ERROR "${library} needs global Vulkan symbols:${imported}")
  endif()
  message(STATUS "${library}: no global vk* symbol needed")
endforeach()
