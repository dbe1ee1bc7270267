// get, set, service and reload: an explicit request with its reply, why an
// exchange failed, and a reload's reply, as lines and as JSON.
#include <fmt/format.h>

#include "adapters/dds/fields.hpp"
#include "adapters/dnbctl/format.hpp"
#include "bridge/cip/general_status.hpp"

namespace dnbridge::dnbctl {

using dds::view;

namespace {

std::string request_text(const ExplicitExchange& x) {
  std::string s = fmt::format("{} {} class 0x{:02X} instance {}", node_name(x.rack, x.port, x.mac),
                              service_text(x.service), x.class_id, x.instance_id);
  if (x.attribute) s += fmt::format(" attribute {}", *x.attribute);
  if (!x.request_data.empty()) s += fmt::format(" data [{}]", hex_bytes(x.request_data));
  return s;
}

std::string_view decoding_name(Decoding as) {
  switch (as) {
    case Decoding::kString:
      return "string";
    case Decoding::kUint:
      return "uint";
    case Decoding::kInt:
      return "int";
    case Decoding::kNone:
      break;
  }
  return "";
}

}  // namespace

namespace {

// A request and its reply as `get`, `set` and `service` show them: in text
// one line per field, "label: value", the request's own line first.
Record explicit_record(const ExplicitExchange& x, Decoding as,
                       const std::optional<Parsed<std::string>>& decoded) {
  Record request;
  request.json("rack", x.rack)
      .json("port", x.port)
      .json("mac", x.mac)
      .json("service", x.service)
      .json("service_name", service_text(x.service))
      .json("class", x.class_id)
      .json("instance", x.instance_id)
      .json("attribute", x.attribute ? Json(*x.attribute) : Json())
      .json("data", hex_bytes(x.request_data));

  Record r;
  r.add(request_text(x), "", "request", Json::object(std::move(request)))
      .add("status: ", fmt::format("{} ({})", x.status, transaction_status_text(x.status)),
           {{"status", x.status}, {"status_text", transaction_status_text(x.status)}});
  // The device's status exists only when the bridge completed the transaction.
  if (x.status == 1) {
    std::string text =
        fmt::format("0x{:02X} ({})", x.general_status, general_status_text(x.general_status));
    if (x.additional_status != cip::kNoAdditionalCode) {
      text += fmt::format(", additional status 0x{:02X}", x.additional_status);
    }
    r.add("CIP general status: ", std::move(text),
          {{"general_status", x.general_status},
           {"general_status_text", general_status_text(x.general_status)},
           {"additional_status", x.additional_status}});
  } else {
    r.add("", "", {{"general_status", {}}, {"general_status_text", {}}, {"additional_status", {}}});
  }
  r.add(x.message.empty() ? "" : "message: ", x.message, "message", x.message);
  std::string data_label;
  if (!x.data.empty()) {
    data_label = fmt::format("data ({} byte{}): ", x.data.size(), x.data.size() == 1 ? "" : "s");
  } else if (x.succeeded()) {
    data_label = "data: ";
  }
  r.add(std::move(data_label), x.data.empty() ? "none" : hex_bytes(x.data), "data",
        hex_bytes(x.data))
      .json("succeeded", x.succeeded());
  if (decoded) {
    Record d;
    d.json("as", decoding_name(as));
    std::string text;
    if (decoded->ok() && as == Decoding::kString) {
      d.json("value", **decoded);
      text = json_quote(**decoded);
    } else if (decoded->ok()) {
      d.json("value", Json::digits(**decoded));  // an integer decode_data wrote
      text = **decoded;
    } else {
      d.json("error", decoded->error());
      text = "cannot decode: " + decoded->error();
    }
    r.add(fmt::format("as {}: ", decoding_name(as)), std::move(text), "decoded",
          Json::object(std::move(d)));
  }
  return r;
}

}  // namespace

std::string explicit_text(const ExplicitExchange& x, Decoding as,
                          const std::optional<Parsed<std::string>>& decoded) {
  return explicit_record(x, as, decoded).lines(0);
}

void explicit_json(JsonWriter& out, const ExplicitExchange& x, Decoding as,
                   const std::optional<Parsed<std::string>>& decoded) {
  explicit_record(x, as, decoded).write(out);
}

std::string_view reload_status_word(std::uint8_t status) {
  switch (status) {
    case dnbridge_RELOAD_APPLIED:
      return "applied";
    case dnbridge_RELOAD_REFUSED:
      return "refused";
    case dnbridge_RELOAD_BUSY:
      return "busy";
    case dnbridge_RELOAD_NO_FILE:
      return "no-file";
    case dnbridge_RELOAD_INCOMPLETE:
      return "incomplete";
    default:
      break;
  }
  return "unknown";
}

namespace {

// A list of the reply as `reload` shows it: in text its heading, then one
// indented line per entry, nothing when empty; in JSON an array of strings.
void add_lines(Record& r, std::string heading, std::string key, const dds_sequence_string& seq) {
  std::vector<std::string_view> entries;
  if (seq._buffer != nullptr) {
    for (std::uint32_t i = 0; i < seq._length; ++i) entries.push_back(view(seq._buffer[i]));
  }
  std::vector<Json> items(entries.begin(), entries.end());
  r.add(entries.empty() ? "" : std::move(heading), "", std::move(key),
        Json::values(std::move(items)));
  for (const auto e : entries) r.text(fmt::format("  {}", e), "");
}

// A reload's reply as `reload` shows it.
Record reload_record(const dnbridge_ReloadReply& r) {
  const std::string_view word = reload_status_word(r.status);
  const std::string message(view(r.message));
  const std::string file(view(r.file));
  Record rec;
  rec.add(fmt::format("rack {}: {}", view(r.rack), message.empty() ? word : message), "",
          {{"rack", std::string(view(r.rack))}, {"status", word}, {"message", message}})
      .add(file.empty() ? "" : "file: ", file, "file", file);
  add_lines(rec, "applied:", "applied", r.applied);
  add_lines(rec, "needs a restart:", "needs_restart", r.needs_restart);
  add_lines(rec, "problems:", "problems", r.problems);
  return rec;
}

}  // namespace

std::string reload_text(const dnbridge_ReloadReply& r) { return reload_record(r).lines(0); }

void reload_json(JsonWriter& out, const dnbridge_ReloadReply& r) { reload_record(r).write(out); }

std::string failure_text(const ExplicitExchange& x) {
  if (x.status != 1) {
    return fmt::format("status {} ({}){}", x.status, transaction_status_text(x.status),
                       x.message.empty() ? "" : ": " + x.message);
  }
  return fmt::format("the device answered 0x{:02X} ({})", x.general_status,
                     general_status_text(x.general_status));
}

}  // namespace dnbridge::dnbctl
