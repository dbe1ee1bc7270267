#include "adapters/dds/participant.hpp"

#include <cstdio>
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

dds_entity_t create_participant(dds_domainid_t domain, const std::string& name,
                                const Properties& properties) {
  Qos qos;
  qos.entity_name(name);
  for (const auto& p : properties) qos.property(p.name, p.value);
  std::lock_guard lock(g_creating);
  dds_entity_t participant = 0;
  std::string errors;
  {
    ErrorCapture capture;
    participant = dds_create_participant(domain, qos.get(), nullptr);
    if (participant < 0) errors = capture.errors();
  }
  const std::string attempted = "creating the participant of domain " + std::to_string(domain);
  if (participant < 0 && !errors.empty()) {
    throw Error(attempted, participant, "refused by Cyclone DDS: " + errors);
  }
  return check(participant, attempted);
}

}  // namespace

Participant::Participant(dds_domainid_t domain, std::string_view rack, const Properties& properties)
    : Entity(create_participant(domain, participant_name(rack), properties)), domain_(domain) {}

Participant::Participant(dds_domainid_t domain, ClientName client, const Properties& properties)
    : Entity(create_participant(domain, std::string(client.name), properties)), domain_(domain) {}

}  // namespace dnbridge::dds
