# cmake -DSOURCE_DIR=... -DWORK_DIR=... -P tst_cuda_version.cmake: the nvcc version check of
# cmake/SylvaCuda.cmake against fake compilers that print what nvcc 11.8, 12.0, 13.0 print (and one that
# fails, one that prints something else). Fails (FATAL_ERROR) on any wrong answer.
include("${SOURCE_DIR}/cmake/SylvaCuda.cmake")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(fake_nvcc name text rc)
  set(path "${WORK_DIR}/${name}")
  file(WRITE "${path}" "#!/bin/sh\nprintf '%s\\n' '${text}'\nexit ${rc}\n")
  file(CHMOD "${path}" PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE)
  set(fake "${path}" PARENT_SCOPE)
endfunction()

function(expect name text rc want_version want_usable)
  fake_nvcc("${name}" "${text}" ${rc})
  sylva_nvcc_version("${fake}" version)
  sylva_cuda_usable("${fake}" usable why)
  if(NOT version STREQUAL "${want_version}")
    message(FATAL_ERROR "${name}: version '${version}', expected '${want_version}'")
  endif()
  if((usable AND NOT want_usable) OR (NOT usable AND want_usable))
    message(FATAL_ERROR "${name}: usable=${usable}, expected ${want_usable} (${why})")
  endif()
  message(STATUS "${name}: ${version} usable=${usable}: ${why}")
endfunction()

expect(nvcc_11_8 "Cuda compilation tools, release 11.8, V11.8.89" 0 "11.8" FALSE)
expect(nvcc_12_0 "Cuda compilation tools, release 12.0, V12.0.76" 0 "12.0" TRUE)
expect(nvcc_13_0 "Cuda compilation tools, release 13.0, V13.0.88" 0 "13.0" TRUE)
expect(nvcc_fails "Cuda compilation tools, release 12.4, V12.4.131" 1 "" FALSE)
expect(not_nvcc "gcc (Debian 12.2.0-14) 12.2.0" 0 "" FALSE)
# The message for an old compiler names its version and the minimum.
fake_nvcc(nvcc_old "Cuda compilation tools, release 11.8, V11.8.89" 0)
sylva_cuda_usable("${fake}" usable why)
if(NOT why MATCHES "nvcc 11\\.8" OR NOT why MATCHES ">= 12\\.0")
  message(FATAL_ERROR "unclear message: ${why}")
endif()
