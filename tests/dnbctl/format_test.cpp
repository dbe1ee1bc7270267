// dnbctl's output: tables, lines and JSON from the IDL structs.
#include "adapters/dnbctl/format.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topics.hpp"
#include "adapters/dnbctl/json.hpp"
#include "adapters/dnbctl/utf8.hpp"

namespace dnbridge::dnbctl {
namespace {

using dds::Owned;
using dds::set_string;

Owned<dnbridge_PumpState> pump(unsigned mac) {
  Owned<dnbridge_PumpState> s;
  set_string(s->rack, "sim-rack");
  set_string(s->port, "A");
  s->mac = static_cast<std::uint8_t>(mac);
  set_string(s->name, "pump-" + std::to_string(mac));
  s->online = true;
  s->inputs_valid = true;
  s->pump_running = true;
  s->n2_flow_ok = true;
  s->interlock_ok = true;
  s->analog_input_count = 1;
  s->analog_input_raw[0] = 1024;
  s->analog_input_valid[0] = true;
  s->analog_input_volts[0] = 2.5006f;
  s->outputs_idle = false;
  s->pump_on = true;
  s->analog_output_raw = 2048;
  s->analog_output_volts = 5.0012f;
  set_string(s->commanded_by, "dnbctl op@host");
  return s;
}

Owned<dnbridge_NodeStatus> node(unsigned mac) {
  Owned<dnbridge_NodeStatus> n;
  set_string(n->rack, "sim-rack");
  set_string(n->port, "A");
  n->mac = static_cast<std::uint8_t>(mac);
  set_string(n->name, "pump-" + std::to_string(mac));
  n->state = dnbridge_NODE_ONLINE;
  set_string(n->reason, "polled every 100 ms");
  n->vendor_id = 59;
  n->product_type = 27;
  n->product_code = 1888;
  n->major_revision = 1;
  n->minor_revision = 5;
  n->serial_number = 3;
  set_string(n->product_name, "CDN127");
  n->device_state_valid = true;
  n->device_state = 3;
  set_string(n->device_state_text, "operating");
  n->counters.commands_refused = 2;
  set_string(n->last_command_refused, "from x: analog output 5000 is out of range 0..4095");
  return n;
}

Owned<dnbridge_PortStatus> port() {
  Owned<dnbridge_PortStatus> p;
  set_string(p->rack, "sim-rack");
  set_string(p->port, "A");
  set_string(p->can_interface, "simulated");
  p->bitrate = 500000;
  p->state = dnbridge_PORT_RUNNING;
  set_string(p->reason, "scanning");
  p->bus_load_percent = 2.74f;
  p->frames_per_second = 176.0f;
  p->nodes_online = 1;
  p->nodes_configured = 2;
  return p;
}

TEST(Table, AlignsColumnsWithoutTrailingBlanks) {
  Table t({"A", "LONG HEADER", "C"});
  t.add({"wide cell", "x", ""});
  t.add({"y", "z", "last"});
  EXPECT_EQ(t.render(),
            "A          LONG HEADER  C\n"
            "wide cell  x\n"
            "y          z            last\n");
}

TEST(Json, CompactAndPrettyWithEscapes) {
  JsonWriter compact(false);
  compact.begin_object()
      .field("s", "a\"b\\c\n\x01")
      .field("n", -3)
      .field("u", std::uint64_t{18446744073709551615u})
      .field("b", true);
  compact.key("x").number(5.0012, 3);
  compact.key("z").number(-0.0001, 3);
  compact.key("e").begin_array().end_array();
  compact.key("o").begin_object().end_object();
  compact.key("nul").null();
  compact.end_object();
  EXPECT_EQ(compact.str(),
            R"({"s":"a\"b\\c\n\u0001","n":-3,"u":18446744073709551615,"b":true,"x":5.001,)"
            R"("z":0.000,"e":[],"o":{},"nul":null})");

  JsonWriter pretty;
  pretty.begin_object().key("a").begin_array().value(1).value(2).end_array().end_object();
  EXPECT_EQ(pretty.str(), "{\n  \"a\": [\n    1,\n    2\n  ]\n}");
}

TEST(Format, PortJsonCarriesTheExplicitCountsAndTheLoopsBusyTime) {
  auto p = port();
  p->explicit_outstanding = 3;
  p->explicit_retained = 256;
  p->explicit_refused_for_limits = 12;
  p->replies_undelivered = 1;
  p->loop_longest_pass_ms = 0.44f;
  p->max_commander_lease_ms = 10000;
  p->commanders_refused = 2;
  p->endpoints_unmatched = 1;
  JsonWriter out(false);
  out.begin_object();
  port_json_members(out, *p);
  out.end_object();
  EXPECT_NE(out.str().find(R"("explicit_outstanding":3,"explicit_retained":256,)"
                           R"("explicit_refused_for_limits":12,"replies_undelivered":1,)"
                           R"("loop_longest_pass_ms":0.44,"max_commander_lease_ms":10000,)"
                           R"("commanders_refused":2,"endpoints_unmatched":1})"),
            std::string::npos)
      << out.str();
}

TEST(Json, Utf8IsWrittenAsItIsAndBytesThatAreNotAsReplacement) {
  EXPECT_EQ(json_quote("\xC3\xA4tz-3"), "\"\xC3\xA4tz-3\"");  // ä
  EXPECT_EQ(json_quote("\xE3\x83\xA9\xF0\x9F\x98\x80"),
            "\"\xE3\x83\xA9\xF0\x9F\x98\x80\"");              // ラ, an emoji
  EXPECT_EQ(json_quote("\xEF\xBF\xBD"), "\"\xEF\xBF\xBD\"");  // U+FFFD itself
  // Not UTF-8: a lone ISO 8859-1 byte, a stray continuation byte, a
  // truncated sequence, an overlong form, a surrogate.
  EXPECT_EQ(json_quote("\xB5s"), "\"\\ufffds\"");
  EXPECT_EQ(json_quote("a\x80"), "\"a\\ufffd\"");
  EXPECT_EQ(json_quote("\xE3\x83"), "\"\\ufffd\\ufffd\"");
  EXPECT_EQ(json_quote("\xC0\xAF"), "\"\\ufffd\\ufffd\"");
  EXPECT_EQ(json_quote("\xED\xA0\x80"), "\"\\ufffd\\ufffd\\ufffd\"");
  EXPECT_EQ(json_quote("\t\x01\x7F"), "\"\\t\\u0001\\u007f\"");
}

TEST(Utf8, CodePointsAndTheirWidths) {
  EXPECT_EQ(next_code_point("a").value, U'a');
  const auto a_umlaut = next_code_point("\xC3\xA4x");
  EXPECT_EQ(a_umlaut.value, U'\u00E4');
  EXPECT_EQ(a_umlaut.length, 2u);
  const auto emoji = next_code_point("\xF0\x9F\x98\x80");
  EXPECT_EQ(emoji.value, U'\U0001F600');
  EXPECT_EQ(emoji.length, 4u);
  EXPECT_EQ(next_code_point("\xF4\x90\x80\x80").value, kReplacementCharacter);  // > U+10FFFF

  EXPECT_EQ(display_width("etch-3"), 6u);
  EXPECT_EQ(display_width("\xC3\xA4tz-3"), 5u);  // ätz-3: 5 characters, 6 bytes
  EXPECT_EQ(display_width("a\xCC\x88tz"), 3u);   // a + combining diaeresis
  EXPECT_EQ(display_width("\xE3\x83\xA9\xE3\x83\x83\xE3\x82\xAF"), 6u);  // ラック: wide
  EXPECT_EQ(display_width("\xEF\xBC\xA1"), 2u);                          // full-width A
  EXPECT_EQ(display_width("\xF0\x9F\x98\x80"), 2u);                      // emoji
  EXPECT_EQ(display_width("\xB5"), 1u);  // not UTF-8: one replacement
}

TEST(Table, AlignsOnDisplayWidthNotBytes) {
  Table t({"RACK", "PORT"});
  t.add({"\xC3\xA4tz-3", "A"});                          // ätz-3
  t.add({"\xE3\x83\xA9\xE3\x83\x83\xE3\x82\xAF", "B"});  // ラック, 6 columns
  t.add({"etch-3", "C"});
  EXPECT_EQ(t.render(),
            "RACK    PORT\n"
            "\xC3\xA4tz-3   A\n"
            "\xE3\x83\xA9\xE3\x83\x83\xE3\x82\xAF  B\n"
            "etch-3  C\n");
}

TEST(Names, StatusesHaveTheirNames) {
  EXPECT_EQ(transaction_status_text(1), "transaction completed");
  EXPECT_EQ(transaction_status_text(3), "slave not in scan list");
  EXPECT_EQ(transaction_status_text(15), "connection busy");
  EXPECT_EQ(transaction_status_text(7), "unknown status 7");
  EXPECT_EQ(general_status_text(0x00), "success");
  EXPECT_EQ(general_status_text(0x14), "attribute not supported");
  EXPECT_EQ(general_status_text(0x2B), "reserved (0x2B)");
  EXPECT_EQ(general_status_text(0xD0), "object class specific (0xD0)");
  EXPECT_EQ(service_text(0x0E), "Get_Attribute_Single");
  EXPECT_EQ(service_text(0x05), "Reset");
  EXPECT_EQ(service_text(0x4E), "service 0x4E");
  EXPECT_EQ(to_text(dnbridge_NODE_WRONG_DEVICE), "wrong device");
  EXPECT_EQ(to_text(dnbridge_PORT_DUPLICATE_MAC), "duplicate MAC");
  EXPECT_EQ(to_text(dnbridge_BUS_OFF), "bus-off");
}

TEST(PumpLine, ShowsInputsAndAppliedOutputs) {
  auto s = pump(3);
  EXPECT_EQ(
      pump_line(*s, "12:00:00.000"),
      "12:00:00.000 sim-rack/A/3 pump-3 online | running warning=no alarm=no n2_flow=ok "
      "interlock=ok ai1=2.501V | pump=on ballast=off aout=2048 (5.001V) by \"dnbctl op@host\"");
  s->outputs_idle = true;
  EXPECT_NE(pump_line(*s, "t").find("| outputs idle"), std::string::npos);
  s->online = false;
  EXPECT_EQ(pump_line(*s, "t"), "t sim-rack/A/3 pump-3 offline");
}

TEST(PumpJson, CarriesTheAppliedOutputs) {
  auto s = pump(3);
  JsonWriter out(false);
  pump_json(out, *s);
  EXPECT_NE(out.str().find(R"("mac":3)"), std::string::npos);
  EXPECT_NE(out.str().find(R"("pump_on":true)"), std::string::npos);
  EXPECT_NE(out.str().find(R"("analog_output_raw":2048,"analog_output_volts":5.001)"),
            std::string::npos);
  EXPECT_NE(out.str().find(R"("analog_inputs":[{"raw":1024,"valid":true,"volts":2.501}])"),
            std::string::npos);
}

// A channel off the 0..4095 scale: its raw value and "invalid", never volts.
TEST(PumpJson, AnInvalidAnalogInputHasNoVolts) {
  auto s = pump(3);
  s->analog_input_raw[0] = 65535;
  s->analog_input_valid[0] = false;
  s->analog_input_volts[0] = std::numeric_limits<float>::quiet_NaN();
  JsonWriter out(false);
  pump_json(out, *s);
  EXPECT_NE(out.str().find(R"("analog_inputs":[{"raw":65535,"valid":false,"volts":null}])"),
            std::string::npos)
      << out.str();
  EXPECT_NE(pump_line(*s, "12:00:00.000").find(" ai1=invalid(65535) "), std::string::npos)
      << pump_line(*s, "12:00:00.000");
}

TEST(OutputsText, VoltsFromRaw) {
  EXPECT_EQ(outputs_text(true, false, 2048), "pump on, N2 ballast off, analog out 2048 (5.001 V)");
  EXPECT_EQ(outputs_text(false, true, 4095), "pump off, N2 ballast on, analog out 4095 (10.000 V)");
}

TEST(List, TablesAndJsonNestNodesUnderPorts) {
  auto p = port();
  auto n1 = node(1);
  auto n2 = node(2);
  n2->state = dnbridge_NODE_ABSENT;
  set_string(n2->reason, "no answer to allocation");
  auto s1 = pump(1);
  const std::vector<PortRow> ports{{p.get(), true}};
  const std::vector<NodeRow> nodes{{n2.get(), nullptr, true}, {n1.get(), s1.get(), true}};

  EXPECT_EQ(ports_table(ports),
            "RACK      PORT  BRIDGE  STATE    BUS           LOAD  FRAMES/S  NODES       "
            "INTERFACE                REASON\n"
            "sim-rack  A     live    running  error-active  2.7%  176       1/2 online  "
            "simulated 500k master 0  scanning\n");
  const std::string table = nodes_table(nodes);
  EXPECT_NE(
      table.find("sim-rack  A     2    pump-2  absent  no      CDN127   no answer to allocation"),
      std::string::npos)
      << table;
  EXPECT_NE(table.find("sim-rack  A     1    pump-1  online  yes     CDN127   polled every 100 ms"),
            std::string::npos)
      << table;

  JsonWriter out(false);
  list_json(out, ports, nodes);
  const std::string& j = out.str();
  EXPECT_EQ(j.rfind(R"({"racks":[{"rack":"sim-rack","bridge_alive":true,"ports":[{"port":"A",)", 0),
            0u)
      << j;
  // Nodes sorted by MAC inside their port.
  const auto first = j.find(R"({"mac":1,"name":"pump-1","state":"online")");
  const auto second = j.find(R"({"mac":2,"name":"pump-2","state":"absent")");
  ASSERT_NE(first, std::string::npos) << j;
  ASSERT_NE(second, std::string::npos) << j;
  EXPECT_LT(first, second);
  EXPECT_NE(j.find(R"("product":"CDN127","online":true})"), std::string::npos);
  EXPECT_NE(j.find(R"("product":"CDN127","online":false})"), std::string::npos);
}

TEST(List, AGoneBridgeIsMarkedAndItsNodesAreNotOnline) {
  auto p = port();
  auto n = node(1);
  auto s = pump(1);
  const std::vector<PortRow> ports{{p.get(), false}};
  const std::vector<NodeRow> nodes{{n.get(), s.get(), false}};
  EXPECT_NE(ports_table(ports).find("gone"), std::string::npos);
  EXPECT_NE(nodes_table(nodes).find("no      CDN127   bridge gone: "), std::string::npos);
  JsonWriter out(false);
  list_json(out, ports, nodes);
  EXPECT_NE(out.str().find(R"("bridge_alive":false)"), std::string::npos);
  EXPECT_NE(out.str().find(R"("online":false)"), std::string::npos);
}

TEST(Show, IdentityStateAndCounters) {
  auto n = node(3);
  auto s = pump(3);
  const std::string text = node_details(*n, s.get(), true);
  for (const char* line :
       {"node                      sim-rack/A/3 (pump-3)\n", "state                     online\n",
        "product name              CDN127\n", "vendor                    59 (0x003B)\n",
        "product type              27 (0x001B)\n", "product code              1888 (0x0760)\n",
        "revision                  1.5\n", "serial number             3 (0x00000003)\n",
        "device state              3 (operating)\n",
        "last refused command      from x: analog output 5000 is out of range 0..4095\n",
        "  commands refused        2\n"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\nin:\n" << text;
  }
  JsonWriter out(false);
  node_json(out, *n, s.get(), true);
  EXPECT_NE(out.str().find(R"("identity":{"vendor_id":59,"product_type":27,"product_code":1888,)"
                           R"("major_revision":1,"minor_revision":5,"serial_number":3,)"
                           R"("product_name":"CDN127"})"),
            std::string::npos)
      << out.str();
}

// A device's fields: their values as JSON numbers, as the text shows them.
TEST(Show, ADevicesFieldsAreNumbersInJson) {
  auto n = node(21);
  char name[] = "Analog input 1", type[] = "INT", units[] = "mV", empty[] = "";
  char bits_name[] = "Digital inputs", bits_type[] = "BYTE";
  std::array<dnbridge_DeviceField, 3> fields{};
  fields[0] = {name, 4, type, units, 8, 16, -1000.0, -2.5};
  fields[1] = {bits_name, 3, bits_type, empty, 0, 8, 165.0, 165.0};
  fields[2] = {bits_name, 3, bits_type, empty, 0, 8, 0.0, std::nan("")};
  dnbridge_DeviceState d{};
  char product[] = "Example IO block";
  d.product = product;
  d.inputs_valid = true;
  d.input_fields._buffer = fields.data();
  d.input_fields._length = d.input_fields._maximum = fields.size();
  d.outputs_idle = true;
  JsonWriter out(false);
  node_json(out, *n, nullptr, true, &d);
  EXPECT_NE(out.str().find(R"("name":"Analog input 1","type":"INT","units":"mV","bit_offset":8,)"
                           R"("bits":16,"value":-1000,"shown":-2.5})"),
            std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find(R"("bits":8,"value":165,"shown":165})"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find(R"("value":0,"shown":null})"), std::string::npos) << out.str();
  EXPECT_NE(node_details(*n, nullptr, true, &d).find("Analog input 1 = -2.5 mV"),
            std::string::npos);
}

ExplicitExchange get_name() {
  ExplicitExchange x;
  x.rack = "sim-rack";
  x.port = "A";
  x.mac = 3;
  x.service = 0x0E;
  x.class_id = 1;
  x.instance_id = 1;
  x.attribute = 7;
  x.status = 1;
  x.general_status = 0;
  x.data = {0x06, 'C', 'D', 'N', '1', '2', '7'};
  return x;
}

TEST(Explicit, SuccessWithDecodedString) {
  const auto x = get_name();
  EXPECT_TRUE(x.succeeded());
  const std::optional<Parsed<std::string>> decoded = decode_data(x.data, Decoding::kString);
  EXPECT_EQ(explicit_text(x, Decoding::kString, decoded),
            "sim-rack/A/3 Get_Attribute_Single class 0x01 instance 1 attribute 7\n"
            "status: 1 (transaction completed)\n"
            "CIP general status: 0x00 (success)\n"
            "data (7 bytes): 06 43 44 4E 31 32 37\n"
            "as string: \"CDN127\"\n");
  JsonWriter out(false);
  explicit_json(out, x, Decoding::kString, decoded);
  EXPECT_NE(
      out.str().find(R"("status":1,"status_text":"transaction completed","general_status":0,)"
                     R"("general_status_text":"success","additional_status":255,"message":"",)"
                     R"("data":"06 43 44 4E 31 32 37","succeeded":true,)"
                     R"("decoded":{"as":"string","value":"CDN127"}})"),
      std::string::npos)
      << out.str();
}

TEST(Explicit, IntegersAreJsonNumbers) {
  auto x = get_name();
  x.data = {0x60, 0x07};
  const std::optional<Parsed<std::string>> decoded = decode_data(x.data, Decoding::kUint);
  JsonWriter out(false);
  explicit_json(out, x, Decoding::kUint, decoded);
  EXPECT_NE(out.str().find(R"("decoded":{"as":"uint","value":1888})"), std::string::npos);
}

TEST(Explicit, DeviceErrorShowsTheCipStatusByName) {
  auto x = get_name();
  x.attribute = 99;
  x.general_status = 0x14;
  x.data.clear();
  x.message = "device error 0x14/0xFF: attribute not supported";
  EXPECT_FALSE(x.succeeded());
  const std::string text = explicit_text(x, Decoding::kNone, std::nullopt);
  EXPECT_NE(text.find("CIP general status: 0x14 (attribute not supported)\n"), std::string::npos)
      << text;
  EXPECT_EQ(text.find("data ("), std::string::npos) << text;  // no data: nothing to show
}

TEST(Explicit, BridgeStatusWithoutDeviceAnswer) {
  auto x = get_name();
  x.mac = 40;
  x.status = 3;
  x.data.clear();
  x.message = "MAC 40 is not in the scan list of port A";
  const std::string text = explicit_text(x, Decoding::kNone, std::nullopt);
  EXPECT_NE(text.find("status: 3 (slave not in scan list)\n"), std::string::npos);
  EXPECT_EQ(text.find("CIP general status"), std::string::npos);  // the device was not asked
  EXPECT_NE(text.find("message: MAC 40 is not in the scan list of port A\n"), std::string::npos);
  JsonWriter out(false);
  explicit_json(out, x, Decoding::kNone, std::nullopt);
  EXPECT_NE(
      out.str().find(R"("status":3,"status_text":"slave not in scan list","general_status":null,)"
                     R"("general_status_text":null,"additional_status":null,)"),
      std::string::npos)
      << out.str();
}

TEST(Explicit, SuccessWithoutData) {
  auto x = get_name();
  x.service = 0x05;
  x.attribute.reset();
  x.data.clear();
  EXPECT_EQ(explicit_text(x, Decoding::kNone, std::nullopt),
            "sim-rack/A/3 Reset class 0x01 instance 1\n"
            "status: 1 (transaction completed)\n"
            "CIP general status: 0x00 (success)\n"
            "data: none\n");
}

// A string sequence as a sample read from DDS holds it, freed with the
// sample.
void set_strings(dds_sequence_string& seq, std::initializer_list<std::string_view> lines) {
  seq._buffer = static_cast<char**>(dds_alloc(sizeof(char*) * lines.size()));
  seq._maximum = seq._length = static_cast<std::uint32_t>(lines.size());
  seq._release = true;
  std::uint32_t i = 0;
  for (const auto line : lines) {
    seq._buffer[i] = nullptr;
    set_string(seq._buffer[i++], line);
  }
}

Owned<dnbridge_ReloadReply> reload_reply(std::uint8_t status) {
  Owned<dnbridge_ReloadReply> r;
  set_string(r->requester, "dnbctl@host:1:2");
  r->txid = 1;
  set_string(r->rack, "sim-rack");
  r->status = status;
  set_string(r->file, "/etc/dnbridge/sim-rack.toml");
  return r;
}

TEST(Reload, AppliedListsWhatChangedAndWhatWaitsForARestart) {
  auto r = reload_reply(dnbridge_RELOAD_APPLIED);
  set_string(r->message, "configuration applied: 2 changes");
  set_strings(r->applied, {"port A: node 12 added", "port A: node 3 renamed \"dry-pump\""});
  set_strings(r->needs_restart, {"metrics address"});
  EXPECT_EQ(reload_text(*r),
            "rack sim-rack: configuration applied: 2 changes\n"
            "file: /etc/dnbridge/sim-rack.toml\n"
            "applied:\n"
            "  port A: node 12 added\n"
            "  port A: node 3 renamed \"dry-pump\"\n"
            "needs a restart:\n"
            "  metrics address\n");
  JsonWriter out(false);
  reload_json(out, *r);
  EXPECT_EQ(out.str(),
            R"({"rack":"sim-rack","status":"applied","message":"configuration applied: 2 changes",)"
            R"("file":"/etc/dnbridge/sim-rack.toml","applied":["port A: node 12 added",)"
            R"("port A: node 3 renamed \"dry-pump\""],"needs_restart":["metrics address"],)"
            R"("problems":[]})");
}

TEST(Reload, RefusedListsTheProblemsOnly) {
  auto r = reload_reply(dnbridge_RELOAD_REFUSED);
  set_string(r->message, "the file has problems: nothing changed");
  set_strings(r->problems, {"/etc/dnbridge/sim-rack.toml:12:7: unknown key 'nmae'"});
  EXPECT_EQ(reload_text(*r),
            "rack sim-rack: the file has problems: nothing changed\n"
            "file: /etc/dnbridge/sim-rack.toml\n"
            "problems:\n"
            "  /etc/dnbridge/sim-rack.toml:12:7: unknown key 'nmae'\n");
  JsonWriter out(false);
  reload_json(out, *r);
  EXPECT_NE(out.str().find(R"("status":"refused",)"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find(R"("applied":[],"needs_restart":[],"problems":["/etc/)"),
            std::string::npos)
      << out.str();
}

TEST(Reload, StatusWordsAndAReplyWithoutFileOrMessage) {
  EXPECT_EQ(reload_status_word(dnbridge_RELOAD_APPLIED), "applied");
  EXPECT_EQ(reload_status_word(dnbridge_RELOAD_REFUSED), "refused");
  EXPECT_EQ(reload_status_word(dnbridge_RELOAD_BUSY), "busy");
  EXPECT_EQ(reload_status_word(dnbridge_RELOAD_NO_FILE), "no-file");
  EXPECT_EQ(reload_status_word(dnbridge_RELOAD_INCOMPLETE), "incomplete");
  EXPECT_EQ(reload_status_word(0), "unknown");
  auto r = reload_reply(dnbridge_RELOAD_NO_FILE);
  set_string(r->file, "");
  EXPECT_EQ(reload_text(*r), "rack sim-rack: no-file\n");
  JsonWriter out(false);
  reload_json(out, *r);
  EXPECT_EQ(out.str(),
            R"({"rack":"sim-rack","status":"no-file","message":"","file":"","applied":[],)"
            R"("needs_restart":[],"problems":[]})");
}

}  // namespace
}  // namespace dnbridge::dnbctl
