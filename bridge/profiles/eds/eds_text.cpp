#include "bridge/profiles/eds/eds_text.hpp"

#include <fmt/format.h>

namespace dnbridge::eds {
namespace {

bool is_blank(char c) noexcept {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

bool is_control(char c) noexcept {
  const auto u = static_cast<unsigned char>(c);
  return (u < 0x20 && !is_blank(c) && c != '\n') || u == 0x7F;
}

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

class Lexer {
 public:
  explicit Lexer(std::string_view in) : in_(in) {}

  Lexed run() {
    while (!at_end()) {
      const char c = peek();
      if (c == '\n' || is_blank(c)) {
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
    } else if (!is_blank(in_[i_])) {
      line_start_ = false;
    }
    ++i_;
  }
  void skip_line() noexcept {
    while (!at_end() && peek() != '\n') advance();
  }
  void problem(std::uint32_t line, std::string message) {
    if (out_.problems.size() < kMaxProblems) {
      out_.problems.push_back({line, Problem::Severity::kError, std::move(message)});
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
    while (!at_end() && peek() != ']' && peek() != '\n') advance();
    if (at_end() || peek() != ']') {
      problem(line, "a section header without its closing ']'");
      section_ = kNone;  // what follows belongs to no section we know
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
      } else if (is_blank(peek())) {
        advance();
      } else {
        problem(line, "text after a section header");
        skip_line();
      }
    }
  }

  // To the end of the entry: past its ';', or before a section header.
  void skip_entry() {
    bool in_string = false;
    while (!at_end()) {
      const char c = peek();
      if (c == '\n') in_string = false;
      if (!in_string && c == '$') {
        skip_line();
        continue;
      }
      if (!in_string && c == '[' && line_start_) return;
      if (c == '"') in_string = !in_string;
      advance();
      if (!in_string && c == ';') return;
    }
  }

  void entry() {
    const std::uint32_t line = line_;
    const std::size_t start = i_;
    while (!at_end() && peek() != '=' && peek() != '\n' && peek() != ';' && peek() != '$') {
      advance();
    }
    const std::string_view keyword = trim(in_.substr(start, i_ - start));
    if (at_end() || peek() != '=') {
      problem(line, fmt::format("\"{}\" is not an entry (Keyword = value;)", keyword));
      skip_entry();
      return;
    }
    advance();  // '='
    if (keyword.empty()) problem(line, "an entry with no keyword before its '='");
    Entry e{std::string(keyword), line, {}};
    const bool ended = fields(e);
    if (!ended) {
      problem(line, fmt::format("entry {} is not ended by ';'", e.keyword));
    }
    if (section_ == kNone) {
      problem(line, fmt::format("entry {} is not in a section", e.keyword));
      return;
    }
    out_.text.sections[section_].entries.push_back(std::move(e));
  }

  // The fields of an entry, up to its ';' (true) or a section header or the
  // end of the input (false).
  bool fields(Entry& e) {
    Field f;
    f.line = line_;
    std::string bare;
    bool bare_after_string = false;
    const auto finish = [&] {
      const std::string_view t = trim(bare);
      if (f.quoted) {
        if (!t.empty()) bare_after_string = true;
      } else {
        f.text = std::string(t);
      }
      if (bare_after_string) {
        problem(f.line, fmt::format("entry {}: text after a string in field {}", e.keyword,
                                    e.fields.size() + 1));
      }
      e.fields.push_back(std::move(f));
      f = Field{};
      f.line = line_;
      bare.clear();
      bare_after_string = false;
    };
    while (!at_end()) {
      const char c = peek();
      if (c == '$') {
        skip_line();
      } else if (c == '\n') {
        advance();
        if (!f.quoted && !trim(bare).empty()) bare += ' ';
      } else if (c == '[' && line_start_) {
        finish();
        return false;
      } else if (c == ',' || c == ';') {
        advance();
        finish();
        if (c == ';') return true;
      } else if (c == '"') {
        if (!f.quoted && !trim(bare).empty()) {
          problem(line_, fmt::format("entry {}: a string after text in field {}", e.keyword,
                                     e.fields.size() + 1));
        }
        if (!f.quoted) f.line = line_;
        f.quoted = true;
        string(f.text);
      } else {
        if (is_control(c)) control(c);
        if (f.quoted) {
          if (!is_blank(c)) bare_after_string = true;
        } else {
          if (trim(bare).empty() && !is_blank(c)) f.line = line_;
          bare += c;
        }
        advance();
      }
    }
    finish();
    return false;
  }

  // A quoted string, appended to `out`; it ends on its line.
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
  std::size_t section_ = kNone;  // index of the section entries go to
  Lexed out_;
};

}  // namespace

bool same_name(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c + 32) : c; };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

const Entry* Section::find(std::string_view keyword) const noexcept {
  for (const auto& e : entries) {
    if (same_name(e.keyword, keyword)) return &e;
  }
  return nullptr;
}

const Section* Text::find(std::string_view name) const noexcept {
  for (const auto& s : sections) {
    if (same_name(s.name, name)) return &s;
  }
  return nullptr;
}

Lexed lex(std::string_view input) { return Lexer(input).run(); }

}  // namespace dnbridge::eds
