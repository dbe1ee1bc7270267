#pragma once
// The text of an Electronic Data Sheet (EDS), the file a DeviceNet device's
// vendor ships to describe it, as sections of entries, each with the line it
// is on. The format as EDS files are written:
//
//   $ a comment, to the end of the line (outside a string)
//   [Section Name]
//   Keyword = field, field, ... ;      an entry, over as many lines as it needs
//
// A field is a quoted string ("..." with \" and \\ escapes; strings side by
// side are one, "ab" "cd" is "abcd"), or the bare text up to the next comma
// or semicolon with the blanks around it removed (numbers, dates, references
// such as Param1), or nothing (an empty field: `1,,3`). Section names and
// keywords are compared without regard to case. What the sections mean is
// eds_file.hpp's.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dnbridge::profiles::eds {

// Something wrong in the file, at a line (1-based). An error leaves the file
// unusable; a warning names what was skipped or assumed.
struct Problem {
  enum class Severity : std::uint8_t { kError, kWarning };
  std::uint32_t line = 0;
  Severity severity = Severity::kError;
  std::string message;
};

struct Field {
  std::string text;
  bool quoted = false;
  std::uint32_t line = 0;
  bool empty() const noexcept { return !quoted && text.empty(); }
};

struct Entry {
  std::string keyword;
  std::uint32_t line = 0;
  std::vector<Field> fields;
};

struct Section {
  std::string name;
  std::uint32_t line = 0;
  std::vector<Entry> entries;
  // The first entry of that keyword; nullptr when there is none.
  const Entry* find(std::string_view keyword) const noexcept;
};

struct Text {
  std::vector<Section> sections;
  // The first section of that name; nullptr when there is none.
  const Section* find(std::string_view name) const noexcept;
};

// Reading goes on after a problem (from the next entry or section), so that
// one pass finds every one; at most kMaxProblems are shown (errors first),
// and at most kMaxProblemsKept are kept while reading.
inline constexpr std::size_t kMaxProblems = 50;
inline constexpr std::size_t kMaxProblemsKept = 10000;

struct Lexed {
  Text text;
  std::vector<Problem> problems;  // the first kMaxProblemsKept
  std::size_t errors = 0;         // all of them, kept or not
  std::size_t not_kept = 0;       // problems past kMaxProblemsKept
};

// Problems found here: a string not closed on its line (it ends there, its
// entry goes on), a line with no '=' (passed over), an entry not ended by ';' before
// the next section or the end, an entry before the first section, a section
// header without its ']' (its entries are passed over), a control character.
// A UTF-8 byte order mark at the start is skipped.
Lexed lex(std::string_view input);

}  // namespace dnbridge::profiles::eds
