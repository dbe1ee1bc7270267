#pragma once
// A small streaming JSON writer for dnbctl's --json output: every command
// prints one document (watch prints one per line). Keys and strings are
// escaped per RFC 8259: UTF-8 is written as it is, a byte that is not UTF-8
// as \ufffd, controls as \u escapes; numbers are written exactly (integers) or with a
// fixed number of decimals (measured values).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dnbridge::dnbctl {

class JsonWriter {
 public:
  // `pretty`: one member per line, indented by two spaces; else compact.
  explicit JsonWriter(bool pretty = true) : pretty_(pretty) {}

  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  // The key of the next value, inside an object.
  JsonWriter& key(std::string_view name);

  JsonWriter& value(std::string_view s);
  JsonWriter& value(const char* s) { return value(std::string_view(s)); }
  JsonWriter& value(bool b);
  JsonWriter& value(std::int64_t n);
  JsonWriter& value(std::uint64_t n);
  JsonWriter& value(int n) { return value(static_cast<std::int64_t>(n)); }
  JsonWriter& value(unsigned n) { return value(static_cast<std::uint64_t>(n)); }
  JsonWriter& null();
  // Text that is already a JSON number ("-12"), written as it is.
  JsonWriter& number_text(std::string_view digits);
  // A measured value, rounded to `decimals` places ("5.001"); null if not finite.
  JsonWriter& number(double v, int decimals);

  template <class T>
  JsonWriter& field(std::string_view name, const T& v) {
    return key(name).value(v);
  }

  const std::string& str() const noexcept { return out_; }

 private:
  void before_value();
  void newline();
  JsonWriter& end_container(char close);

  bool pretty_;
  std::string out_;
  std::vector<bool> first_;  // per open container: nothing written in it yet
  bool after_key_ = false;
};

// `s` as a JSON string literal, quotes included.
std::string json_quote(std::string_view s);

}  // namespace dnbridge::dnbctl
