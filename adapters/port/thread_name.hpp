#pragma once
// Names a thread, so that top -H, ps -L, gdb and /proc/PID/task/*/comm tell
// the bridge's threads apart ("port A", "dds input", "sd_notify", "sim bus").
// Linux keeps 15 characters; the rest is cut.
#include <pthread.h>

#include <string>
#include <thread>

namespace dnbridge::port {

inline void name_thread(std::thread& thread, const std::string& name) {
  (void)pthread_setname_np(thread.native_handle(), name.substr(0, 15).c_str());
}

}  // namespace dnbridge::port
