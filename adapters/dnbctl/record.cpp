#include "adapters/dnbctl/record.hpp"

#include <fmt/format.h>

#include <cmath>

namespace dnbridge::dnbctl {

Json::Json(double d) {
  if (std::isfinite(d)) value_ = Digits{fmt::format("{}", d)};
}

Json Json::digits(std::string text) {
  Json j;
  j.value_ = Digits{std::move(text)};
  return j;
}

Json Json::object(Record r) {
  Json j;
  j.value_ = std::make_shared<const Record>(std::move(r));
  return j;
}

Json Json::array(std::vector<Record> items) {
  Json j;
  j.value_ = std::make_shared<const std::vector<Record>>(std::move(items));
  return j;
}

Json Json::values(std::vector<Json> items) {
  Json j;
  j.value_ = std::make_shared<const std::vector<Json>>(std::move(items));
  return j;
}

void Json::write(JsonWriter& out) const {
  struct Writer {
    JsonWriter& out;
    void operator()(std::nullptr_t) const { out.null(); }
    void operator()(bool b) const { out.value(b); }
    void operator()(std::uint64_t n) const { out.value(n); }
    void operator()(std::int64_t n) const { out.value(n); }
    void operator()(const Decimal& d) const { out.number(d.value, d.places); }
    void operator()(const std::string& s) const { out.value(std::string_view(s)); }
    void operator()(const Digits& d) const { out.number_text(d.text); }
    void operator()(const std::shared_ptr<const Record>& r) const { r->write(out); }
    void operator()(const std::shared_ptr<const std::vector<Record>>& items) const {
      out.begin_array();
      for (const auto& r : *items) r.write(out);
      out.end_array();
    }
    void operator()(const std::shared_ptr<const std::vector<Json>>& items) const {
      out.begin_array();
      for (const auto& v : *items) v.write(out);
      out.end_array();
    }
  };
  std::visit(Writer{out}, value_);
}

Record& Record::add(std::string label, std::string text, std::string key, Json value) {
  std::vector<Member> members;
  members.push_back({std::move(key), std::move(value)});
  return add(std::move(label), std::move(text), std::move(members));
}

Record& Record::add(std::string label, std::string text, std::vector<Member> members) {
  fields_.push_back({std::move(label), std::move(text), std::move(members), nullptr, {}});
  return *this;
}

Record& Record::json(std::string key, Json value) {
  return add({}, {}, std::move(key), std::move(value));
}

Record& Record::text(std::string label, std::string text) {
  return add(std::move(label), std::move(text), std::vector<Member>{});
}

Record& Record::nest(std::string key, Record inner, std::string heading) {
  fields_.push_back({std::move(key),
                     {},
                     {},
                     std::make_shared<const Record>(std::move(inner)),
                     std::move(heading)});
  return *this;
}

Record& Record::retext(std::string_view label, std::string text) {
  for (auto& f : fields_) {
    if (!f.inner && f.label == label) {
      f.text = std::move(text);
      break;
    }
  }
  return *this;
}

void Record::write_members(JsonWriter& out) const {
  for (const auto& f : fields_) {
    if (f.inner) {
      out.key(f.label);
      f.inner->write(out);
    }
    for (const auto& m : f.members) {
      out.key(m.key);
      m.value.write(out);
    }
  }
}

void Record::write(JsonWriter& out) const {
  out.begin_object();
  write_members(out);
  out.end_object();
}

std::string Record::lines(std::size_t width) const {
  std::string out;
  for (const auto& f : fields_) {
    if (f.inner && f.heading.empty()) {
      out += f.inner->lines(width);
    } else if (f.inner) {
      out += f.heading + '\n';
      const std::string inner = f.inner->lines(width >= 2 ? width - 2 : 0);
      for (std::size_t at = 0; at < inner.size();) {
        const std::size_t end = inner.find('\n', at);
        out += "  " + inner.substr(at, end - at + 1);
        at = end == std::string::npos ? inner.size() : end + 1;
      }
    } else if (!f.label.empty()) {
      out += fmt::format("{:<{}}{}\n", f.label, width, f.text);
    }
  }
  return out;
}

std::string Record::text_of(std::string_view label) const {
  for (const auto& f : fields_) {
    if (f.inner && f.heading.empty()) {
      if (auto t = f.inner->text_of(label); !t.empty()) return t;
    } else if (!f.inner && f.label == label) {
      return f.text;
    }
  }
  return {};
}

}  // namespace dnbridge::dnbctl
