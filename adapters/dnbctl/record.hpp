#pragma once
// A record as dnbctl shows it, described once: an ordered list of fields,
// each with its JSON members (typed) and its text for people (a label and
// the value as it reads). A record's JSON object, its detail lines and its
// row in a table are all made from that one list, so they cannot disagree
// on what the record holds.
//
// A field may be text only (a column such as "BRIDGE live"), JSON only (a
// counter the table has no room for), or one line of text for several
// members ("revision 1.5" and major_revision, minor_revision).
#include <concepts>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "adapters/dnbctl/json.hpp"

namespace dnbridge::dnbctl {

class Record;

// A measured value, written with a fixed number of decimals (null if not
// finite).
struct Decimal {
  double value = 0;
  int places = 0;
};

// A JSON value: null, a boolean, an integer, a measured value, a real, a
// string, a number already in JSON's form, an object (a record), an array of
// objects or an array of values.
class Json {
 public:
  Json() = default;
  Json(std::nullptr_t) {}
  Json(bool b) : value_(b) {}
  template <std::unsigned_integral T>
  requires(!std::same_as<T, bool>) Json(T n) : value_(static_cast<std::uint64_t>(n)) {}
  template <std::signed_integral T>
  Json(T n) : value_(static_cast<std::int64_t>(n)) {}
  Json(Decimal d) : value_(d) {}
  // The shortest digits that read back as `d` (as fmt writes it for the
  // text); null if not finite.
  Json(double d);
  Json(std::string s) : value_(std::move(s)) {}
  Json(std::string_view s) : value_(std::string(s)) {}
  Json(const char* s) : value_(std::string(s)) {}

  // Digits already written as a JSON number ("-12").
  static Json digits(std::string text);
  static Json object(Record r);
  static Json array(std::vector<Record> items);
  static Json values(std::vector<Json> items);

  void write(JsonWriter& out) const;

 private:
  struct Digits {
    std::string text;
  };
  std::variant<std::nullptr_t, bool, std::uint64_t, std::int64_t, Decimal, std::string, Digits,
               std::shared_ptr<const Record>, std::shared_ptr<const std::vector<Record>>,
               std::shared_ptr<const std::vector<Json>>>
      value_{nullptr};
};

struct Member {
  std::string key;
  Json value;
};

class Record {
 public:
  // Shown both ways: `label` and `text` for people, `key` = `value` in JSON.
  Record& add(std::string label, std::string text, std::string key, Json value);
  // One line of text for several JSON members.
  Record& add(std::string label, std::string text, std::vector<Member> members);
  Record& json(std::string key, Json value);
  Record& text(std::string label, std::string text);
  // Another record inside this one: in JSON an object under `key`. In text,
  // with a `heading`, that line and then the inner record's lines indented;
  // without one, its lines (and its table cells) among this record's own.
  Record& nest(std::string key, Record inner, std::string heading = {});

  // Shows `text` for the field labelled `label` instead of its own (a table
  // that says more than the record).
  Record& retext(std::string_view label, std::string text);

  // The members, inside an object the caller opened.
  void write_members(JsonWriter& out) const;
  void write(JsonWriter& out) const;

  // One line per field with text: the label, padded to `width` with spaces,
  // then the text ("state       online"). Nested records with a heading are
  // indented by two spaces, their labels padded to `width` - 2.
  std::string lines(std::size_t width) const;
  // The text of the field labelled `label` (here or nested without a
  // heading); empty when none.
  std::string text_of(std::string_view label) const;

 private:
  struct Field {
    std::string label;  // empty: JSON only; nest(): the key
    std::string text;
    std::vector<Member> members;          // empty: text only
    std::shared_ptr<const Record> inner;  // nest()
    std::string heading;
  };
  std::vector<Field> fields_;
};

}  // namespace dnbridge::dnbctl
