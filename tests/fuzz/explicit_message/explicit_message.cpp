// Explicit message codecs: requests in every body format, responses, the
// Allocate response data and body format codes. Input: [selector][message...];
// the selector's low 2 bits name the body format the request is decoded in.
// Properties: whatever decodes re-encodes to the very same bytes and decodes
// again to the same fields; the decoded service data points into the input;
// encoders refuse outputs one byte too small.
#include "bridge/devicenet/wire/explicit_message.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::devicenet;

namespace {

bool same(Bytes a, Bytes b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] != b[i]) return false;
  }
  return true;
}

bool inside(Bytes part, Bytes whole) {
  return part.empty() ||
         (part.data() >= whole.data() && part.data() + part.size() <= whole.data() + whole.size());
}

void check_request(Bytes message, BodyFormat format) {
  auto req = decode_request(message, format);
  if (!req) return;
  FUZZ_CHECK((req->service & cip::kResponseFlag) == 0);
  FUZZ_CHECK(inside(req->data, message));
  const std::size_t size = encoded_size(*req, format);
  FUZZ_CHECK(size == message.size());
  std::array<std::uint8_t, kMaxExplicitMessage + 8> buf{};
  if (size > buf.size()) return;
  auto n = encode_request(*req, format, MutableBytes(buf.data(), size));
  FUZZ_CHECK(n.ok() && *n == size);
  FUZZ_CHECK(same(Bytes(buf.data(), *n), message));
  if (size > 0) {
    auto small = encode_request(*req, format, MutableBytes(buf.data(), size - 1));
    FUZZ_CHECK(!small.ok());
  }
  auto again = decode_request(Bytes(buf.data(), *n), format);
  FUZZ_CHECK(again.ok());
  FUZZ_CHECK(again->service == req->service && again->class_id == req->class_id &&
             again->instance_id == req->instance_id && again->attribute == req->attribute &&
             same(again->data, req->data));
}

void check_response(Bytes message) {
  auto resp = decode_response(message);
  if (!resp) return;
  FUZZ_CHECK(!message.empty() && (message[0] & cip::kResponseFlag) != 0);
  FUZZ_CHECK(inside(resp->data, message));
  std::array<std::uint8_t, kMaxExplicitMessage + 8> buf{};
  if (resp->is_error()) {
    FUZZ_CHECK(resp->general_status != cip::GeneralStatus::kSuccess);
    FUZZ_CHECK(resp->data.empty());
    auto n =
        encode_error_response(resp->general_status, resp->additional_status, MutableBytes(buf));
    FUZZ_CHECK(n.ok());
    // The additional code may be missing (read as 0xFF) and bytes after it
    // are ignored: the encoding matches the input up to what was read.
    const std::size_t common = message.size() < *n ? message.size() : *n;
    FUZZ_CHECK(same(Bytes(buf.data(), common), message.first(common)));
    auto again = decode_response(Bytes(buf.data(), *n));
    FUZZ_CHECK(again.ok() && again->is_error() && again->general_status == resp->general_status &&
               again->additional_status == resp->additional_status);
  } else {
    FUZZ_CHECK(resp->general_status == cip::GeneralStatus::kSuccess);
    if (message.size() > buf.size()) return;
    auto n = encode_success_response(resp->service, resp->data,
                                     MutableBytes(buf.data(), message.size()));
    FUZZ_CHECK(n.ok() && *n == message.size());
    FUZZ_CHECK(same(Bytes(buf.data(), *n), message));
    auto small = encode_success_response(resp->service, resp->data,
                                         MutableBytes(buf.data(), message.size() - 1));
    FUZZ_CHECK(!small.ok());
    auto again = decode_response(Bytes(buf.data(), *n));
    FUZZ_CHECK(again.ok() && again->service == resp->service && same(again->data, resp->data));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const Bytes message(data + 1, size - 1);

  // Every body format, so each input exercises the four field layouts.
  for (std::uint8_t code = 0; code < 4; ++code) {
    auto format = body_format_from_code(code);
    FUZZ_CHECK(format.ok());
    check_request(message, *format);
  }
  const auto selected = body_format_from_code(data[0]);
  FUZZ_CHECK(selected.ok() == (data[0] <= 3));
  check_response(message);

  auto alloc = decode_allocate_response_data(message);
  if (!message.empty()) {
    FUZZ_CHECK(alloc.ok() == ((message[0] & 0x0F) <= 3));
  } else {
    FUZZ_CHECK(!alloc.ok());
  }

  // A whole frame: header byte, then an unfragmented message.
  if (size <= can::kMaxDataLength) {
    const ExplicitHeader h = decode_header(data[0]);
    FUZZ_CHECK(encode_header(h) == data[0]);
  }
  return 0;
}
