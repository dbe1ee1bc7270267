#pragma once
// The product's DDS contract in one place: which generated type travels on
// which topic (idl/dnbridge.idl), and the QoS of each side. The bridge
// daemon, the dnbctl client and the tests all take their QoS from here, so
// that the two sides of every topic always match.
#include <cstdint>
#include <optional>

#include "adapters/dds/fields.hpp"
#include "adapters/dds/qos.hpp"
#include "adapters/dds/topic.hpp"
#include "dnbridge.h"

namespace dnbridge::dds {

template <>
struct TopicTraits<dnbridge_PumpState> {
  static constexpr const char* kName = "dnbridge/PumpState";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_PumpState_desc;
};
template <>
struct TopicTraits<dnbridge_PumpCommand> {
  static constexpr const char* kName = "dnbridge/PumpCommand";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_PumpCommand_desc;
};
template <>
struct TopicTraits<dnbridge_NodeStatus> {
  static constexpr const char* kName = "dnbridge/NodeStatus";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_NodeStatus_desc;
};
template <>
struct TopicTraits<dnbridge_PortStatus> {
  static constexpr const char* kName = "dnbridge/PortStatus";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_PortStatus_desc;
};
template <>
struct TopicTraits<dnbridge_ExplicitRequest> {
  static constexpr const char* kName = "dnbridge/ExplicitRequest";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_ExplicitRequest_desc;
};
template <>
struct TopicTraits<dnbridge_ExplicitReply> {
  static constexpr const char* kName = "dnbridge/ExplicitReply";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_ExplicitReply_desc;
};

// --- State topics: PumpState, NodeStatus, PortStatus -------------------------
// Reliable, transient-local, keep-last 1: a late joiner gets each instance's
// current state at once. Automatic liveliness (a bridge that dies is noticed
// through its participant's lease). Ordered by source timestamp (the CAN
// receive time). Instances are unregistered at shutdown, never disposed: the
// `online` member says "offline", so deleting the writer must not dispose.

// `deadline`: the longest gap the bridge promises between two samples of an
// instance, derived from the node's publish period.
Qos state_writer_qos(Duration deadline);
// `deadline`: what the reader asks for; it must be at least the writer's
// (DDS matches only offered <= requested); none to match any writer.
Qos state_reader_qos(std::optional<Duration> deadline = std::nullopt);

// --- PumpCommand ---------------------------------------------------------------
// Reliable, volatile, keep-last 1; exclusive ownership: of the live writers
// of an instance the strongest commands. Automatic liveliness with `lease`:
// a supervisor that stops renewing its lease loses its instances, which then
// pass to the next strongest writer or, with none left, go NOT_ALIVE_NO_WRITERS.
// Autodispose is off: a departing stronger writer must only unregister, so
// that the instance stays alive while a weaker writer still commands it.
Qos command_writer_qos(int32_t strength, Duration lease);
Qos command_reader_qos();

// --- ExplicitRequest / ExplicitReply -------------------------------------------
// Reliable and keep-all (no request or reply is overwritten while waiting),
// bounded: a port runs one explicit transaction per node at a time and a rack
// has a few ports of at most 64 nodes, so 256 outstanding requests is far
// above what a bridge can execute, while keeping memory bounded. A
// transaction is one instance; 4 samples per instance leave room for a
// repeated request or the IN_PROGRESS and final replies of a GET_STATUS.
// Past a limit a write blocks for at most the reliability max_blocking_time
// and then fails with DDS_RETCODE_TIMEOUT: pushed back, never dropped.
// A reader keeps an instance for as long as a writer has it registered, even
// with no sample left, so each side unregisters a transaction's instance
// once done with it (the requester after its reply, the bridge when it
// forgets the transaction); readers skip the invalid samples that follow.
inline constexpr int32_t kExplicitMaxSamples = 256;
inline constexpr int32_t kExplicitMaxInstances = 256;
inline constexpr int32_t kExplicitMaxSamplesPerInstance = 4;
// Every reply reader receives the replies of every requester, and a bridge
// keeps the replies of the transactions it remembers registered (256 per
// port, plus the last 256 refusals and status answers): reply readers take
// far more instances than request readers, so that a bridge's writer is
// never pushed back by a reader that is full of other requesters' replies.
inline constexpr int32_t kReplyMaxInstances = 8192;
inline constexpr int32_t kReplyMaxSamples = 8192;

// Requests are volatile: a bridge that starts must never execute requests
// written before it existed (a stale Set_Attribute would be replayed). A
// requester that wrote before the bridge matched gets no reply and repeats
// the request (same key: the same reply, not a second execution).
Qos request_writer_qos();
Qos request_reader_qos();

// Replies are transient-local: the bridge may answer before its reply writer
// has discovered the requester's reply reader (discovery of the two topics is
// independent), and a volatile reply would then be lost. The writer keeps the
// last reply of each transaction (durability service keep-last 1) for such a
// late reader; the bridge unregisters a transaction's instance when it
// forgets the transaction, which releases it from that cache.
Qos reply_writer_qos();
Qos reply_reader_qos();

}  // namespace dnbridge::dds
