// CDN127 device-information decoders (Identity and Device Supervisor
// attribute values). Input: [selector][value...]; the selector names the
// decoder, and every decoder also sees the value.
// Properties: fixed-size values decode only at their size; a SHORT_STRING
// decodes only when its length byte covers the rest exactly; the supervisor
// detail accounts for every byte it was given; names exist for every value.
#include "bridge/profiles/cdn127/device_info.hpp"

#include <cstddef>
#include <cstdint>

#include "tests/fuzz/support/fuzz_check.hpp"

using namespace dnbridge;
using namespace dnbridge::profiles::cdn127;

namespace {

void check_detail(Bytes value) {
  auto d = decode_supervisor_detail(value);
  if (!d) return;
  FUZZ_CHECK(d->point_count <= 4);
  // Sizes as sent add up to the value: three size bytes and their contents.
  FUZZ_CHECK(3 + d->common.size() + d->device_size + d->manufacturer.size() == value.size());
  std::size_t points = 0;
  for (std::size_t i = 0; i < d->point_count; ++i) {
    const PointStatus& p = d->points[i];
    points += 1 + (p.count + 7U) / 8U;
    FUZZ_CHECK(!p.fault(p.count));
    bool any = false;
    for (std::size_t b = 0; b < p.count; ++b) any = any || p.fault(b);
    FUZZ_CHECK(any == p.any_fault());
  }
  FUZZ_CHECK(points + d->device_extra.size() == d->device_size);
  if (d->device_extra.size() != 0) FUZZ_CHECK(d->point_count == 4);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const Bytes value(data + 1, size - 1);

  auto rev = decode_revision(value);
  FUZZ_CHECK(rev.ok() == (value.size() == 2));
  auto status = decode_identity_status(value);
  FUZZ_CHECK(status.ok() == (value.size() == 2));
  if (status)
    FUZZ_CHECK(status->any_fault() ==
               (status->minor_recoverable_fault() || status->minor_unrecoverable_fault() ||
                status->major_recoverable_fault() || status->major_unrecoverable_fault()));
  auto serial = decode_serial_number(value);
  FUZZ_CHECK(serial.ok() == (value.size() == 2 || value.size() == 4));
  if (serial) FUZZ_CHECK(serial->width == value.size());

  auto name = decode_product_name(value);
  FUZZ_CHECK(name.ok() == (!value.empty() && value[0] + 1U == value.size()));
  if (name) {
    FUZZ_CHECK(name->size() == value[0]);
    for (std::size_t i = 0; i < name->size(); ++i) {
      FUZZ_CHECK(static_cast<std::uint8_t>(name->view()[i]) == value[1 + i]);
    }
  }

  auto state = decode_identity_state(value);
  FUZZ_CHECK(state.ok() == (value.size() == 1));
  if (state) FUZZ_CHECK(!to_string(*state).empty());
  auto dev = decode_supervisor_device_status(value);
  FUZZ_CHECK(dev.ok() == (value.size() == 1));
  if (dev) FUZZ_CHECK(!to_string(*dev).empty());
  auto exc = decode_exception_status(value);
  FUZZ_CHECK(exc.ok() == (value.size() == 1));
  if (exc) FUZZ_CHECK(ExceptionStatus::decode(exc->encode()) == *exc);

  check_detail(value);
  // The selector picks a suffix too, so detail structures can start anywhere.
  if (data[0] < value.size()) check_detail(value.subspan(data[0]));
  return 0;
}
