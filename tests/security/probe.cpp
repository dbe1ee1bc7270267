// dnbridge_security_probe: a DDS participant of its own process, for the
// security tests (participants of one process share Cyclone's domain and
// reach each other without DDS Security's checks, so each identity under
// test is a process of its own). It joins the domain, with the [security]
// table of --security FILE or without any, reads PumpState and, with
// --command MAC, commands that pump again and again (pump on, N2 ballast on,
// analog out 1234) every 100 ms for --seconds, and then says what it could
// do and saw, one "key: value" a line:
//
//   participant: created | refused: WHY
//   state_reader: created | refused: WHY
//   command_writer: created | refused: WHY   (with --command)
//   commands_written: N
//   command_readers_matched: N   (most readers its writer was matched with)
//   pumpstate_samples: N         (valid samples taken)
//   first_online_ms: T           (first sample of a pump online, from the start; -1 if none)
//   window_ms: T                 (with --start-file: how long it ran after seeing the
//                                 file; -1 if it never did)
//
// --until-online: it ends at the first sample of a pump online (--seconds
// bounds the wait). --start-file FILE: the --seconds count from when it sees
// FILE (looked for every 100 ms; not seen within kStartFileWait, it ends),
// so that another process decides when its window begins; it is on the
// domain, reading and commanding, from its start to its end all the same.
//
// Exit code 0 when it ran (whatever it was refused), 2 on a bad command line
// or a security file it cannot use.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/reader.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topic.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dds/waitset.hpp"
#include "adapters/dds/writer.hpp"
#include "adapters/security/check.hpp"
#include "adapters/security/toml_settings.hpp"

namespace {

using namespace dnbridge;
using Clock = std::chrono::steady_clock;

// The longest --start-file waits for its file: a test that never makes it
// does not leave the probe running.
constexpr auto kStartFileWait = std::chrono::seconds(60);

struct Options {
  dds_domainid_t domain = 0;
  std::string security;
  double seconds = 3;
  std::optional<unsigned> command;
  bool until_online = false;
  std::filesystem::path start_file;
};

std::optional<Options> parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view key = argv[i];
    if (key == "--until-online") {
      o.until_online = true;
      continue;
    }
    if (i + 1 == argc) return std::nullopt;
    const char* value = argv[++i];
    if (key == "--domain") {
      o.domain = static_cast<dds_domainid_t>(std::atoi(value));
    } else if (key == "--security") {
      o.security = value;
    } else if (key == "--seconds") {
      o.seconds = std::atof(value);
    } else if (key == "--command") {
      o.command = static_cast<unsigned>(std::atoi(value));
    } else if (key == "--start-file") {
      o.start_file = value;
    } else {
      return std::nullopt;
    }
  }
  if (o.seconds <= 0) return std::nullopt;
  return o;
}

void say(const char* key, const std::string& value) { std::printf("%s: %s\n", key, value.c_str()); }

// Makes an entity, or says why it was refused.
template <class T, class Make>
std::unique_ptr<T> attempt(const char* key, Make make) {
  try {
    auto entity = make();
    say(key, "created");
    return entity;
  } catch (const dds::Error& e) {
    say(key, std::string("refused: ") + e.what());
    return nullptr;
  }
}

}  // namespace

int main(int argc, char** argv) {
  const auto options = parse(argc, argv);
  if (!options) {
    std::fprintf(stderr,
                 "usage: dnbridge_security_probe --domain D [--security FILE] [--seconds S] "
                 "[--command MAC] [--until-online] [--start-file FILE]\n");
    return 2;
  }
  dds::Properties properties;
  if (!options->security.empty()) {
    try {
      auto settings = security::load_file(options->security);
      (void)security::check(settings);
      properties = security::participant_properties(settings);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return 2;
    }
  }

  const auto start = Clock::now();
  auto participant = attempt<dds::Participant>("participant", [&] {
    return std::make_unique<dds::Participant>(
        options->domain, dds::Participant::ClientName{"security probe"}, properties);
  });
  if (!participant) return 0;
  std::unique_ptr<dds::Topic<dnbridge_PumpState>> state_topic;
  auto state_reader = attempt<dds::Reader<dnbridge_PumpState>>("state_reader", [&] {
    state_topic = std::make_unique<dds::Topic<dnbridge_PumpState>>(*participant);
    return std::make_unique<dds::Reader<dnbridge_PumpState>>(*participant, *state_topic,
                                                             dds::state_reader_qos());
  });
  std::unique_ptr<dds::Topic<dnbridge_PumpCommand>> command_topic;
  std::unique_ptr<dds::Writer<dnbridge_PumpCommand>> command_writer;
  if (options->command) {
    command_writer = attempt<dds::Writer<dnbridge_PumpCommand>>("command_writer", [&] {
      command_topic = std::make_unique<dds::Topic<dnbridge_PumpCommand>>(*participant);
      return std::make_unique<dds::Writer<dnbridge_PumpCommand>>(
          *participant, *command_topic,
          dds::command_writer_qos(dds::rack_partitions("sim-rack"), 10, seconds(1)));
    });
  }

  dds::WaitSet waitset(*participant);
  std::optional<dds::ReadCondition> fresh;
  if (state_reader) {
    fresh.emplace(*state_reader, DDS_ANY_STATE);
    waitset.attach(*fresh, 1);
  }
  dds::Owned<dnbridge_PumpCommand> command;
  dds::set_string(command->rack, "sim-rack");
  dds::set_string(command->port, "A");
  command->mac = static_cast<std::uint8_t>(options->command.value_or(0));
  command->pump_on = true;
  command->n2_ballast_on = true;
  command->analog_output_raw = 1234;
  dds::set_string(command->issuer, "security probe");

  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options->seconds));
  // Without --start-file the window is the whole run.
  std::optional<Clock::time_point> window_start;
  if (options->start_file.empty()) window_start = start;
  const auto give_up = start + kStartFileWait;
  auto next_command = start;
  unsigned written = 0;
  std::uint32_t readers_matched = 0;
  unsigned samples = 0;
  double first_online_ms = -1;
  const auto take_state = [&] {
    if (!state_reader) return;
    auto taken = state_reader->take();
    if (!taken.ok()) return;
    for (const auto& s : *taken) {
      if (!s.valid_data()) continue;
      ++samples;
      if (s->online && first_online_ms < 0) {
        first_online_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      }
    }
  };
  for (;;) {
    take_state();
    const auto now = Clock::now();
    if (options->until_online && first_online_ms >= 0) break;
    if (!window_start) {
      if (std::filesystem::exists(options->start_file)) {
        window_start = now;
      } else if (now >= give_up) {
        break;
      }
    }
    const auto end = window_start ? *window_start + period : give_up;
    if (now >= end) break;
    if (command_writer && now >= next_command) {
      if (command_writer->write(*command).ok()) ++written;
      if (auto m = command_writer->matched_subscriptions(); m.ok() && *m > readers_matched) {
        readers_matched = *m;
      }
      next_command = now + std::chrono::milliseconds(100);
    }
    // Woken by PumpState, at the next command, or to look for the start
    // file; never past the end.
    auto wake = end;
    if (command_writer) wake = std::min(wake, next_command);
    if (!window_start) wake = std::min(wake, now + std::chrono::milliseconds(100));
    (void)waitset.wait(std::max<Duration>(std::chrono::duration_cast<Duration>(wake - Clock::now()),
                                          milliseconds(1)));
  }
  const auto ended = Clock::now();
  say("commands_written", std::to_string(written));
  say("command_readers_matched", std::to_string(readers_matched));
  say("pumpstate_samples", std::to_string(samples));
  say("first_online_ms", std::to_string(static_cast<long>(first_online_ms)));
  if (!options->start_file.empty()) {
    const auto window =
        window_start ? ended - *window_start : Clock::duration(std::chrono::milliseconds(-1));
    say("window_ms",
        std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(window).count()));
  }
  return 0;
}
