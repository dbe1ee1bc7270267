// The names and the tables every command's output uses. Each command's
// records: format_list.cpp, format_watch.cpp, format_show.cpp,
// format_replies.cpp.
#include "adapters/dnbctl/format.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "adapters/dds/states.hpp"
#include "adapters/dnbctl/format_internal.hpp"
#include "adapters/dnbctl/utf8.hpp"
#include "bridge/cip/general_status.hpp"
#include "bridge/cip/service.hpp"
#include "bridge/rack/explicit_gateway.hpp"

namespace dnbridge::dnbctl {

std::string_view to_text(dnbridge_NodeLifecycle state) { return dds::name_of(state); }
std::string_view to_text(dnbridge_PortLifecycle state) { return dds::name_of(state); }
std::string_view to_text(dnbridge_BusState state) { return dds::name_of(state); }

std::string transaction_status_text(std::uint8_t status) {
  // The bridge's own names (rack::TransactionStatus); 7 is unassigned.
  if (status >= 1 && status <= 15 && status != 7) {
    return std::string(rack::to_string(static_cast<rack::TransactionStatus>(status)));
  }
  return fmt::format("unknown status {}", status);
}

std::string general_status_text(std::uint8_t code) {
  if (cip::is_known(code))
    return std::string(cip::to_string(static_cast<cip::GeneralStatus>(code)));
  if (code >= 0xD0) return fmt::format("object class specific (0x{:02X})", code);
  return fmt::format("reserved (0x{:02X})", code);
}

std::string service_text(std::uint8_t service) {
  const auto name = cip::to_string(static_cast<cip::Service>(service));
  if (!name.empty()) return std::string(name);
  return fmt::format("service 0x{:02X}", service);
}

std::string node_name(std::string_view rack, std::string_view port, unsigned mac) {
  return fmt::format("{}/{}/{}", rack, port, mac);
}

std::string Table::render() const {
  std::vector<std::size_t> width(headers_.size());
  for (std::size_t c = 0; c < headers_.size(); ++c) width[c] = display_width(headers_[c]);
  for (const auto& row : rows_) {
    for (std::size_t c = 0; c < row.size() && c < width.size(); ++c) {
      width[c] = std::max(width[c], display_width(row[c]));
    }
  }
  std::string out;
  const auto line = [&](const std::vector<std::string>& cells) {
    std::string l;
    for (std::size_t c = 0; c < cells.size() && c < width.size(); ++c) {
      if (c != 0) l += "  ";
      l += cells[c];
      if (c + 1 < cells.size()) l.append(width[c] - display_width(cells[c]), ' ');
    }
    while (!l.empty() && l.back() == ' ') l.pop_back();
    out += l;
    out += '\n';
  };
  line(headers_);
  for (const auto& row : rows_) line(row);
  return out;
}

std::string table(std::span<const std::string_view> labels, std::span<const Record> rows) {
  std::vector<std::string> headers;
  for (auto label : labels) {
    std::string h(label);
    std::transform(h.begin(), h.end(), h.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    headers.push_back(std::move(h));
  }
  Table t(std::move(headers));
  for (const auto& r : rows) {
    std::vector<std::string> cells;
    for (auto label : labels) cells.push_back(r.text_of(label));
    t.add(std::move(cells));
  }
  return t.render();
}

namespace format_detail {

const char* yes_no(bool b) { return b ? "yes" : "no"; }
const char* on_off(bool b) { return b ? "on" : "off"; }

}  // namespace format_detail

}  // namespace dnbridge::dnbctl
