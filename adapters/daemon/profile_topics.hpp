#pragma once
// Each profile's DDS topics, as the publisher (DdsPublisher) and the input
// (DdsInput) use them whatever the profile:
//   - its state topic: a writer, the node's sample and the profile's part of
//     NodeStatus filled from the node's view;
//   - its command topic: readers, on the topic or on one filtered to a
//     node, and a sample read as the rack::NodeCommand the profile's rack
//     takes.
// bridge_profiles() (profile_topics.cpp) is the registration: one line per
// profile, made by topics_of from the profile's IDL types, its rack's view
// and its three functions of samples.hpp (ProfileSamples).
#include <fmt/format.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "adapters/daemon/unless_denied.hpp"
#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/time.hpp"
#include "adapters/dds/topic.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/port/port_publisher.hpp"
#include "bridge/common/log.hpp"
#include "bridge/rack/node_view.hpp"
#include "bridge/rack/profile_nodes.hpp"
#include "dnbridge.h"

namespace dnbridge::daemon {

// A node's instance of a topic keyed by rack, port and MAC.
template <class T>
dds::Owned<T> key_of(const std::string& rack, const std::string& port, std::uint8_t mac) {
  dds::Owned<T> key;
  dds::set_string(key->rack, rack);
  dds::set_string(key->port, port);
  key->mac = mac;
  return key;
}

// A profile's state topic: its writer, and how its sample and its part of
// NodeStatus are filled.
class StateTopic {
 public:
  virtual ~StateTopic() = default;
  virtual std::string_view profile() const = 0;
  virtual const char* name() const = 0;
  // The node's state sample (no writer, when DDS Security does not grant
  // the topic: nothing, OK).
  virtual Status write(const std::string& rack, const std::string& port, const rack::NodeView& node,
                       dds::Timestamp at) = 0;
  // The node's NodeStatus, its profile's part included.
  virtual void fill_status(dnbridge_NodeStatus& out, const std::string& rack,
                           const std::string& port, const rack::NodeView& node,
                           const port::NodeStatusView& status) const = 0;
  virtual Status dispose(const std::string& rack, const std::string& port, std::uint8_t mac,
                         dds::Timestamp at) = 0;
  virtual Status unregister(const std::string& rack, const std::string& port, std::uint8_t mac,
                            dds::Timestamp at) = 0;
  virtual void wait_for_acks(Duration timeout) = 0;
};

// A command sample of any command topic, as the input takes it: valid only
// during the call it is handed to (its views and its outputs' source are the
// reader's take buffer); never kept.
struct CommandSample {
  std::string_view topic;    // "dnbridge/PumpCommand"
  std::string_view profile;  // the profile whose nodes the topic commands
  std::string_view rack, port;
  std::uint8_t mac = 0;
  std::string_view issuer;
  const dds::SampleInfo& info;
  // The outputs, in the form the profile's rack takes them (a sample with
  // data only).
  std::function<rack::NodeCommand()> outputs;
};

// One reader of a command topic, with what it takes samples into.
class CommandReader {
 public:
  virtual ~CommandReader() = default;
  // Takes every sample waiting and hands each to `on_sample`; a failed take
  // is logged on `log`.
  virtual void take(Logger& log, const std::function<void(const CommandSample&)>& on_sample) = 0;
  virtual const dds::Entity& entity() const = 0;
};

// The node a reader of its own takes the commands of.
struct CommandedNode {
  std::string rack, port;
  std::uint8_t mac = 0;
};

// A profile's command topic, which makes its readers.
class CommandTopic {
 public:
  virtual ~CommandTopic() = default;
  virtual std::string_view profile() const = 0;
  virtual std::string_view name() const = 0;
  // A reader of it that DDS Security does not grant is an error
  // (ProfileTopics::required).
  virtual bool required() const = 0;
  // A reader for every node (`node` null) or for one node, on a topic entity
  // of its own filtered to it (`node` must outlive the reader). Throws
  // dds::Error.
  virtual std::unique_ptr<CommandReader> reader(const dds::Participant& participant,
                                                const dds::Qos& qos, const dds_listener_t* listener,
                                                const CommandedNode* node) const = 0;
};

// One profile's topics, as the bridge makes them for its participant.
struct ProfileTopics {
  std::string_view profile;  // its name in the rack file: "cdn127", "eds"
  std::string_view state_topic, command_topic;
  // Whether the bridge needs them to run: a state writer or command reader
  // DDS Security does not grant is then an error (thrown); otherwise the
  // bridge runs without it and says so (unless_denied).
  bool required = false;
  std::function<std::unique_ptr<StateTopic>(const dds::Participant& participant,
                                            const dds::Qos& qos, Logger& log)>
      make_state;
  // Throws dds::Error.
  std::function<std::unique_ptr<CommandTopic>(const dds::Participant& participant)> make_command;
};

// Every profile the bridge publishes and takes commands for.
std::span<const ProfileTopics> bridge_profiles();

// How a profile's samples are filled and read: State is its state topic's
// type, filled from View (its rack's node view); Command is its command
// topic's type.
template <class State, class View, class Command>
struct ProfileSamples {
  void (*fill_state)(State& out, std::string_view rack, std::string_view port, const View& node);
  void (*fill_status)(dnbridge_NodeStatus& out, std::string_view rack, std::string_view port,
                      const View& node, const port::NodeStatusView& status);
  rack::NodeCommand (*command_of)(const Command& command);
};

// A profile's topics (`profile`: a string of static storage, its rack's
// kName).
template <class State, class View, class Command>
ProfileTopics topics_of(std::string_view profile, bool required,
                        ProfileSamples<State, View, Command> samples);

// --- how topics_of makes them -------------------------------------------------

namespace profile_topics_detail {

// Samples taken at a time.
inline constexpr std::size_t kCommandBatch = 32;

template <class State, class View, class Command>
class TypedStateTopic final : public StateTopic {
 public:
  using Samples = ProfileSamples<State, View, Command>;
  TypedStateTopic(const dds::Participant& participant, const dds::Qos& qos, Logger& log,
                  std::string_view profile, bool required, Samples samples)
      : profile_(profile), samples_(samples) {
    const auto make = [&] { return Out(participant, qos); };
    if (required) {
      out_.emplace(participant, qos);
    } else {
      out_ = unless_denied(log, fmt::format("the state of profile \"{}\" ({})", profile, name()),
                           make);
    }
  }
  std::string_view profile() const override { return profile_; }
  const char* name() const override { return dds::TopicTraits<State>::kName; }
  Status write(const std::string& rack, const std::string& port, const rack::NodeView& node,
               dds::Timestamp at) override {
    if (!out_) return {};
    dds::Owned<State> sample;
    samples_.fill_state(*sample, rack, port, static_cast<const View&>(node));
    return out_->writer.write(*sample, at);
  }
  void fill_status(dnbridge_NodeStatus& out, const std::string& rack, const std::string& port,
                   const rack::NodeView& node, const port::NodeStatusView& status) const override {
    samples_.fill_status(out, rack, port, static_cast<const View&>(node), status);
  }
  Status dispose(const std::string& rack, const std::string& port, std::uint8_t mac,
                 dds::Timestamp at) override {
    if (!out_) return {};
    return out_->writer.dispose(*key_of<State>(rack, port, mac), at);
  }
  Status unregister(const std::string& rack, const std::string& port, std::uint8_t mac,
                    dds::Timestamp at) override {
    if (!out_) return {};
    return out_->writer.unregister_instance(*key_of<State>(rack, port, mac), at);
  }
  void wait_for_acks(Duration timeout) override {
    if (out_) (void)out_->writer.wait_for_acks(timeout);
  }

 private:
  struct Out {
    Out(const dds::Participant& participant, const dds::Qos& qos)
        : topic(participant), writer(participant, topic, qos) {}
    dds::Topic<State> topic;
    dds::Writer<State> writer;
  };
  std::string_view profile_;
  Samples samples_;
  std::optional<Out> out_;
};

// The filter of a node's own command readers.
template <class Command>
bool commands_node(const Command& c, const void* node) {
  const auto& n = *static_cast<const CommandedNode*>(node);
  return c.mac == n.mac && dds::view(c.port) == n.port && dds::view(c.rack) == n.rack;
}

template <class Command>
class TypedCommandTopic final : public CommandTopic {
 public:
  using Read = rack::NodeCommand (*)(const Command&);
  TypedCommandTopic(const dds::Participant& participant, std::string_view profile, bool required,
                    Read read)
      : profile_(profile), required_(required), read_(read), topic_(participant) {}

  std::string_view profile() const override { return profile_; }
  std::string_view name() const override { return dds::TopicTraits<Command>::kName; }
  bool required() const override { return required_; }

  std::unique_ptr<CommandReader> reader(const dds::Participant& participant, const dds::Qos& qos,
                                        const dds_listener_t* listener,
                                        const CommandedNode* node) const override {
    auto made = std::make_unique<Reader>(profile_, read_);
    const dds::Topic<Command>* topic = &topic_;
    if (node) {
      made->filtered.emplace(participant);
      made->filtered->filter(&commands_node<Command>, node);
      topic = &*made->filtered;
    }
    made->reader.emplace(participant, *topic, qos, listener);
    return made;
  }

 private:
  struct Reader final : CommandReader {
    Reader(std::string_view p, Read r) : profile(p), read(r) {}
    std::string_view profile;
    Read read;
    std::optional<dds::Topic<Command>> filtered;  // before the reader: it outlives it
    std::optional<dds::Reader<Command>> reader;
    dds::TakeBuffer<Command> buffer{kCommandBatch};

    void take(Logger& log, const std::function<void(const CommandSample&)>& on_sample) override {
      // Taking resets DATA_AVAILABLE while samples may remain: a full buffer
      // is followed by another take.
      for (;;) {
        auto taken = reader->take(buffer);
        if (!taken) {
          log.error("taking {} failed: {}", dds::TopicTraits<Command>::kName,
                    taken.error().message());
          return;
        }
        for (std::size_t i = 0; i < *taken; ++i) {
          const Command& c = buffer.data(i);
          on_sample(CommandSample{dds::TopicTraits<Command>::kName, profile, dds::view(c.rack),
                                  dds::view(c.port), c.mac, dds::view(c.issuer), buffer.info(i),
                                  [this, &c] { return read(c); }});
        }
        if (*taken < buffer.capacity()) return;
      }
    }
    const dds::Entity& entity() const override { return *reader; }
  };
  std::string_view profile_;
  bool required_;
  Read read_;
  dds::Topic<Command> topic_;
};

}  // namespace profile_topics_detail

template <class State, class View, class Command>
ProfileTopics topics_of(std::string_view profile, bool required,
                        ProfileSamples<State, View, Command> samples) {
  using namespace profile_topics_detail;
  ProfileTopics t;
  t.profile = profile;
  t.state_topic = dds::TopicTraits<State>::kName;
  t.command_topic = dds::TopicTraits<Command>::kName;
  t.required = required;
  t.make_state = [profile, required, samples](const dds::Participant& participant,
                                              const dds::Qos& qos,
                                              Logger& log) -> std::unique_ptr<StateTopic> {
    return std::make_unique<TypedStateTopic<State, View, Command>>(participant, qos, log, profile,
                                                                   required, samples);
  };
  t.make_command = [profile, required, read = samples.command_of](
                       const dds::Participant& participant) -> std::unique_ptr<CommandTopic> {
    return std::make_unique<TypedCommandTopic<Command>>(participant, profile, required, read);
  };
  return t;
}

}  // namespace dnbridge::daemon
