# Fails when a file of bridge/ or adapters/ opens a dnbridge namespace other
# than its folder's (ARCHITECTURE.md, "Namespaces"):
#   bridge/common/            dnbridge
#   bridge/profiles/<name>/   dnbridge::profiles::<name>
#   bridge/<layer>/...        dnbridge::<layer>      (devicenet/wire and devicenet/master: devicenet)
#   adapters/sim/host/        dnbridge::sim::host    (cdn127-sim, a program of its own)
#   adapters/<folder>/...     dnbridge::<folder>     (sim/bus, generic, cdn127, world: sim)
# A namespace nested in the folder's is the folder's too (cip::identity,
# daemon::config_detail); a block of forward declarations of another
# folder's classes is not a namespace of the file's.
#   cmake -DROOT=path/to/repository -P check_namespaces.cmake
function(expected_namespace rel out)
  if(rel MATCHES "^bridge/common/")
    set(ns "dnbridge")
  elseif(rel MATCHES "^bridge/profiles/([a-z0-9_]+)/")
    set(ns "dnbridge::profiles::${CMAKE_MATCH_1}")
  elseif(rel MATCHES "^adapters/sim/host/")
    set(ns "dnbridge::sim::host")
  elseif(rel MATCHES "^(bridge|adapters)/([a-z0-9_]+)/")
    set(ns "dnbridge::${CMAKE_MATCH_2}")
  else()
    set(ns "")
  endif()
  set(${out} "${ns}" PARENT_SCOPE)
endfunction()

set(violations "")
set(count 0)
file(GLOB_RECURSE files RELATIVE ${ROOT} ${ROOT}/bridge/*.hpp ${ROOT}/bridge/*.cpp
     ${ROOT}/adapters/*.hpp ${ROOT}/adapters/*.cpp ${ROOT}/adapters/*.h ${ROOT}/adapters/*.c)
foreach(rel ${files})
  expected_namespace(${rel} want)
  if(want STREQUAL "")
    continue()
  endif()
  file(READ ${ROOT}/${rel} text)
  string(REGEX REPLACE "\nnamespace [a-z0-9_:]+ {\n((class|struct) [A-Za-z0-9_]+;\n)+}" "" text
         "\n${text}")
  string(REGEX MATCHALL "\nnamespace dnbridge[a-z0-9_:]* {" opened "${text}")
  foreach(line ${opened})
    math(EXPR count "${count} + 1")
    string(REGEX REPLACE "^\nnamespace (dnbridge[a-z0-9_:]*) {" "\\1" ns "${line}")
    if(want STREQUAL "dnbridge")
      # The root's own files: the root alone, or a detail of one file.
      if(NOT ns STREQUAL "dnbridge" AND NOT ns MATCHES "_detail$")
        list(APPEND violations "${rel}: namespace ${ns} (its folder's is dnbridge)")
      endif()
    elseif(NOT ns STREQUAL want AND NOT ns MATCHES "^${want}::")
      list(APPEND violations "${rel}: namespace ${ns} (its folder's is ${want})")
    endif()
  endforeach()
endforeach()
if(violations)
  string(REPLACE ";" "\n" text "${violations}")
  message(FATAL_ERROR "A file's namespace is not its folder's:\n${text}")
endif()
if(count LESS 100)
  message(FATAL_ERROR "only ${count} namespaces found under ${ROOT}: is ROOT the repository?")
endif()
message(STATUS "${count} namespaces in bridge/ and adapters/: each is its folder's")
