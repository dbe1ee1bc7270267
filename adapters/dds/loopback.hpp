#pragma once
// Cyclone DDS pinned to this host: the loopback interface, no multicast,
// unicast discovery to 127.0.0.1 (the same as deploy/cyclonedds/loopback.xml).
// `dnbridge --simulate` and `dnbctl --loopback` use it when CYCLONEDDS_URI is
// not set, so that the two find each other without touching the network.
namespace dnbridge::dds {

inline constexpr const char* kLoopbackConfig =
    "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/>"
    "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
    "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex>"
    "<Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery></Domain></CycloneDDS>";

}  // namespace dnbridge::dds
