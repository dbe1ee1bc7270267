#include "bridge/devicenet/wire/explicit_message.hpp"

#include <gtest/gtest.h>

#include <array>
#include <random>

#include "bridge/devicenet/wire/identifier.hpp"
#include "support/bytes.hpp"

namespace dnbridge::devicenet {
namespace {

using test::ByteVec;
using test::hex;

MacId mac(unsigned v) { return MacId::from(v).value(); }

ByteVec encode(const RequestMessage& request, BodyFormat format) {
  ByteVec out(encoded_size(request, format));
  auto n = encode_request(request, format, out);
  EXPECT_TRUE(n.ok()) << n.error().message();
  if (n.ok()) {
    EXPECT_EQ(*n, out.size());
  }
  return out;
}

TEST(BodyFormat, CodesZeroToThreeAreTheFourFormats) {
  EXPECT_EQ(body_format_from_code(0).value(), BodyFormat::k8_8);
  EXPECT_EQ(body_format_from_code(1).value(), BodyFormat::k8_16);
  EXPECT_EQ(body_format_from_code(2).value(), BodyFormat::k16_16);
  EXPECT_EQ(body_format_from_code(3).value(), BodyFormat::k16_8);
  EXPECT_EQ(body_format_from_code(4).error(), Errc::kUnsupported);  // packed path
  for (unsigned code = 5; code <= 0xFF; ++code) {
    EXPECT_EQ(body_format_from_code(static_cast<std::uint8_t>(code)).error(), Errc::kMalformed)
        << code;
  }
}

TEST(ExplicitHeader, BitsAreFragXidMac) {
  EXPECT_EQ(encode_header({.frag = true, .xid = false, .mac = mac(0)}), 0x80);
  EXPECT_EQ(encode_header({.frag = false, .xid = true, .mac = mac(10)}), 0x4A);
  EXPECT_EQ(encode_header({.frag = true, .xid = true, .mac = mac(63)}), 0xFF);
  const ExplicitHeader h = decode_header(0xC5);
  EXPECT_TRUE(h.frag);
  EXPECT_TRUE(h.xid);
  EXPECT_EQ(h.mac, mac(5));
  for (unsigned b = 0; b <= 0xFF; ++b) {
    const auto byte = static_cast<std::uint8_t>(b);
    EXPECT_EQ(encode_header(decode_header(byte)), byte);
  }
}

// ---------------------------------------------------------------------------
// Allocate / Release (bridge/PROTOCOL.md §3), slave 3, master 10.

TEST(Allocate, RequestFrameGolden) {
  auto f = make_allocate_frame(mac(3), mac(10), allocation::kExplicit | allocation::kPoll);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->id, 0x41Eu);  // Group 2: 10 000011 110 = 0x406 + (3 << 3), message 6
  EXPECT_EQ(hex(*f), "41E: 0A 4B 03 01 03 0A");
  // 0A  header: Frag 0, XID 0, MAC 10 (the master)
  // 4B  service Allocate_Master/Slave_Connection_Set, request
  // 03  class DeviceNet object
  // 01  instance 1
  // 03  allocation choice: explicit (0x01) + poll (0x02)
  // 0A  allocator MAC 10
}

TEST(Allocate, ResponseGoldenDecodesToBodyFormat8_8) {
  const ByteVec frame = {0x0A,   // header: MAC 10 (the master), echoed
                         0xCB,   // 0x4B | R/R
                         0x00};  // reserved 0 | body format 0 = 8/8
  const ExplicitHeader h = decode_header(frame[0]);
  EXPECT_FALSE(h.frag);
  EXPECT_EQ(h.mac, mac(10));
  auto r = decode_response(Bytes(frame).subspan(1));
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->is_error());
  EXPECT_EQ(r->service, 0x4B);
  EXPECT_EQ(r->general_status, cip::GeneralStatus::kSuccess);
  ASSERT_EQ(r->data.size(), 1u);
  EXPECT_EQ(r->data.data(), frame.data() + 2);  // points into the input
  EXPECT_EQ(decode_allocate_response_data(r->data).value(), BodyFormat::k8_8);
}

TEST(Allocate, ResponseDataOtherFormatsAndErrors) {
  const ByteVec f8_16 = {0x01}, f16_8 = {0xF3}, packed = {0x04}, bad = {0x07}, empty = {};
  EXPECT_EQ(decode_allocate_response_data(f8_16).value(), BodyFormat::k8_16);
  EXPECT_EQ(decode_allocate_response_data(f16_8).value(),
            BodyFormat::k16_8);  // reserved nibble ignored
  EXPECT_EQ(decode_allocate_response_data(packed).error(), Errc::kUnsupported);
  EXPECT_EQ(decode_allocate_response_data(bad).error(), Errc::kMalformed);
  EXPECT_EQ(decode_allocate_response_data(empty).error(), Errc::kTruncated);
}

TEST(Release, RequestFrameGolden) {
  auto f = make_release_frame(mac(3), mac(10), allocation::kPoll);
  ASSERT_TRUE(f.ok());
  // 0A header MAC 10, 4C Release, 03 class, 01 instance, 02 release choice poll
  EXPECT_EQ(hex(*f), "41E: 0A 4C 03 01 02");
}

TEST(Allocate, RefusesEmptyAndReservedChoice) {
  EXPECT_EQ(make_allocate_frame(mac(3), mac(10), 0).error(), Errc::kOutOfRange);
  EXPECT_EQ(make_allocate_frame(mac(3), mac(10), 0x81).error(), Errc::kOutOfRange);
  EXPECT_EQ(make_release_frame(mac(3), mac(10), 0).error(), Errc::kOutOfRange);
  EXPECT_EQ(make_release_frame(mac(3), mac(10), 0x80).error(), Errc::kOutOfRange);
}

// ---------------------------------------------------------------------------
// Error responses.

TEST(ErrorResponse, GoldenObjectStateConflict) {
  const ByteVec frame = {0x0A,   // header, MAC 10
                         0x94,   // Error_Response 0x14 | R/R
                         0x0C,   // general status: object state conflict
                         0x01};  // additional code 1 (allocation conflict)
  auto r = decode_response(Bytes(frame).subspan(1));
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->is_error());
  EXPECT_EQ(r->service, 0x14);
  EXPECT_EQ(r->general_status, cip::GeneralStatus::kObjectStateConflict);
  EXPECT_EQ(r->additional_status, 0x01);
  EXPECT_TRUE(r->data.empty());

  std::array<std::uint8_t, 3> out{};
  auto n = encode_error_response(cip::GeneralStatus::kObjectStateConflict, 0x01, out);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(hex(Bytes(out.data(), *n)), "94 0C 01");
}

TEST(ErrorResponse, MissingAdditionalCodeReadsAsNone) {
  const ByteVec msg = {0x94, 0x08};
  auto r = decode_response(msg);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->general_status, cip::GeneralStatus::kServiceNotSupported);
  EXPECT_EQ(r->additional_status, cip::kNoAdditionalCode);
}

TEST(ErrorResponse, WithoutStatusOrWithSuccessStatusFails) {
  const ByteVec no_status = {0x94}, success = {0x94, 0x00, 0xFF};
  EXPECT_EQ(decode_response(no_status).error(), Errc::kTruncated);
  EXPECT_EQ(decode_response(success).error(), Errc::kMalformed);
  std::array<std::uint8_t, 3> out{};
  EXPECT_EQ(encode_error_response(cip::GeneralStatus::kSuccess, 0xFF, out).error(),
            Errc::kOutOfRange);
  std::array<std::uint8_t, 2> small{};
  EXPECT_EQ(encode_error_response(cip::GeneralStatus::kObjectStateConflict, 1, small).error(),
            Errc::kBufferTooSmall);
}

TEST(Response, EmptyOrRequestFails) {
  const ByteVec empty = {}, request = {0x0E, 0x01};
  EXPECT_EQ(decode_response(empty).error(), Errc::kTruncated);
  EXPECT_EQ(decode_response(request).error(), Errc::kMalformed);
}

TEST(SuccessResponse, EncodeRefusesResponseBitAndErrorService) {
  const ByteVec data = {0x10, 0x0E};
  std::array<std::uint8_t, 8> out{};
  EXPECT_EQ(encode_success_response(0x90, data, out).error(), Errc::kOutOfRange);
  EXPECT_EQ(encode_success_response(0x14, data, out).error(), Errc::kOutOfRange);
  std::array<std::uint8_t, 2> small{};
  EXPECT_EQ(encode_success_response(0x10, data, small).error(), Errc::kBufferTooSmall);
}

// ---------------------------------------------------------------------------
// Get_Attribute_Single in each body format.

TEST(Request, GetAttributeSingleInEachBodyFormat) {
  RequestMessage get;
  get.service = cip::code(cip::Service::kGetAttributeSingle);
  get.class_id = 0x05;     // Connection object
  get.instance_id = 0x02;  // poll connection
  get.attribute = 0x09;    // expected packet rate
  // 0E service | class | instance | 09 attribute
  EXPECT_EQ(hex(encode(get, BodyFormat::k8_8)), "0E 05 02 09");
  EXPECT_EQ(hex(encode(get, BodyFormat::k8_16)), "0E 05 02 00 09");
  EXPECT_EQ(hex(encode(get, BodyFormat::k16_16)), "0E 05 00 02 00 09");
  EXPECT_EQ(hex(encode(get, BodyFormat::k16_8)), "0E 05 00 02 09");

  RequestMessage wide = get;
  wide.class_id = 0x0304;
  wide.instance_id = 0x0201;
  // 0E | class 0x0304 LE | instance 0x0201 LE | 09
  EXPECT_EQ(hex(encode(wide, BodyFormat::k16_16)), "0E 04 03 01 02 09");

  for (auto format : {BodyFormat::k8_8, BodyFormat::k8_16, BodyFormat::k16_16, BodyFormat::k16_8}) {
    const ByteVec bytes = encode(get, format);
    auto d = decode_request(bytes, format);
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d->service, get.service);
    EXPECT_EQ(d->class_id, get.class_id);
    EXPECT_EQ(d->instance_id, get.instance_id);
    EXPECT_EQ(d->attribute, get.attribute);
    EXPECT_TRUE(d->data.empty());
    // Every prefix is a truncated request.
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      EXPECT_EQ(decode_request(Bytes(bytes.data(), n), format).error(), Errc::kTruncated)
          << static_cast<int>(format) << " prefix " << n;
    }
  }
}

TEST(Request, EncodeRefusesWhatDoesNotFit) {
  RequestMessage r;
  r.service = 0x0E;
  r.class_id = 0x100;
  r.instance_id = 1;
  r.attribute = 1;
  std::array<std::uint8_t, 16> out{};
  EXPECT_EQ(encode_request(r, BodyFormat::k8_8, out).error(), Errc::kOutOfRange);
  EXPECT_EQ(encode_request(r, BodyFormat::k8_16, out).error(), Errc::kOutOfRange);
  EXPECT_TRUE(encode_request(r, BodyFormat::k16_8, out).ok());
  r.class_id = 1;
  r.instance_id = 0x100;
  EXPECT_EQ(encode_request(r, BodyFormat::k16_8, out).error(), Errc::kOutOfRange);
  EXPECT_TRUE(encode_request(r, BodyFormat::k8_16, out).ok());
  r.instance_id = 1;
  r.service = 0x8E;  // R/R set: not a request
  EXPECT_EQ(encode_request(r, BodyFormat::k8_8, out).error(), Errc::kOutOfRange);
  r.service = 0x0E;
  const std::size_t size = encoded_size(r, BodyFormat::k8_8);
  for (std::size_t n = 0; n < size; ++n) {
    EXPECT_EQ(encode_request(r, BodyFormat::k8_8, MutableBytes(out.data(), n)).error(),
              Errc::kBufferTooSmall);
  }
}

TEST(Request, ServiceWithoutAttributeHasNone) {
  const ByteVec reset = {0x05,   // Reset
                         0x01,   // class Identity
                         0x01,   // instance 1
                         0x00};  // service data: reset type 0
  auto d = decode_request(reset, BodyFormat::k8_8);
  ASSERT_TRUE(d.ok());
  EXPECT_FALSE(d->attribute.has_value());
  EXPECT_EQ(hex(d->data), "00");
  RequestMessage again = *d;
  EXPECT_EQ(encode(again, BodyFormat::k8_8), reset);
}

TEST(Request, DecodeRefusesResponse) {
  const ByteVec msg = {0x8E, 0x01, 0x01, 0x07};
  EXPECT_EQ(decode_request(msg, BodyFormat::k8_8).error(), Errc::kMalformed);
}

// ---------------------------------------------------------------------------
// Expected packet rate (bridge/PROTOCOL.md §7, §8).

TEST(ExpectedPacketRate, SetRequestAndResponseGolden) {
  const ByteVec data = {0x0A, 0x0E};  // 3594 ms, UINT LE
  RequestMessage set;
  set.service = cip::code(cip::Service::kSetAttributeSingle);
  set.class_id = 0x05;
  set.instance_id = 0x02;
  set.attribute = 0x09;
  set.data = data;
  const ByteVec frame_tail = encode(set, BodyFormat::k8_8);
  // 10 Set_Attribute_Single, 05 class Connection, 02 instance poll,
  // 09 attribute EPR, 0A 0E = 0x0E0A = 3594 ms
  EXPECT_EQ(hex(frame_tail), "10 05 02 09 0A 0E");
  ASSERT_LE(frame_tail.size(), kMaxUnfragmentedMessage);

  auto d = decode_request(frame_tail, BodyFormat::k8_8);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->attribute, 0x09);
  ByteReader epr(d->data);
  EXPECT_EQ(epr.u16le(), 3594);

  const ByteVec response = {0x0A,         // header, MAC 10
                            0x90,         // 0x10 | R/R
                            0x10, 0x0E};  // actual EPR 0x0E10 = 3600 ms
  auto r = decode_response(Bytes(response).subspan(1));
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r->is_error());
  EXPECT_EQ(r->service, 0x10);
  ByteReader actual(r->data);
  EXPECT_EQ(actual.u16le(), 3600);
  EXPECT_TRUE(actual.at_end());

  std::array<std::uint8_t, 7> out{};
  auto n = encode_success_response(0x10, r->data, out);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(hex(Bytes(out.data(), *n)), "90 10 0E");
}

// ---------------------------------------------------------------------------
// Garbage: every decoder either fails or gives a value consistent with its input.

TEST(ExplicitMessage, GarbageDecodesConsistentlyOrFails) {
  std::mt19937 rng(20240601);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::size_t> length(0, 12);
  for (int i = 0; i < 20000; ++i) {
    ByteVec in(length(rng));
    for (auto& b : in) b = static_cast<std::uint8_t>(byte(rng));
    for (auto format :
         {BodyFormat::k8_8, BodyFormat::k8_16, BodyFormat::k16_16, BodyFormat::k16_8}) {
      auto req = decode_request(in, format);
      if (req.ok()) {
        ASSERT_TRUE(req->data.empty() ||
                    (req->data.data() >= in.data() &&
                     req->data.data() + req->data.size() == in.data() + in.size()));
        EXPECT_EQ(encode(*req, format), in) << hex(in);
      }
    }
    auto rsp = decode_response(in);
    if (rsp.ok()) {
      ASSERT_FALSE(in.empty());
      std::array<std::uint8_t, 16> out{};
      if (rsp->is_error()) {
        auto n = encode_error_response(rsp->general_status, rsp->additional_status, out);
        ASSERT_TRUE(n.ok());
        const std::size_t common = std::min(in.size(), *n);
        EXPECT_EQ(hex(Bytes(out.data(), common)), hex(Bytes(in.data(), common)));
      } else {
        auto n = encode_success_response(rsp->service, rsp->data, out);
        ASSERT_TRUE(n.ok());
        EXPECT_EQ(hex(Bytes(out.data(), *n)), hex(in));
      }
    }
    (void)decode_allocate_response_data(in);
  }
}

}  // namespace
}  // namespace dnbridge::devicenet
