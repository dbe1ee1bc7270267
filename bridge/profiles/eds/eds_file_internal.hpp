#pragma once
// What the parts of the EDS file reader share: the keyword helpers
// (eds_file.cpp) and Reader, which builds an EdsFile from the sections of
// eds_text.hpp. Reader's parts: the top of the reading (eds_file.cpp), its
// problems and field readers (eds_file_fields.cpp), [Device] and [IO_Info]
// (eds_file_io_info.cpp), [Params] and [Assembly] (eds_file_params.cpp), and
// the references between sections (eds_file_cross_check.cpp).
#include <fmt/format.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bridge/cip/epath.hpp"
#include "bridge/profiles/eds/eds_file.hpp"
#include "bridge/profiles/eds/eds_text.hpp"

namespace dnbridge::profiles::eds::eds_file_detail {

// The entry numbered `number` of `list`, or nullptr.
const IoData* numbered(const std::vector<IoData>& list, unsigned number) noexcept;

// "Input12" with prefix "Input": 12. Nothing when the keyword is not the
// prefix followed by a number from 1.
std::optional<unsigned> number_after(std::string_view keyword, std::string_view prefix);

// An entry's identity: "param5" for Param5 or PARAM05 (the numbered
// keywords by their number), the keyword in lower case for the others.
std::string entry_key(std::string_view keyword);

class Reader {
 public:
  explicit Reader(Parsed& out) : out_(out) {}

  // The sections of `text` as an EdsFile, or nothing after an error
  // (eds_file.cpp).
  std::optional<EdsFile> read(const Text& text);

 private:
  // Problems, and the entries found wrong (eds_file_fields.cpp).
  void error(std::uint32_t line, std::string message);
  void warning(std::uint32_t line, std::string message);
  void add(std::uint32_t line, Problem::Severity severity, std::string message);
  void failed(const Entry& e);
  bool has_failed(std::string_view keyword) const;

  // An entry's fields as values (eds_file_fields.cpp).
  const Field* field(const Entry& e, std::size_t i, std::string_view what);
  static const Field* given(const Entry& e, std::size_t i);
  std::string string(const Entry& e, std::size_t i);
  std::optional<std::int64_t> integer(const Entry& e, std::size_t i, std::string_view what,
                                      std::int64_t lo, std::int64_t hi);
  std::optional<double> real(const Entry& e, std::size_t i, std::string_view what);
  std::optional<cip::EPath> path(const Entry& e, std::size_t i, std::string_view what,
                                 std::optional<std::int64_t> size = std::nullopt);

  // [Device] and [IO_Info] (eds_file_io_info.cpp).
  void device(const Section& s, Device& d);
  std::optional<ConnectionKinds> kinds(const Entry& e, std::size_t i, std::string_view what);
  void io_info(const Section& s, IoInfo& io);
  void io_data(const Entry& e, unsigned number, std::vector<IoData>& list);

  // [Params] and [Assembly] (eds_file_params.cpp).
  std::optional<Param> param(const Entry& e, unsigned number);
  std::optional<Assembly> assembly(const Entry& e, unsigned number);

  // The numbered entries PREFIXn of a section, each read by `read_one` (which
  // reports its own errors); one given twice is an error, whether or not the
  // first was read.
  template <typename T, typename Read>
  void numbered_entries(const Section& s, std::string_view prefix, std::vector<T>& out,
                        Read read_one) {
    std::set<unsigned> seen;
    for (const Entry& e : s.entries) {
      auto n = number_after(e.keyword, prefix);
      if (!n) continue;  // other entries (Enum, Group, vendors') are not read
      if (!seen.insert(*n).second) {
        error(e.line, fmt::format("{} is given twice", e.keyword));
        continue;
      }
      if (auto item = (this->*read_one)(e, *n)) {
        out.push_back(std::move(*item));
      } else {
        failed(e);
      }
    }
  }

  // The references between sections (eds_file_cross_check.cpp).
  void assembly_cycles(const EdsFile& f);
  void cross_check(const EdsFile& f);

  Parsed& out_;
  std::set<std::string> failed_;
  std::uint32_t defaults_line_ = 0;
};

}  // namespace dnbridge::profiles::eds::eds_file_detail
