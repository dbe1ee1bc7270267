#include "adapters/dnbctl/usage_hint.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string_view>
#include <vector>

#include "bridge/common/closest.hpp"

namespace dnbridge::dnbctl {
namespace {

struct Known {
  std::vector<std::string> commands;
  std::vector<std::string> options;         // "--name", of the program and every command
  std::vector<std::string> valued_options;  // those that take a value
};

void add_options(const CLI::App& app, Known& known) {
  for (const CLI::Option* opt : app.get_options()) {
    for (const auto& name : opt->get_lnames()) {
      known.options.push_back("--" + name);
      if (opt->get_expected_min() > 0) known.valued_options.push_back("--" + name);
    }
  }
}

std::string hint(std::string_view what, std::string_view word,
                 const std::vector<std::string>& among) {
  const std::vector<std::string_view> views(among.begin(), among.end());
  const auto near = closest(word, views, 3);
  return fmt::format("unknown {} \"{}\"{}", what, word,
                     near ? fmt::format(" (did you mean \"{}\"?)", *near) : std::string{});
}

bool contains(const std::vector<std::string>& v, std::string_view s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

}  // namespace

std::string usage_hint(CLI::App& app, std::span<const char* const> args) {
  Known known;
  add_options(app, known);
  for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    known.commands.push_back(sub->get_name());
    add_options(*sub, known);
  }
  bool command_seen = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view word = args[i];
    if (word.starts_with("--")) {
      const std::string_view name = word.substr(0, word.find('='));
      if (!contains(known.options, name)) return hint("option", name, known.options);
      if (name.size() == word.size() && contains(known.valued_options, name)) ++i;  // its value
    } else if (!word.starts_with("-") && !command_seen) {
      if (!contains(known.commands, word)) {
        return hint("command", word, known.commands) + "; dnbctl --help lists them";
      }
      command_seen = true;
    }
  }
  return {};
}

}  // namespace dnbridge::dnbctl
