#pragma once
// Cyclone DDS pinned to this host: the loopback interface, no multicast,
// unicast discovery to 127.0.0.1 (as deploy/cyclonedds/loopback.xml).
// `dnbridge-sim --simulate` uses it when CYCLONEDDS_URI is not set; tests and the
// benchmark add a discovery tag of their own, so that participants of other
// runs on the same host are never matched.
#include <string>
#include <string_view>

namespace dnbridge::dds {

// Unicast discovery reaches participants 0..max_participants-1 of the host
// (one port each); more than that many on one domain need a larger figure.
inline std::string loopback_config(std::string_view discovery_tag = {}, int max_participants = 50) {
  std::string xml =
      "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/>"
      "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
      "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>" +
      std::to_string(max_participants) +
      "</MaxAutoParticipantIndex>"
      "<Peers><Peer address=\"127.0.0.1\"/></Peers>";
  if (!discovery_tag.empty()) {
    xml += "<Tag>";
    xml += discovery_tag;
    xml += "</Tag>";
  }
  xml += "</Discovery></Domain></CycloneDDS>";
  return xml;
}

}  // namespace dnbridge::dds
