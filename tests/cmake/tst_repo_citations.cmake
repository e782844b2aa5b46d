# cmake -DSOURCE_DIR=... -P tst_repo_citations.cmake: the repository speaks for itself. Its tracked text
# files must not cite what the repository does not hold: work items (issue numbers), CI runs by number,
# work sessions, the source documents by their file numbers, or paths outside the repository. A paper is
# cited by title and authors (docs/LB_MODEL.md shows how), a design decision by the doc that holds it.
# Fails (FATAL_ERROR) listing file:line of every hit. This file holds the patterns, so it is not scanned.
#
# The files: `git ls-files` when git and SOURCE_DIR/.git exist, else the source folders globbed.
cmake_minimum_required(VERSION 3.16)

if(NOT SOURCE_DIR)
  get_filename_component(SOURCE_DIR "${CMAKE_CURRENT_LIST_DIR}/../.." ABSOLUTE)
endif()
set(self "tests/cmake/tst_repo_citations.cmake")

# One regular expression per kind of citation (CMake syntax: no \b, no {n}, no case flag).
set(patterns
  "[Ii]ssues? #?[0-9]+"                             # "issue 18 item 4", "issue #3", "issues 15"
  "[Tt]he issue's"                                   # "the issue's target"
  "[Pp]icture issue"
  "CI('s)? stops? [0-9]+"                            # "CI's stop 25"
  "([Tt]his|[Tt]hat|[Ss]ame|[Oo]ne) session"       # work sessions, not the studio's or MPI's sessions
  "session's [0-9]+-core"
  "[Ss]eeds?/"                                       # the seed documents' folder
  "[Ss]eed 00[0-9]"                                  # "seed 000 section 3"
  "[Ss]eed paper"
  "\\.\\./shared"                                    # paths beside the repository
  "shared/(design|seeds|data)"
)
set(kinds "issue number" "issue" "issue" "CI stop" "work session" "work session" "seed documents"
  "seed document" "seed document" "path outside the repository" "path outside the repository")

# Files that are not text (or are data too large to be prose) are skipped by extension and size.
set(skip_ext png jpg jpeg exr hdr npy vdb fbx obj mtl glb gltf gz xz zip pdf ico bin ttf otf woff)

set(files "")
find_program(GIT_EXECUTABLE git)
if(GIT_EXECUTABLE AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT_EXECUTABLE}" -c core.quotepath=off ls-files WORKING_DIRECTORY "${SOURCE_DIR}"
                  OUTPUT_VARIABLE listed RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "git ls-files failed in ${SOURCE_DIR}")
  endif()
  string(REPLACE ";" "\\;" listed "${listed}")
  string(REPLACE "\n" ";" files "${listed}")
  message(STATUS "scanning the files git tracks in ${SOURCE_DIR}")
else()
  foreach(top core pipeline studio cuda tests docs resources cmake .ci)
    if(IS_DIRECTORY "${SOURCE_DIR}/${top}")
      file(GLOB_RECURSE found RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/${top}/*")
      list(APPEND files ${found})
    endif()
  endforeach()
  foreach(top README.md build.sh CMakeLists.txt)
    if(EXISTS "${SOURCE_DIR}/${top}")
      list(APPEND files "${top}")
    endif()
  endforeach()
  message(STATUS "no git checkout: scanning the source folders of ${SOURCE_DIR}")
endif()

set(hits "")
set(scanned 0)
list(LENGTH patterns npatterns)
math(EXPR last "${npatterns} - 1")
string(JOIN "|" any ${patterns})
foreach(rel IN LISTS files)
  if(rel STREQUAL "" OR rel STREQUAL self)
    continue()
  endif()
  set(path "${SOURCE_DIR}/${rel}")
  if(IS_DIRECTORY "${path}" OR NOT EXISTS "${path}")
    continue()
  endif()
  get_filename_component(name "${rel}" NAME)
  string(REGEX MATCH "[^.]+$" ext "${name}")
  string(TOLOWER "${ext}" ext)
  if(NOT name STREQUAL ext AND ext IN_LIST skip_ext)
    continue()
  endif()
  file(SIZE "${path}" size)
  if(size GREATER 4000000)
    continue()
  endif()
  file(READ "${path}" text)
  math(EXPR scanned "${scanned} + 1")
  if(NOT text MATCHES "${any}")
    continue()
  endif()
  # Line by line for the line numbers: characters that CMake lists treat specially are masked first.
  string(REPLACE "\\" "<bs>" text "${text}")
  string(REPLACE ";" "<sc>" text "${text}")
  string(REPLACE "[" "<lb>" text "${text}")
  string(REPLACE "]" "<rb>" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  set(n 0)
  foreach(line IN LISTS lines)
    math(EXPR n "${n} + 1")
    if(NOT line MATCHES "${any}")
      continue()
    endif()
    foreach(i RANGE ${last})
      list(GET patterns ${i} pattern)
      if(line MATCHES "${pattern}")
        list(GET kinds ${i} kind)
        string(REPLACE "<sc>" ";" shown "${CMAKE_MATCH_0}")
        string(REPLACE "<lb>" "[" shown "${shown}")
        string(REPLACE "<rb>" "]" shown "${shown}")
        string(REPLACE "<bs>" "\\" shown "${shown}")
        list(APPEND hits "${rel}:${n}: ${kind}: '${shown}'")
        break()
      endif()
    endforeach()
  endforeach()
endforeach()

list(LENGTH hits nhits)
if(nhits GREATER 0)
  string(REPLACE ";" "\n  " listing "${hits}")
  message(FATAL_ERROR "${nhits} citation(s) of things the repository does not hold (cite a paper by title and "
                      "authors, a doc by its path in the repository, a work item by what it did):\n  ${listing}")
endif()
message(STATUS "${scanned} text files scanned: no citation of issues, CI stops, work sessions, seed documents or "
               "paths outside the repository")
