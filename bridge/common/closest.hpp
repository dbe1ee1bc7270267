#pragma once
// "Did you mean ...?": the known word closest to a mistyped one, for the
// hints of the configuration's unknown keys and of dnbctl's commands and
// node names.
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>

namespace dnbridge {

// Levenshtein distance: the fewest single-character insertions, deletions
// and substitutions that turn `a` into `b`.
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate nearest to `word`, if one is at most `max_distance` edits
// away (the first of equally near ones); none when `word` is a candidate.
std::optional<std::string_view> closest(std::string_view word,
                                        std::span<const std::string_view> candidates,
                                        std::size_t max_distance = 2);

}  // namespace dnbridge
