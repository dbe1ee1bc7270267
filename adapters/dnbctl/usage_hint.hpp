#pragma once
// What to say when the command line was refused because of a mistyped
// command or option: "unknown command "lst" (did you mean "list"?)".
#include <CLI/CLI.hpp>
#include <span>
#include <string>

namespace dnbridge::dnbctl {

// The first word of `args` (argv without the program) that is neither a
// command nor an option of `app` or of its commands, said with the closest
// known one; empty if every word is known (the refusal was for something
// else, which CLI11's own message says).
std::string usage_hint(CLI::App& app, std::span<const char* const> args);

}  // namespace dnbridge::dnbctl
