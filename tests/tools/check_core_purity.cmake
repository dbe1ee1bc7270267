# Fails if a file under ROOT includes an OS, socket, thread or DDS header, or
# reads a clock. The protocol core is driven by events and a time handed in.
file(GLOB_RECURSE files ${ROOT}/*.hpp ${ROOT}/*.cpp)
set(forbidden
  "#include <sys/" "#include <linux/" "#include <net/" "#include <netinet/" "#include <unistd.h>"
  "#include <fcntl.h>" "#include <poll.h>" "#include <pthread.h>" "#include <thread>" "#include <mutex>"
  "#include <condition_variable>" "#include <dds/" "#include <ctime>" "#include <iostream>"
  "steady_clock" "system_clock" "high_resolution_clock")
set(violations "")
foreach(f ${files})
  file(READ ${f} text)
  foreach(pattern ${forbidden})
    string(FIND "${text}" "${pattern}" at)
    if(NOT at EQUAL -1)
      list(APPEND violations "${f}: ${pattern}")
    endif()
  endforeach()
endforeach()
list(LENGTH files count)
if(violations)
  string(REPLACE ";" "\n" text "${violations}")
  message(FATAL_ERROR "OS/DDS dependencies in the protocol core:\n${text}")
endif()
message(STATUS "${count} core files checked, none depends on the OS or DDS")
