# cmake -DPROGRAM=... -DARGS="--man" -DOUT=file -P SylvaRunToFile.cmake: runs PROGRAM ARGS and writes its
# standard output to OUT (a build step that needs no shell redirection). Fails when the program fails.
separate_arguments(args UNIX_COMMAND "${ARGS}")
execute_process(COMMAND "${PROGRAM}" ${args} OUTPUT_FILE "${OUT}.tmp" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  file(REMOVE "${OUT}.tmp")
  message(FATAL_ERROR "${PROGRAM} ${ARGS} failed (${rc})")
endif()
file(RENAME "${OUT}.tmp" "${OUT}")
