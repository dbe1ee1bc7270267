#pragma once
// Names the calling thread, so that top -H, ps -L and debuggers tell the
// bridge's threads apart ("dds input", "sim bus"; port loops are named
// "port NAME" by PortLoop). Linux keeps 15 characters; the rest is cut.
#include <pthread.h>

#include <string>

namespace dnbridge::port {

inline void name_this_thread(const std::string& name) {
  (void)pthread_setname_np(pthread_self(), name.substr(0, 15).c_str());
}

}  // namespace dnbridge::port
