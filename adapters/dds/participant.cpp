#include "adapters/dds/participant.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

#include "adapters/dds/qos.hpp"

namespace dnbridge::dds {

std::string participant_name(std::string_view rack) {
  std::string name = "dnbridge ";
  name += rack;
  return name;
}

namespace {

// Cyclone DDS says why it refuses a participant only in its log (with DDS
// Security, the plugin's exception: "Certificate expired", "Could not find
// domain 8 in governance"); dds_create_participant returns a bare error.
// While a participant is created, Cyclone's log sink is this one: it
// writes every line to stderr as Cyclone's own sink does, and keeps the
// errors logged by the creating thread, for the exception.
class ErrorCapture {
 public:
  ErrorCapture() : creator_(std::this_thread::get_id()) {
    dds_set_log_sink(&ErrorCapture::sink, this);
  }
  ~ErrorCapture() { dds_set_log_sink(nullptr, nullptr); }  // Cyclone's default again
  ErrorCapture(const ErrorCapture&) = delete;
  ErrorCapture& operator=(const ErrorCapture&) = delete;

  std::string errors() const {
    std::lock_guard lock(mutex_);
    return errors_;
  }

 private:
  static void sink(void* self, const dds_log_data_t* data) {
    // Cyclone's default sink: the header it formatted precedes the message.
    std::fwrite(data->message - data->hdrsize, 1, data->hdrsize + data->size + 1, stderr);
    std::fflush(stderr);
    static_cast<ErrorCapture*>(self)->keep(*data);
  }
  void keep(const dds_log_data_t& data) {
    if (data.priority != DDS_LC_ERROR || std::this_thread::get_id() != creator_) return;
    std::string_view text(data.message, data.size);
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.remove_suffix(1);
    std::lock_guard lock(mutex_);
    if (!errors_.empty()) errors_ += "; ";
    errors_ += text;
  }

  std::thread::id creator_;
  mutable std::mutex mutex_;
  std::string errors_;
};

// One creation at a time owns Cyclone's (process-wide) log sink.
std::mutex g_creating;

// `created` (an entity or an error), or Error saying what Cyclone logged.
dds_entity_t checked(dds_entity_t created, const std::string& errors,
                     const std::string& attempted) {
  if (created < 0 && !errors.empty()) {
    throw Error(attempted, created, "refused by Cyclone DDS: " + errors);
  }
  return check(created, attempted);
}

// The bridge's domain settings: Cyclone's high-water mark of a writer's
// unacknowledged data, fixed. Cyclone 0.10.2 makes a write wait once a
// writer holds more unacknowledged bytes than the mark (adaptive by default:
// from 1 KiB upwards, growing only while nothing is being resent) until they
// fall to 1 KiB. A reader that acknowledges nothing any more (topics.hpp)
// keeps them above that for good, and after any resend (a late reader's
// history, a lost packet) the mark stops growing: from then on every write
// of that writer waited and failed, for every reader (seen with a keep-all
// reply writer). The bridge's writers are all keep-last now, and Cyclone
// 0.10.2 gives keep-last writers no mark at all (src/core/ddsi/src/
// ddsi_endpoint.c): this fixed mark, 4 MiB, is for a keep-all writer, should
// one be added. The operator's CYCLONEDDS_URI (files
// and fragments, as Cyclone reads it) comes after and may override these.
constexpr const char* kBridgeDomainConfig =
    "<CycloneDDS><Domain id=\"any\"><Internal><Watermarks>"
    "<WhcAdaptive>false</WhcAdaptive>"
    "<WhcHighInit>4 MiB</WhcHighInit>"
    "<WhcHigh>4 MiB</WhcHigh>"
    "</Watermarks></Internal></Domain></CycloneDDS>";

// Creates `domain` with the bridge's settings, unless this process has
// joined it already (then its settings stay, and 0 is returned).
dds_entity_t create_bridge_domain(dds_domainid_t domain) {
  std::string errors;
  dds_entity_t created = 0;
  {
    ErrorCapture capture;
    std::string config = kBridgeDomainConfig;
    if (const char* uri = std::getenv("CYCLONEDDS_URI"); uri && *uri) {
      config += ',';
      config += uri;
    }
    created = dds_create_domain(domain, config.c_str());
    if (created < 0) errors = capture.errors();
  }
  if (created == DDS_RETCODE_PRECONDITION_NOT_MET) return 0;
  return checked(created, errors, "creating domain " + std::to_string(domain));
}

Participant::Created create_participant(dds_domainid_t domain, const std::string& name,
                                        const Properties& properties, bool bridge,
                                        std::string_view user_data) {
  Qos qos;
  qos.entity_name(name);
  if (!user_data.empty()) qos.userdata(std::as_bytes(std::span(user_data)));
  for (const auto& p : properties) qos.property(p.name, p.value);
  std::lock_guard lock(g_creating);
  Entity own_domain(bridge ? create_bridge_domain(domain) : 0);
  dds_entity_t participant = 0;
  std::string errors;
  {
    ErrorCapture capture;
    participant = dds_create_participant(domain, qos.get(), nullptr);
    if (participant < 0) errors = capture.errors();
  }
  participant =
      checked(participant, errors, "creating the participant of domain " + std::to_string(domain));
  return {participant, own_domain.release()};
}

}  // namespace

Participant::Participant(dds_domainid_t domain, std::string_view rack, const Properties& properties,
                         std::string_view user_data)
    : Participant(create_participant(domain, participant_name(rack), properties, true, user_data),
                  domain) {}

Participant::Participant(dds_domainid_t domain, ClientName client, const Properties& properties,
                         std::string_view user_data)
    : Participant(
          create_participant(domain, std::string(client.name), properties, false, user_data),
          domain) {}

std::string host_user_data(std::string_view version) {
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  std::string out = "host=";
  out += host;
  out += "\npid=" + std::to_string(getpid());
  out += "\nversion=";
  out += version;
  out += '\n';
  return out;
}

std::string user_data_field(std::string_view user_data, std::string_view key) {
  while (!user_data.empty()) {
    const auto end = user_data.find('\n');
    const std::string_view line = user_data.substr(0, end);
    if (line.size() > key.size() && line.starts_with(key) && line[key.size()] == '=') {
      return std::string(line.substr(key.size() + 1));
    }
    if (end == std::string_view::npos) break;
    user_data.remove_prefix(end + 1);
  }
  return {};
}

Participant::Participant(Created created, dds_domainid_t domain)
    : Entity(created.participant), domain_(domain), own_domain_(created.domain) {}

Participant::~Participant() {
  // Under the creation lock: a bridge participant created meanwhile must
  // not find the domain and then lose it.
  std::lock_guard lock(g_creating);
  reset();
  // The domain goes with the last participant in it, as one that Cyclone
  // created implicitly does. Left for Cyclone to tear down as the process
  // exits, a domain with DDS Security plugins loaded crashed the process.
  if (own_domain_ > 0 && dds_get_children(own_domain_, nullptr, 0) == 0) {
    (void)dds_delete(own_domain_);
  }
}

}  // namespace dnbridge::dds
