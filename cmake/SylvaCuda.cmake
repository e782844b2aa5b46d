# The CUDA backend needs nvcc >= 12 (C++20 in device code). sylva_nvcc_version asks a compiler for its
# version before CMake enables the language, so an older nvcc leaves a CPU-only build instead of failing
# later in the CUDA sources (tests/cmake/tst_cuda_version.cmake runs it against fake compilers).
set(SYLVA_MIN_NVCC_VERSION 12.0)

# sylva_nvcc_version(<compiler> <out-var>): "MAJOR.MINOR" from `<compiler> --version`
# ("Cuda compilation tools, release 12.4, V12.4.131"), or "" when it does not run or say so.
function(sylva_nvcc_version compiler out)
  set(version "")
  execute_process(COMMAND "${compiler}" --version OUTPUT_VARIABLE text ERROR_QUIET RESULT_VARIABLE rc TIMEOUT 60)
  if(rc EQUAL 0 AND text MATCHES "release ([0-9]+)\\.([0-9]+)")
    set(version "${CMAKE_MATCH_1}.${CMAKE_MATCH_2}")
  endif()
  set(${out} "${version}" PARENT_SCOPE)
endfunction()

# sylva_cuda_usable(<compiler> <out-var> <why-var>): TRUE when the compiler is nvcc >= 12; otherwise
# FALSE and, in <why-var>, the sentence configure prints.
function(sylva_cuda_usable compiler out why)
  sylva_nvcc_version("${compiler}" version)
  if(version STREQUAL "")
    set(${out} FALSE PARENT_SCOPE)
    set(${why} "cannot read the version of ${compiler} (--version says no \"release X.Y\")" PARENT_SCOPE)
  elseif(version VERSION_LESS SYLVA_MIN_NVCC_VERSION)
    set(${out} FALSE PARENT_SCOPE)
    set(${why} "${compiler} is nvcc ${version}; the CUDA backend needs nvcc >= ${SYLVA_MIN_NVCC_VERSION} (C++20 in device code)" PARENT_SCOPE)
  else()
    set(${out} TRUE PARENT_SCOPE)
    set(${why} "nvcc ${version}" PARENT_SCOPE)
  endif()
endfunction()
