#include "bridge/profiles/eds/eds_text.hpp"

#include <fmt/format.h>

#include "bridge/common/text.hpp"

namespace dnbridge::profiles::eds {
namespace {

// A blank within a line (a newline ends one).
bool is_line_blank(char c) noexcept {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

bool is_control(char c) noexcept {
  const auto u = static_cast<unsigned char>(c);
  return (u < 0x20 && !is_line_blank(c) && c != '\n') || u == 0x7F;
}

class Lexer {
 public:
  explicit Lexer(std::string_view in) : in_(in) {
    if (in_.starts_with("\xEF\xBB\xBF")) i_ = 3;  // a UTF-8 byte order mark
  }

  Lexed run() {
    while (!at_end()) {
      const char c = peek();
      if (c == '\n' || is_line_blank(c)) {
        advance();
      } else if (c == '$') {
        skip_line();
      } else if (c == '[') {
        header();
      } else {
        entry();
      }
    }
    return std::move(out_);
  }

 private:
  bool at_end() const noexcept { return i_ >= in_.size(); }
  char peek() const noexcept { return in_[i_]; }
  void advance() noexcept {
    if (in_[i_] == '\n') {
      ++line_;
      line_start_ = true;
    } else if (!is_line_blank(in_[i_])) {
      line_start_ = false;
    }
    ++i_;
  }
  void skip_line() noexcept {
    while (!at_end() && peek() != '\n') advance();
  }
  void problem(std::uint32_t line, std::string message) {
    ++out_.errors;
    if (out_.problems.size() < kMaxProblemsKept) {
      out_.problems.push_back({line, Problem::Severity::kError, std::move(message)});
    } else {
      ++out_.not_kept;
    }
  }
  // Reports a control character once per line.
  void control(char c) {
    if (control_line_ == line_) return;
    control_line_ = line_;
    problem(line_, fmt::format("a control character (0x{:02X}) where text was expected",
                               static_cast<unsigned char>(c)));
  }

  void header() {
    const std::uint32_t line = line_;
    advance();  // '['
    const std::size_t start = i_;
    while (!at_end() && peek() != ']' && peek() != '\n') {
      if (is_control(peek())) control(peek());
      advance();
    }
    if (at_end() || peek() != ']') {
      problem(line, "a section header without its closing ']' (its entries are not read)");
      section_ = kLost;
      skip_line();
      return;
    }
    const std::string_view name = trim(in_.substr(start, i_ - start));
    advance();  // ']'
    if (name.empty()) problem(line, "a section header with no name");
    section_ = out_.text.sections.size();
    out_.text.sections.push_back(Section{std::string(name), line, {}});
    // The rest of the line: blanks, or a comment.
    while (!at_end() && peek() != '\n') {
      if (peek() == '$') {
        skip_line();
      } else if (is_line_blank(peek())) {
        advance();
      } else {
        problem(line, "text after a section header");
        skip_line();
      }
    }
  }

  void entry() {
    const std::uint32_t line = line_;
    const std::size_t start = i_;
    while (!at_end() && peek() != '=' && peek() != '\n' && peek() != ';' && peek() != '$') {
      if (is_control(peek())) control(peek());
      advance();
    }
    const std::string_view keyword = trim(in_.substr(start, i_ - start));
    if (at_end() || peek() != '=') {
      // A stray line: only it is passed over.
      problem(line, fmt::format("\"{}\" is not an entry (Keyword = value;)", keyword));
      if (!at_end() && peek() == ';') advance();
      skip_line();
      return;
    }
    advance();  // '='
    if (keyword.empty()) problem(line, "an entry with no keyword before its '='");
    Entry e{std::string(keyword), line, {}};
    if (!fields(e)) problem(line, fmt::format("entry {} is not ended by ';'", e.keyword));
    if (section_ == kLost) return;
    if (section_ == kNone) {
      problem(line, fmt::format("entry {} is not in a section", e.keyword));
      return;
    }
    out_.text.sections[section_].entries.push_back(std::move(e));
  }

  // The fields of an entry, up to its ';' or a string left open (true), or a
  // section header or the end of the input (false).
  bool fields(Entry& e) {
    Field f;
    f.line = line_;
    std::string bare;
    bool has_bare = false;         // bare text other than blanks
    std::uint32_t stray_line = 0;  // of text after a string
    const auto finish = [&] {
      if (stray_line != 0) {
        problem(stray_line, fmt::format("entry {}: text after a string in field {}", e.keyword,
                                        e.fields.size() + 1));
      }
      if (!f.quoted) f.text = std::string(trim(bare));
      e.fields.push_back(std::move(f));
      f = Field{};
      f.line = line_;
      bare.clear();
      has_bare = false;
      stray_line = 0;
    };
    while (!at_end()) {
      const char c = peek();
      if (c == '$') {
        skip_line();
      } else if (c == '\n') {
        advance();
        if (has_bare) bare += ' ';
      } else if (c == '[' && line_start_) {
        finish();
        return false;
      } else if (c == ',' || c == ';') {
        advance();
        finish();
        if (c == ';') return true;
      } else if (c == '"') {
        if (has_bare) {
          problem(line_, fmt::format("entry {}: a string after text in field {}", e.keyword,
                                     e.fields.size() + 1));
          bare.clear();
          has_bare = false;
        }
        if (!f.quoted) f.line = line_;
        f.quoted = true;
        string(f.text);
      } else {
        if (is_control(c)) control(c);
        if (f.quoted) {
          if (!is_line_blank(c) && stray_line == 0) stray_line = line_;
        } else {
          if (!has_bare && !is_line_blank(c)) {
            f.line = line_;
            has_bare = true;
          }
          bare += c;
        }
        advance();
      }
    }
    finish();
    return false;
  }

  // A quoted string, appended to `out`; it ends with its line at the latest.
  void string(std::string& out) {
    const std::uint32_t line = line_;
    advance();  // '"'
    while (!at_end() && peek() != '\n') {
      char c = peek();
      advance();
      if (c == '"') return;
      if (c == '\\' && !at_end() && (peek() == '"' || peek() == '\\')) {
        c = peek();
        advance();
      } else if (is_control(c)) {
        control(c);
      }
      out += c;
    }
    problem(line, "a string not closed on its line");
  }

  std::string_view in_;
  std::size_t i_ = 0;
  std::uint32_t line_ = 1;
  bool line_start_ = true;  // nothing but blanks since the line began
  std::uint32_t control_line_ = 0;
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  static constexpr std::size_t kLost = static_cast<std::size_t>(-2);
  // Where entries go: a section's index; kNone before the first section,
  // kLost after a header that could not be read.
  std::size_t section_ = kNone;
  Lexed out_;
};

}  // namespace

const Entry* Section::find(std::string_view keyword) const noexcept {
  for (const auto& e : entries) {
    if (iequals(e.keyword, keyword)) return &e;
  }
  return nullptr;
}

const Section* Text::find(std::string_view name) const noexcept {
  for (const auto& s : sections) {
    if (iequals(s.name, name)) return &s;
  }
  return nullptr;
}

Lexed lex(std::string_view input) { return Lexer(input).run(); }

}  // namespace dnbridge::profiles::eds
