# sylva_add_test(NAME <name> SOURCES <files...> LABELS <labels...> [CORE] [CLI] [LIBS <targets...>] [TIMEOUT <s>])
# CORE links only sylva_core (no Qt beyond Qt Test, no Assimp/OIIO). CLI: the test runs the sylva program
# (SYLVA_CLI_PATH, tests/common/run_program.h), which is built first.
# One Qt Test executable per unit, registered with CTest under its labels (unit, pipeline, gui, gpu, slow).
function(sylva_add_test)
  cmake_parse_arguments(T "CORE;CLI" "NAME;TIMEOUT" "SOURCES;LABELS;LIBS" ${ARGN})
  add_executable(${T_NAME} ${T_SOURCES})
  set_target_properties(${T_NAME} PROPERTIES AUTOMOC ON)
  if(T_CORE)
    target_link_libraries(${T_NAME} PRIVATE sylva_core Qt6::Test ${T_LIBS})
  else()
    target_link_libraries(${T_NAME} PRIVATE sylva_pipeline Qt6::Test ${T_LIBS})
  endif()
  target_compile_definitions(${T_NAME} PRIVATE
    SYLVA_RESOURCES="${CMAKE_SOURCE_DIR}/resources"
    SYLVA_TEST_DATA="${CMAKE_SOURCE_DIR}/tests/data"
    SYLVA_TEST_OUTPUT="${CMAKE_BINARY_DIR}/test-output")
  if(T_CLI)
    target_compile_definitions(${T_NAME} PRIVATE SYLVA_CLI_PATH="$<TARGET_FILE:sylva>")
    add_dependencies(${T_NAME} sylva)
  endif()
  add_test(NAME ${T_NAME} COMMAND ${T_NAME})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 600)
  endif()
  set_tests_properties(${T_NAME} PROPERTIES LABELS "${T_LABELS}" TIMEOUT ${T_TIMEOUT}
    ENVIRONMENT "QT_QPA_PLATFORM=offscreen;XDG_CACHE_HOME=${CMAKE_BINARY_DIR}/test-cache")
endfunction()

# sylva_add_bench(NAME <name> SOURCES <files...>): a benchmark program (not a test); run it by hand.
function(sylva_add_bench)
  cmake_parse_arguments(B "" "NAME" "SOURCES;LIBS" ${ARGN})
  add_executable(${B_NAME} ${B_SOURCES})
  target_link_libraries(${B_NAME} PRIVATE sylva_pipeline ${B_LIBS})
  target_compile_definitions(${B_NAME} PRIVATE SYLVA_RESOURCES="${CMAKE_SOURCE_DIR}/resources")
endfunction()
