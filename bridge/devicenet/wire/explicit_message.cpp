#include "bridge/devicenet/wire/explicit_message.hpp"

#include "bridge/devicenet/wire/identifier.hpp"

namespace dnbridge::devicenet {
namespace {

constexpr std::uint8_t kFragBit = 0x80;
constexpr std::uint8_t kXidBit = 0x40;
constexpr std::uint8_t kMacMask = 0x3F;

constexpr bool wide_class(BodyFormat f) noexcept {
  return f == BodyFormat::k16_16 || f == BodyFormat::k16_8;
}
constexpr bool wide_instance(BodyFormat f) noexcept {
  return f == BodyFormat::k8_16 || f == BodyFormat::k16_16;
}

bool has_attribute(std::uint8_t service) noexcept {
  return cip::has_attribute(static_cast<cip::Service>(service));
}

void write_field(ByteWriter& w, std::uint16_t value, bool wide) noexcept {
  if (wide) {
    w.u16le(value);
  } else {
    w.u8(static_cast<std::uint8_t>(value));
  }
}

std::uint16_t read_field(ByteReader& r, bool wide) noexcept { return wide ? r.u16le() : r.u8(); }

// Allocate/Release refuse choice 0 (the slave answers 0x09/0x02, bridge/PROTOCOL.md
// §3) and the reserved bit 0x80.
constexpr bool valid_choice(std::uint8_t choice) noexcept {
  return choice != 0 && (choice & 0x80) == 0;
}

}  // namespace

Result<BodyFormat> body_format_from_code(std::uint8_t code) noexcept {
  switch (code) {
    case 0:
      return BodyFormat::k8_8;
    case 1:
      return BodyFormat::k8_16;
    case 2:
      return BodyFormat::k16_16;
    case 3:
      return BodyFormat::k16_8;
    case 4:
      return Errc::kUnsupported;  // packed CIP path: not used by Group 2 only slaves
    default:
      return Errc::kMalformed;
  }
}

std::uint8_t encode_header(ExplicitHeader h) noexcept {
  return static_cast<std::uint8_t>((h.frag ? kFragBit : 0) | (h.xid ? kXidBit : 0) |
                                   (h.mac.value() & kMacMask));
}

ExplicitHeader decode_header(std::uint8_t byte) noexcept {
  ExplicitHeader h;
  h.frag = (byte & kFragBit) != 0;
  h.xid = (byte & kXidBit) != 0;
  h.mac = MacId::from_bits(byte);
  return h;
}

std::size_t encoded_size(const RequestMessage& request, BodyFormat format) noexcept {
  return 1 + (wide_class(format) ? 2u : 1u) + (wide_instance(format) ? 2u : 1u) +
         (request.attribute ? 1u : 0u) + request.data.size();
}

Result<std::size_t> encode_request(const RequestMessage& request, BodyFormat format,
                                   MutableBytes out) noexcept {
  if ((request.service & cip::kResponseFlag) != 0) return Errc::kOutOfRange;
  if (!wide_class(format) && request.class_id > 0xFF) return Errc::kOutOfRange;
  if (!wide_instance(format) && request.instance_id > 0xFF) return Errc::kOutOfRange;
  const std::size_t size = encoded_size(request, format);
  if (out.size() < size) return Errc::kBufferTooSmall;
  ByteWriter w(out);
  w.u8(request.service);
  write_field(w, request.class_id, wide_class(format));
  write_field(w, request.instance_id, wide_instance(format));
  if (request.attribute) w.u8(*request.attribute);
  w.bytes(request.data);
  if (!w.ok()) return Errc::kBufferTooSmall;
  return w.size();
}

Result<RequestMessage> decode_request(Bytes message, BodyFormat format) noexcept {
  ByteReader r(message);
  RequestMessage request;
  request.service = r.u8();
  if (!r.ok()) return Errc::kTruncated;
  if ((request.service & cip::kResponseFlag) != 0) return Errc::kMalformed;
  request.class_id = read_field(r, wide_class(format));
  request.instance_id = read_field(r, wide_instance(format));
  if (has_attribute(request.service)) {
    const std::uint8_t attribute = r.u8();
    if (r.ok()) request.attribute = attribute;
  }
  if (!r.ok()) return Errc::kTruncated;
  request.data = r.rest();
  return request;
}

Result<std::size_t> encode_success_response(std::uint8_t service, Bytes data,
                                            MutableBytes out) noexcept {
  if ((service & cip::kResponseFlag) != 0 || service == cip::code(cip::Service::kErrorResponse)) {
    return Errc::kOutOfRange;
  }
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(service | cip::kResponseFlag));
  w.bytes(data);
  if (!w.ok()) return Errc::kBufferTooSmall;
  return w.size();
}

Result<std::size_t> encode_error_response(cip::GeneralStatus status, std::uint8_t additional,
                                          MutableBytes out) noexcept {
  if (status == cip::GeneralStatus::kSuccess) return Errc::kOutOfRange;
  ByteWriter w(out);
  w.u8(static_cast<std::uint8_t>(cip::code(cip::Service::kErrorResponse) | cip::kResponseFlag));
  w.u8(static_cast<std::uint8_t>(status));
  w.u8(additional);
  if (!w.ok()) return Errc::kBufferTooSmall;
  return w.size();
}

Result<ResponseMessage> decode_response(Bytes message) noexcept {
  ByteReader r(message);
  const std::uint8_t service = r.u8();
  if (!r.ok()) return Errc::kTruncated;
  if ((service & cip::kResponseFlag) == 0) return Errc::kMalformed;
  ResponseMessage response;
  response.service = service & cip::kServiceMask;
  if (!response.is_error()) {
    response.data = r.rest();
    return response;
  }
  const std::uint8_t general = r.u8();
  if (!r.ok()) return Errc::kTruncated;
  // An error response that reports success says nothing consistent.
  if (general == static_cast<std::uint8_t>(cip::GeneralStatus::kSuccess)) {
    return Errc::kMalformed;
  }
  response.general_status = static_cast<cip::GeneralStatus>(general);
  // The additional code may be missing in small devices' replies: 0xFF = none.
  if (r.remaining() > 0) response.additional_status = r.u8();
  // DeviceNet error responses carry one additional code; anything after it is
  // left unread (not an error: the status is what matters).
  return response;
}

Result<can::CanFrame> make_allocate_frame(MacId slave, MacId master, std::uint8_t choice) noexcept {
  if (!valid_choice(choice)) return Errc::kOutOfRange;
  const std::uint8_t payload[] = {
      encode_header({.frag = false, .xid = false, .mac = master}),
      cip::code(cip::Service::kAllocateMasterSlave),
      kDeviceNetClass,
      0x01,  // instance 1
      choice,
      master.value(),  // allocator MAC
  };
  return can::CanFrame::make(group2_id(slave, Group2Message::kUnconnectedExplicitRequest),
                             Bytes(payload));
}

Result<can::CanFrame> make_release_frame(MacId slave, MacId master, std::uint8_t choice) noexcept {
  if (!valid_choice(choice)) return Errc::kOutOfRange;
  const std::uint8_t payload[] = {
      encode_header({.frag = false, .xid = false, .mac = master}),
      cip::code(cip::Service::kReleaseMasterSlave),
      kDeviceNetClass,
      0x01,  // instance 1
      choice,
  };
  return can::CanFrame::make(group2_id(slave, Group2Message::kUnconnectedExplicitRequest),
                             Bytes(payload));
}

Result<BodyFormat> decode_allocate_response_data(Bytes data) noexcept {
  ByteReader r(data);
  const std::uint8_t byte = r.u8();
  if (!r.ok()) return Errc::kTruncated;
  // The high nibble is reserved: ignored, as are bytes after the first (none
  // are defined; a slave that adds some still allocated the connection).
  return body_format_from_code(byte & 0x0F);
}

}  // namespace dnbridge::devicenet
