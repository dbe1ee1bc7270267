// dnbridge: the DeviceNet-to-DDS bridge of one equipment rack, on SocketCAN.
#include "adapters/daemon/bridge_main.hpp"

int main(int argc, char** argv) { return dnbridge::daemon::bridge_main(argc, argv, {"dnbridge"}); }
