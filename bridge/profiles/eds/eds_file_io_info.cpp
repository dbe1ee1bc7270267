// Reader: [Device], the identity, and [IO_Info], the connections and their
// data.
#include <fmt/format.h>

#include <set>
#include <utility>

#include "bridge/common/text.hpp"
#include "bridge/profiles/eds/eds_file_internal.hpp"

namespace dnbridge::profiles::eds::eds_file_detail {

void Reader::device(const Section& s, Device& d) {
  const auto required = [&](std::string_view keyword, std::int64_t hi, auto& out) -> void {
    const Entry* e = s.find(keyword);
    if (e == nullptr) {
      error(s.line, fmt::format("[Device] has no {}", keyword));
      return;
    }
    if (auto v = integer(*e, 0, "value", 0, hi)) {
      out = static_cast<std::remove_reference_t<decltype(out)>>(*v);
    }
  };
  std::set<std::string> seen;
  for (const Entry& e : s.entries) {
    if (!seen.insert(to_lower(e.keyword)).second) {
      warning(e.line, fmt::format("[Device] {} is given again: only the first is read", e.keyword));
    }
  }
  required("VendCode", 0xFFFF, d.vendor_code);
  required("ProdType", 0xFFFF, d.product_type);
  required("ProdCode", 0xFFFF, d.product_code);
  required("MajRev", 0xFF, d.major_revision);
  required("MinRev", 0xFF, d.minor_revision);
  if (const Entry* e = s.find("VendName")) d.vendor_name = string(*e, 0);
  if (const Entry* e = s.find("ProdTypeStr")) d.product_type_name = string(*e, 0);
  if (const Entry* e = s.find("ProdName")) d.product_name = string(*e, 0);
  if (const Entry* e = s.find("Catalog")) d.catalog = string(*e, 0);
}

std::optional<ConnectionKinds> Reader::kinds(const Entry& e, std::size_t i, std::string_view what) {
  auto v = integer(e, i, what, 0, 0xFFFF);
  if (!v) return std::nullopt;
  const auto bits = static_cast<std::uint16_t>(*v);
  if ((bits & ~0x000Fu) != 0) {
    warning(e.line, fmt::format("{}: {} 0x{:04X} has bits beyond poll, bit-strobe, change of "
                                "state and cyclic; those are ignored",
                                e.keyword, what, bits));
  }
  return ConnectionKinds{static_cast<std::uint16_t>(bits & 0x000F)};
}

void Reader::io_info(const Section& s, IoInfo& io) {
  static constexpr std::pair<std::string_view, ConnectionKind> kInfos[] = {
      {"PollInfo", ConnectionKind::kPoll},
      {"StrobeInfo", ConnectionKind::kStrobe},
      {"COSInfo", ConnectionKind::kChangeOfState},
      {"CyclicInfo", ConnectionKind::kCyclic}};
  for (const Entry& e : s.entries) {
    if (iequals(e.keyword, "Default")) {
      if (defaults_line_ != 0) {
        error(e.line, "Default is given twice");
        continue;
      }
      defaults_line_ = e.line;
      if (auto k = kinds(e, 0, "default connections")) io.defaults = *k;
      continue;
    }
    bool known = false;
    for (const auto& [keyword, kind] : kInfos) {
      if (!iequals(e.keyword, keyword)) continue;
      known = true;
      if (io.connection(kind) != nullptr) {
        error(e.line, fmt::format("{} is given twice", e.keyword));
        break;
      }
      auto combines = kinds(e, 0, "the connections it combines with");
      auto input = integer(e, 1, "its input", 0, 0xFFFF);
      auto output = integer(e, 2, "its output", 0, 0xFFFF);
      if (combines && input && output) {
        io.connections.push_back({kind, *combines, static_cast<unsigned>(*input),
                                  static_cast<unsigned>(*output), e.line});
      } else {
        failed(e);
      }
    }
    if (known) continue;
    if (auto n = number_after(e.keyword, "Input")) {
      io_data(e, *n, io.inputs);
    } else if (auto m = number_after(e.keyword, "Output")) {
      io_data(e, *m, io.outputs);
    }
    // Other keywords (vendors' own) are not dnbridge's.
  }
}

void Reader::io_data(const Entry& e, unsigned number, std::vector<IoData>& list) {
  if (numbered(list, number) != nullptr) {
    error(e.line, fmt::format("{} is given twice", e.keyword));
    return;
  }
  IoData d;
  d.number = number;
  d.line = e.line;
  auto size = integer(e, 0, "size in bytes", 0, 0xFFFF);
  auto bits = integer(e, 1, "bits used", 0, std::int64_t{0xFFFF} * 8);
  auto carried = kinds(e, 2, "the connections that carry it");
  d.name = string(e, 3);
  auto path_size = integer(e, 4, "path size", 0, 0xFF);
  std::optional<cip::EPath> p;
  if (path_size) p = path(e, 5, "path", *path_size);
  d.help = string(e, 6);
  if (!size || !bits || !carried || !p) {
    failed(e);
    return;
  }
  if (*bits > *size * 8) {
    error(e.line, fmt::format("{}: {} bits used do not fit in {} bytes", e.keyword, *bits, *size));
    failed(e);
    return;
  }
  d.size = static_cast<std::uint16_t>(*size);
  d.bits_used = static_cast<std::uint16_t>(*bits);
  d.carried_by = *carried;
  d.path = *p;
  list.push_back(std::move(d));
}

}  // namespace dnbridge::profiles::eds::eds_file_detail
