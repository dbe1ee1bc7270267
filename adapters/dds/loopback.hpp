#pragma once
// Cyclone DDS pinned to this host: the loopback interface, no multicast,
// unicast discovery to 127.0.0.1 (as deploy/cyclonedds/loopback.xml).
// `dnbridge-sim --simulate` uses it when CYCLONEDDS_URI is not set; tests and the
// benchmark add a discovery tag of their own, so that participants of other
// runs on the same host are never matched.
#include <string>
#include <string_view>

namespace dnbridge::dds {

inline std::string loopback_config(std::string_view discovery_tag = {}) {
  std::string xml =
      "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/>"
      "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
      "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>50</MaxAutoParticipantIndex>"
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
