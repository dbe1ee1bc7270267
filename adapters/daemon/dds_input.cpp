#include "adapters/daemon/dds_input.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "adapters/daemon/samples.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/port/steady_time.hpp"
#include "adapters/port/thread_name.hpp"

namespace dnbridge::daemon {
namespace {

enum Token : dds::WaitSet::Token { kCommands = 1, kRequests = 2, kStop = 3 };

// Samples taken at a time.
constexpr std::size_t kBatch = 32;

// Takes every sample the reader holds, a buffer at a time (taking resets
// DATA_AVAILABLE while samples may remain, so a full buffer is followed by
// another take), and hands each to `fn`.
template <class T, class Fn>
void take_all(const dds::Reader<T>& reader, dds::TakeBuffer<T>& buffer, Logger& log,
              const char* what, Fn fn) {
  for (;;) {
    auto taken = reader.take(buffer);
    if (!taken) {
      log.error("taking {} failed: {}", what, taken.error().message());
      return;
    }
    for (std::size_t i = 0; i < *taken; ++i) fn(buffer.data(i), buffer.info(i));
    if (*taken < buffer.capacity()) return;
  }
}

}  // namespace

DdsInput::DdsInput(const dds::Participant& participant, DdsPublisher& publisher, std::string rack,
                   std::map<std::string, port::PortLoop*> ports, Logger log)
    : rack_(std::move(rack)),
      publisher_(publisher),
      ports_(std::move(ports)),
      log_(std::move(log)),
      commands_(participant, publisher.command_topic(), dds::command_reader_qos()),
      requests_(participant, publisher.request_topic(), dds::request_reader_qos()),
      command_buffer_(kBatch),
      request_buffer_(kBatch),
      stop_(participant),
      waitset_(participant) {
  // A reader's status condition stays triggered while any status in its mask
  // is set, and taking resets only DATA_AVAILABLE: with the default mask
  // (every status) a matched writer's SUBSCRIPTION_MATCHED, never read here,
  // would keep the waitset triggered and this thread spinning.
  for (const dds::Entity* reader :
       {static_cast<const dds::Entity*>(&commands_), static_cast<const dds::Entity*>(&requests_)}) {
    if (!reader->set_status_mask(DDS_DATA_AVAILABLE_STATUS)) {
      throw std::runtime_error("setting the status mask of a DDS input reader failed");
    }
  }
  waitset_.attach(commands_, kCommands);
  waitset_.attach(requests_, kRequests);
  waitset_.attach(stop_, kStop);
}

DdsInput::~DdsInput() { stop(); }

void DdsInput::start() {
  thread_ = std::thread([this] { run(); });
  port::name_thread(thread_, "dds input");
}

void DdsInput::stop() {
  if (!thread_.joinable()) return;
  (void)stop_.trigger();
  thread_.join();
}

port::PortLoop* DdsInput::port_of(std::string_view name) {
  auto it = ports_.find(std::string(name));
  return it == ports_.end() ? nullptr : it->second;
}

void DdsInput::run() {
  for (;;) {
    auto triggered = waitset_.wait(seconds(1));
    if (!triggered) {
      log_.error("waiting for DDS input failed: {}", triggered.error().message());
      continue;
    }
    for (auto token : *triggered) {
      if (token == kStop) return;
      if (token == kCommands) take_commands();
      if (token == kRequests) take_requests();
    }
  }
}

void DdsInput::take_commands() {
  take_all(commands_, command_buffer_, log_, "pump commands",
           [this](const dnbridge_PumpCommand& c, const dds::SampleInfo& info) {
             on_command(c, info);
           });
}

void DdsInput::on_command(const dnbridge_PumpCommand& c, const dds::SampleInfo& info) {
  if (dds::view(c.rack) != rack_) return;  // another bridge's pump
  port::PortLoop* loop = port_of(dds::view(c.port));
  const auto mac = devicenet::MacId::from(c.mac);
  if (!loop || !mac || !loop->has_node(*mac)) {
    unsigned suppressed = 0;
    if (warn_limit_.allow(port::steady_now(), suppressed)) {
      log_.warn("command{} for port \"{}\" MAC {} refused: not in this rack's configuration",
                info.valid_data() ? fmt::format(" from {}", dds::view(c.issuer)) : "",
                dds::view(c.port), c.mac);
    }
    return;
  }
  // No live commander left for this pump (all writers gone, or disposed):
  // idle. A command taken after its writer left carries that state itself,
  // with no sample of its own to tell it; it is not applied: a commander
  // that is gone commands nothing, not even for a moment.
  if (info.instance_state() != dds::InstanceState::kAlive) {
    loop->release_command(*mac);
    return;
  }
  if (info.valid_data()) loop->command(*mac, outputs_of(c), std::string(dds::view(c.issuer)));
}

void DdsInput::take_requests() {
  take_all(requests_, request_buffer_, log_, "explicit requests",
           [this](const dnbridge_ExplicitRequest& r, const dds::SampleInfo& info) {
             if (info.valid_data()) on_request(r);
           });
}

void DdsInput::on_request(const dnbridge_ExplicitRequest& r) {
  if (dds::view(r.rack) != rack_) return;
  rack::ExplicitCall call = call_of(r);
  port::PortLoop* loop = port_of(call.port);
  if (!loop) {
    publisher_.explicit_reply(
        {}, rack::refuse(call, rack::TransactionStatus::kInvalidPort,
                         fmt::format("rack {} has no port \"{}\"", rack_, call.port)));
    return;
  }
  loop->explicit_request(std::move(call));
}

}  // namespace dnbridge::daemon
