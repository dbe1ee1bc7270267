#pragma once
// What the parts of dnbctl's formatting share (format.cpp: names and tables;
// format_list.cpp: list; format_watch.cpp: watch; format_show.cpp: show;
// format_replies.cpp: get, set, service and reload): the yes/no and on/off
// words, and a pump's record, which show nests in a node's.
#include "adapters/dnbctl/record.hpp"
#include "dnbridge.h"

namespace dnbridge::dnbctl::format_detail {

// "yes" or "no", "on" or "off" (format.cpp).
const char* yes_no(bool b);
const char* on_off(bool b);

// A pump's PumpState as `watch` and `show` show it (format_watch.cpp).
Record pump_record(const dnbridge_PumpState& s);

}  // namespace dnbridge::dnbctl::format_detail
