// config_keys_roff OUTPUT: writes dnbridge.toml(5)'s key reference, generated
// from the rack file's key table (config_keys.hpp), for the man page's
// rendering at build time (deploy/man/render.cmake).
#include <cstdio>
#include <fstream>
#include <iostream>

#include "adapters/daemon/config_keys.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: config_keys_roff OUTPUT\n";
    return 2;
  }
  std::ofstream out(argv[1], std::ios::binary | std::ios::trunc);
  out << dnbridge::daemon::key_reference_roff();
  out.close();
  if (!out) {
    std::cerr << "config_keys_roff: cannot write " << argv[1] << "\n";
    return 1;
  }
  return 0;
}
