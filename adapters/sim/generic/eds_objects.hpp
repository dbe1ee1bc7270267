#pragma once
// The objects of a simulated device described by an EDS file, as its
// explicit requests reach them (Get_Attribute_Single, Set_Attribute_Single):
//
//   Identity (class 0x01, instance 1): 1 vendor, 2 product type, 3 product
//     code, 4 revision (major, minor), 5 status (0), 6 serial number (UDINT),
//     7 product name (SHORT_STRING), from [Device] and the serial given.
//   Assembly (class 0x04): class attributes 1 revision (1), 2 max instance;
//     per AssemN of the EDS, the instance its path names: 1 number of
//     members, 2 member list
//     (each member's size in bits and path: its own path, a ParamN's link
//     path, an AssemN's path; empty for padding), 3 data (the members packed,
//     parameters' values at their bits, the rest zero; Get only). The
//     1203-CN1 manual's Assembly object (shared/seeds/003).
//   Parameter (class 0x0F): class attribute 2 max instance; per ParamN,
//     instance N attribute 1 the value, Set within the EDS's limits (0x09
//     outside them, or not a finite number), refused when read only
//     (0x0E); starts at the default. String parameters are kept empty and
//     are not settable here.
//   Acknowledge Handler (class 0x2B, instance 1): class attributes 1
//     revision (1), 2 max instance (1); 1 acknowledge timer (UINT ms,
//     1..65535, default 20), 2 retry limit (USINT, default 1), 3 COS
//     producing connection instance (UINT, default 4), 4 ack list size
//     (BYTE, 1; Get only), 5 ack list (BYTE count, USINT instances; the
//     COS connection's once it is acknowledged; Get only). The LUFP9
//     manual, appendix D (shared/seeds/000). Attribute 3 is kept to
//     1..255, which the ack list can hold.
//   Identity's class attributes 1 revision and 2 max instance are 1.
//
// Anything else is answered with the CIP error for it, checked in the order
// the CDN127 simulator checks: 0x16 object does not exist, 0x08 service not
// supported (any other service; Set at class level), 0x13 no attribute,
// 0x15 data with a Get, 0x14 attribute not supported, 0x0E attribute not
// settable, 0x13 / 0x15 for the size of a Set, 0x09 a value refused.
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "bridge/cip/assembly.hpp"
#include "bridge/cip/general_status.hpp"
#include "bridge/common/bytes.hpp"
#include "bridge/devicenet/wire/explicit_message.hpp"
#include "bridge/profiles/eds/eds_file.hpp"

namespace dnbridge::sim {

struct AckHandler {
  std::uint16_t ack_timer_ms = 20;
  std::uint8_t retry_limit = 1;
  std::uint16_t cos_producing_instance = 4;
  bool cos_acknowledged = false;  // the COS connection in the ack list
};

class EdsObjects {
 public:
  // `member_lists`: false, the Assembly object's attributes 1 and 2 are not
  // supported (0x14), as on a device that describes its assemblies only in
  // its EDS.
  EdsObjects(profiles::eds::EdsFile file, std::uint32_t serial_number, bool member_lists = true);

  // Runs `request` and writes the response message (service byte first,
  // success or error) into `out` (devicenet::kMaxExplicitMessage bytes);
  // the size written.
  std::size_t execute(const devicenet::RequestMessage& request, MutableBytes out);

  // A parameter's value, little-endian in its data size; empty if no such
  // parameter.
  std::vector<std::uint8_t> param_value(unsigned number) const;
  // A numeric parameter's value as a number; nothing for a string or none.
  std::optional<double> param_number(unsigned number) const;
  // Sets it as the device itself would (an input changing), limits unchecked;
  // false if no such parameter or the size differs.
  bool set_param_value(unsigned number, Bytes value);
  // The same from a number, as the parameter's type holds it; false if no
  // such numeric parameter or the type cannot hold `value`.
  bool set_param_number(unsigned number, double value);
  // The data of the assembly at `instance`: its members packed, least
  // significant bit first; empty if no such assembly.
  std::vector<std::uint8_t> assembly_data(unsigned instance) const;
  // Unpacks `data` into the parameters the assembly at `instance` names
  // (nested assemblies too; padding taken as it is), limits unchecked, as
  // the device takes its outputs from a connection; false if no such
  // assembly or `data` is not its size. A member named by a path (an object
  // the simulator does not have, e.g. a Discrete Input Point) keeps the bits
  // it is given here, the same for every assembly that names it (zero
  // before): so a test sets such inputs.
  bool set_assembly_data(unsigned instance, Bytes data);
  // How deep nested assemblies are packed.
  static constexpr unsigned kMaxNesting = 8;

  const AckHandler& ack_handler() const noexcept { return ack_; }
  AckHandler& ack_handler() noexcept { return ack_; }
  const profiles::eds::EdsFile& file() const noexcept { return file_; }

 private:
  struct Outcome {
    cip::GeneralStatus status = cip::GeneralStatus::kSuccess;
    std::uint8_t additional = cip::kNoAdditionalCode;
  };
  Outcome get(const devicenet::RequestMessage& r, ByteWriter& out) const;
  Outcome set(const devicenet::RequestMessage& r);
  Outcome get_identity(std::uint8_t attribute, ByteWriter& out) const;
  Outcome get_assembly(std::uint16_t instance, std::uint8_t attribute, ByteWriter& out) const;
  Outcome get_parameter(std::uint16_t instance, std::uint8_t attribute, ByteWriter& out) const;
  Outcome get_ack_handler(std::uint16_t instance, std::uint8_t attribute, ByteWriter& out) const;
  bool exists(std::uint16_t class_id, std::uint16_t instance) const noexcept;
  // The assembly at an instance (its path's), and AssemN.
  const profiles::eds::Assembly* assembly(unsigned instance) const noexcept;
  const profiles::eds::Assembly* assembly_numbered(unsigned number) const noexcept;
  std::vector<std::uint8_t> packed(const profiles::eds::Assembly& assembly, unsigned depth) const;
  void unpack(const profiles::eds::Assembly& assembly, Bytes data, std::uint32_t at,
              unsigned depth);
  std::vector<cip::AssemblyMember> member_list(const profiles::eds::Assembly& a) const;

  profiles::eds::EdsFile file_;
  std::uint32_t serial_number_;
  bool member_lists_ = true;
  std::map<unsigned, std::vector<std::uint8_t>> values_;  // per ParamN
  // Path members' bits, per encoded path.
  std::map<std::vector<std::uint8_t>, std::vector<std::uint8_t>> path_values_;
  AckHandler ack_;
};

}  // namespace dnbridge::sim
