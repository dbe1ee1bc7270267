#pragma once
// The product's DDS contract in one place: which generated type travels on
// which topic (idl/dnbridge.idl), and the QoS of each side. The bridge
// daemon, the dnbctl client and the tests all take their QoS from here, so
// that the two sides of every topic always match.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

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
struct TopicTraits<dnbridge_DeviceState> {
  static constexpr const char* kName = "dnbridge/DeviceState";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_DeviceState_desc;
};

template <>
struct TopicTraits<dnbridge_DeviceCommand> {
  static constexpr const char* kName = "dnbridge/DeviceCommand";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_DeviceCommand_desc;
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
template <>
struct TopicTraits<dnbridge_BusScanRequest> {
  static constexpr const char* kName = "dnbridge/BusScanRequest";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_BusScanRequest_desc;
};
template <>
struct TopicTraits<dnbridge_BusScanReply> {
  static constexpr const char* kName = "dnbridge/BusScanReply";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_BusScanReply_desc;
};
template <>
struct TopicTraits<dnbridge_ReloadRequest> {
  static constexpr const char* kName = "dnbridge/ReloadRequest";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_ReloadRequest_desc;
};
template <>
struct TopicTraits<dnbridge_ReloadReply> {
  static constexpr const char* kName = "dnbridge/ReloadReply";
  static constexpr const dds_topic_descriptor_t* kDescriptor = &dnbridge_ReloadReply_desc;
};

// --- Partitions ----------------------------------------------------------------
// What is for one rack, PumpCommand, DeviceCommand and the requests (ExplicitRequest,
// BusScanRequest, ReloadRequest) with their replies, is published and read
// in that rack's partition, "dnbridge/RACK": DDS delivers a bridge only its
// own rack's commands and requests, and a command goes to the one bridge
// that serves its pump. The state topics (PumpState, DeviceState, NodeStatus, PortStatus)
// are in the default partition, so that one reader sees every rack; so are
// readers that set no partition (a generic tool). A client of several racks
// reads their replies with each rack's partition, or with
// kEveryRackPartition. A rack name holds no '*' or '?' (the configuration
// refuses them): partition names with those match as patterns.
std::string rack_partition(std::string_view rack);
inline constexpr std::string_view kEveryRackPartition = "dnbridge/*";
// The partition list of a writer or reader of these racks' topics, or of
// one rack's.
std::vector<std::string> rack_partitions(std::span<const std::string> racks);
std::vector<std::string> rack_partitions(std::string_view rack);

// --- State topics: PumpState, DeviceState, NodeStatus, PortStatus -------------
// Reliable, transient-local, keep-last 1: a late joiner gets each instance's
// current state at once. Automatic liveliness (a bridge that dies is noticed
// through its participant's lease). Ordered by source timestamp (the CAN
// receive time). Instances are unregistered at shutdown, never disposed: the
// `online` member says "offline", so deleting the writer must not dispose.

// `deadline`: the longest gap the bridge promises between two samples of an
// instance, derived from the node's publish period. Keep-last, which Cyclone
// DDS 0.10.2 never holds back for readers that have not acknowledged; its max
// blocking time is 0, so that a write that would have to wait for room (a
// full reader history in the same process) fails at once instead.
Qos state_writer_qos(Duration deadline);
// `deadline`: what the reader asks for; it must be at least the writer's
// (DDS matches only offered <= requested); none to match any writer.
Qos state_reader_qos(std::optional<Duration> deadline = std::nullopt);

// --- PumpCommand, DeviceCommand ------------------------------------------------
// Reliable, volatile, keep-last 1; exclusive ownership: of the live writers
// of an instance the strongest commands. Automatic liveliness with `lease`:
// a supervisor that stops renewing its lease loses its instances, which then
// pass to the next strongest writer or, with none left, go NOT_ALIVE_NO_WRITERS.
// Autodispose is off: a departing stronger writer must only unregister, so
// that the instance stays alive while a weaker writer still commands it.
// `partitions`: rack_partitions(...) of the racks written to or read.
//
// `deadline`, when given: the writer promises to write each instance at
// least that often. A bridge whose nodes have a command refresh
// (command_refresh_ms) takes their commands only from writers offering a
// deadline of at most that.
Qos command_writer_qos(std::span<const std::string> partitions, int32_t strength, Duration lease,
                       std::optional<Duration> deadline = std::nullopt);
// The bridge's: it requests a lease of at most `max_lease`, so that a writer
// offering a longer one (or an infinite one) does not match, and, for the
// nodes with a command refresh, a deadline of `deadline` (none: any writer's).
// The deadline makes a writer that does not promise the refresh refuse to
// match; it does not hand a silent owner's instance to a weaker writer: Cyclone
// DDS renews an instance's deadline on the samples exclusive ownership
// rejects too, so a weaker writer that keeps writing keeps the silent
// owner's deadline met (the bridge's own refresh idles the node).
// kDefaultMaxCommanderLease is the bridge's max_commander_lease_ms when its
// configuration gives none.
inline constexpr Duration kDefaultMaxCommanderLease = seconds(10);
Qos command_reader_qos(std::span<const std::string> partitions,
                       Duration max_lease = kDefaultMaxCommanderLease,
                       std::optional<Duration> deadline = std::nullopt);

// --- ExplicitRequest / ExplicitReply -------------------------------------------
// Reliable. A transaction is one instance; keep-last 4 per instance leaves
// room for a repeated request, or the IN_PROGRESS and final replies of a
// GET_STATUS.
//
// Readers never refuse a sample: no resource limits. With Cyclone DDS 0.10 a
// reader that rejects a reliable sample (a full keep-all history, a limit on
// instances) makes the thread that delivers it retry until the reader takes
// something, and that thread delivers every reader of the participant: one
// client that filled the bridge's request reader would stop the bridge from
// taking anyone's commands. The bridge takes every request at once and
// answers the excess itself, with OUT_OF_BUFFERS (its per-requester and
// per-port limits), so the number of requests it holds stays bounded where
// it can say so.
//
// A reader keeps an instance for as long as a writer has it registered, even
// with no sample left, so a requester unregisters a transaction's request
// instance once it has the reply; the bridge skips the invalid sample that
// follows.
inline constexpr int32_t kExplicitHistoryDepth = 4;

// Requests are volatile: a bridge that starts must never execute requests
// written before it existed (a stale Set_Attribute would be replayed). A
// requester that wrote before the bridge matched gets no reply and repeats
// the request (same key: the same reply, not a second execution).
// The writer's history is keep-all, bounded: a requester that writes faster
// than the bridge acknowledges waits up to the max_blocking_time and then
// gets DDS_RETCODE_TIMEOUT, in its own process.
inline constexpr int32_t kRequestWriterMaxSamples = 256;
Qos request_writer_qos(std::span<const std::string> partitions);
Qos request_reader_qos(std::span<const std::string> partitions);

// Replies are transient-local: the bridge may answer before its reply writer
// has discovered the requester's reply reader (discovery of the two topics is
// independent), and a volatile reply would then be lost. Such a late reader
// gets the last kReplyHistory replies.
//
// Replies have no key: one instance, never unregistered while the bridge
// runs. Keyed per transaction, each reply would register an instance of its
// own, and Cyclone DDS 0.10.2 keeps about 330 bytes per transient-local
// writer instance for good once it is unregistered (its writer history
// cache does not drop its reference to the instance's key; fixed upstream
// in Cyclone DDS 11): a bridge answering one request a second would grow by
// some 28 MB a day. Readers are keep-all, so that replies to other
// requesters never push out a requester's own, and keep those with their
// requester name.
//
// The writer's history is keep-last kReplyHistory of its one instance: a
// reader that stops acknowledging (a client process whose Cyclone receive
// thread waits, in a listener or on a reader that refuses a sample, and
// which acknowledges nothing any more while its participant stays alive)
// holds at most that many replies in the writer, never the writer itself.
// Keep-all, the writer kept every reply that reader had not acknowledged;
// once those passed Cyclone's high-water mark, every write waited and
// failed, for every requester, for as long as that process lived. A reply a
// working reader misses on the wire and asks for after kReplyHistory newer
// ones were written is lost to it: its requester repeats the request and
// gets the same reply (ExplicitGateway keeps completed transactions).
// The bridge's participant also fixes Cyclone's high-water mark above what
// its bounded histories can hold (participant.hpp).
inline constexpr int32_t kReplyHistory = 256;
Qos reply_writer_qos(std::span<const std::string> partitions);
Qos reply_reader_qos(std::span<const std::string> partitions);

// BusScanRequest / BusScanReply (a port's bus scan) follow the same
// contract: request_*_qos() for requests (keyed by requester and txid),
// reply_reader_qos() for reply readers (no key, one instance). A scan reply
// is larger (up to 63 findings, some 30 KiB at most): the writer keeps the
// last kScanReplyHistory, which bounds what it holds for a reader that
// stopped acknowledging to well under a MiB.
inline constexpr int32_t kScanReplyHistory = 16;
Qos scan_reply_writer_qos(std::span<const std::string> partitions);
// ReloadRequest / ReloadReply (a configuration read again) follow it too,
// with scan_reply_writer_qos() for the replies (a few KiB each at most).

}  // namespace dnbridge::dds
