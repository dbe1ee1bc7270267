#pragma once
// A typed data reader. Samples are taken (or read) into owned copies: Cyclone
// deserialises straight into structs of ours, whose strings and sequences
// Sample<T> (or TakeBuffer<T>) frees, so no loan is ever outstanding.
// Creation throws Error; every operation after that returns a Status or Result.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "adapters/dds/entity.hpp"
#include "adapters/dds/participant.hpp"
#include "adapters/dds/qos.hpp"
#include "adapters/dds/sample.hpp"
#include "adapters/dds/topic.hpp"

namespace dnbridge::dds {

// Triggers (in a waitset) while the reader holds samples matching `mask`, a
// combination of the DDS_*_SAMPLE_STATE, DDS_*_VIEW_STATE and
// DDS_*_INSTANCE_STATE masks (DDS_ANY_STATE for all). Taking through the
// condition takes only those samples.
class ReadCondition : public Entity {
 public:
  ReadCondition(const Entity& reader, uint32_t mask)
      : Entity(check(dds_create_readcondition(reader.handle(), mask), "creating a read condition")),
        reader_(reader.handle()) {}
  dds_entity_t reader() const noexcept { return reader_; }

 private:
  dds_entity_t reader_;
};

template <class T>
class Reader;

// Storage a reader takes into again and again, for a reader on a hot path:
// its samples keep their strings and sequences from one take to the next,
// Cyclone deserialises into them (reallocating only a member that grows), so
// once the buffer has held samples of every size a take allocates nothing.
// A sample stays valid until the next take into the buffer.
template <class T>
class TakeBuffer {
 public:
  explicit TakeBuffer(std::size_t capacity)
      : samples_(capacity), buffers_(capacity), infos_(capacity) {
    for (std::size_t i = 0; i < capacity; ++i) buffers_[i] = samples_[i].get();
  }
  TakeBuffer(const TakeBuffer&) = delete;
  TakeBuffer& operator=(const TakeBuffer&) = delete;

  std::size_t capacity() const noexcept { return samples_.size(); }
  // The samples of the last take.
  std::size_t size() const noexcept { return count_; }
  // For a sample without valid data only the key members are current.
  const T& data(std::size_t i) const noexcept { return *samples_[i]; }
  SampleInfo info(std::size_t i) const noexcept { return SampleInfo(infos_[i]); }

 private:
  friend class Reader<T>;
  std::vector<Owned<T>> samples_;
  std::vector<void*> buffers_;
  std::vector<dds_sample_info_t> infos_;
  std::size_t count_ = 0;
};

template <class T>
class Reader : public Entity {
 public:
  Reader(const Participant& participant, const Topic<T>& topic, const Qos& qos)
      : Reader(participant, topic, qos, nullptr) {}
  // With `listener` (DataListener::get), which must outlive the reader or be
  // detached from it first (DataListener::detach).
  Reader(const Participant& participant, const Topic<T>& topic, const Qos& qos,
         const dds_listener_t* listener)
      : Entity(check(
            dds_create_reader(participant.handle(), topic.handle(), qos.get(), listener),
            std::string("creating a reader of ") + TopicTraits<T>::kDescriptor->m_typename)) {}

  // Up to `max` samples, removed from the reader.
  Result<std::vector<Sample<T>>> take(std::size_t max = kDefaultMax) const {
    return collect(handle(), max, true, DDS_HANDLE_NIL);
  }
  // Up to into.capacity() samples, removed from the reader, into `into`
  // (replacing what it held); the number taken.
  Result<std::size_t> take(TakeBuffer<T>& into) const {
    const auto cap = static_cast<uint32_t>(into.capacity());
    into.count_ = 0;
    const dds_return_t n = dds_take(handle(), into.buffers_.data(), into.infos_.data(), cap, cap);
    if (n < 0) return make_error_code(n);
    into.count_ = static_cast<std::size_t>(n);
    return into.count_;
  }
  // As take(into), and the serialized form of each sample (CDR, from its
  // 4-byte encapsulation header on) into `serialized`: what the typed sample
  // cannot show, such as a string with a NUL inside (the struct's copy ends
  // at that NUL). A sample without valid data (an instance state change)
  // comes with neither its key members nor bytes: for a reader that only
  // acts on data. Not for a hot path: it allocates.
  Result<std::size_t> take(TakeBuffer<T>& into,
                           std::vector<std::vector<unsigned char>>& serialized) const {
    const auto cap = static_cast<uint32_t>(into.capacity());
    into.count_ = 0;
    std::vector<ddsi_serdata*> raw(cap, nullptr);
    const dds_return_t n =
        dds_takecdr(handle(), raw.data(), cap, into.infos_.data(), DDS_ANY_STATE);
    if (n < 0) return make_error_code(n);
    serialized.resize(static_cast<std::size_t>(n));
    for (std::size_t i = 0; i < serialized.size(); ++i) {
      auto& sample = into.samples_[i];
      sample.clear();
      auto& bytes = serialized[i];
      if (into.infos_[i].valid_data) {
        (void)ddsi_serdata_to_sample(raw[i], sample.get(), nullptr, nullptr);
        bytes.resize(ddsi_serdata_size(raw[i]));
        ddsi_serdata_to_ser(raw[i], 0, bytes.size(), bytes.data());
      } else {
        // An instance state change. Cyclone 0.10 hands it over as a bare
        // key without its type, which cannot be deserialised here, and the
        // instance may be gone already: neither key nor bytes.
        bytes.clear();
      }
      ddsi_serdata_unref(raw[i]);
    }
    into.count_ = static_cast<std::size_t>(n);
    return into.count_;
  }
  // Up to `max` samples, left in the reader (marked read).
  Result<std::vector<Sample<T>>> read(std::size_t max = kDefaultMax) const {
    return collect(handle(), max, false, DDS_HANDLE_NIL);
  }
  // Only the samples that match the condition's mask.
  Result<std::vector<Sample<T>>> take(const ReadCondition& condition,
                                      std::size_t max = kDefaultMax) const {
    if (condition.reader() != handle()) return make_error_code(DDS_RETCODE_BAD_PARAMETER);
    return collect(condition.handle(), max, true, DDS_HANDLE_NIL);
  }
  Result<std::vector<Sample<T>>> read(const ReadCondition& condition,
                                      std::size_t max = kDefaultMax) const {
    if (condition.reader() != handle()) return make_error_code(DDS_RETCODE_BAD_PARAMETER);
    return collect(condition.handle(), max, false, DDS_HANDLE_NIL);
  }
  // Only the samples of one instance (see lookup_instance).
  Result<std::vector<Sample<T>>> take_instance(dds_instance_handle_t instance,
                                               std::size_t max = kDefaultMax) const {
    return collect(handle(), max, true, instance);
  }

  // The handle of the instance whose key members `key` holds; DDS_HANDLE_NIL
  // when the reader does not know it.
  dds_instance_handle_t lookup_instance(const T& key) const noexcept {
    return dds_lookup_instance(handle(), &key);
  }

  Result<uint32_t> matched_publications() const noexcept {
    auto status = subscription_matched();
    if (!status) return status.error();
    return status->current_count;
  }

  // Status getters read and reset the status' "change" counts.
  Result<dds_subscription_matched_status_t> subscription_matched() const noexcept {
    dds_subscription_matched_status_t s{};
    return result(dds_get_subscription_matched_status(handle(), &s), s);
  }
  Result<dds_requested_deadline_missed_status_t> requested_deadline_missed() const noexcept {
    dds_requested_deadline_missed_status_t s{};
    return result(dds_get_requested_deadline_missed_status(handle(), &s), s);
  }
  Result<dds_liveliness_changed_status_t> liveliness_changed() const noexcept {
    dds_liveliness_changed_status_t s{};
    return result(dds_get_liveliness_changed_status(handle(), &s), s);
  }
  Result<dds_requested_incompatible_qos_status_t> requested_incompatible_qos() const noexcept {
    dds_requested_incompatible_qos_status_t s{};
    return result(dds_get_requested_incompatible_qos_status(handle(), &s), s);
  }
  Result<dds_sample_lost_status_t> sample_lost() const noexcept {
    dds_sample_lost_status_t s{};
    return result(dds_get_sample_lost_status(handle(), &s), s);
  }
  Result<dds_sample_rejected_status_t> sample_rejected() const noexcept {
    dds_sample_rejected_status_t s{};
    return result(dds_get_sample_rejected_status(handle(), &s), s);
  }

  static constexpr std::size_t kDefaultMax = 64;

 private:
  template <class S>
  static Result<S> result(dds_return_t rc, const S& s) noexcept {
    if (rc < 0) return make_error_code(rc);
    return s;
  }

  // `from` is the reader or one of its read conditions.
  static Result<std::vector<Sample<T>>> collect(dds_entity_t from, std::size_t max, bool take,
                                                dds_instance_handle_t instance) {
    if (max == 0) return std::vector<Sample<T>>{};
    std::vector<Sample<T>> samples(max);
    std::vector<void*> buffers(max);
    std::vector<dds_sample_info_t> infos(max);
    for (std::size_t i = 0; i < max; ++i) buffers[i] = samples[i].data_.get();
    const auto n32 = static_cast<uint32_t>(max);
    dds_return_t n;
    if (instance != DDS_HANDLE_NIL) {
      n = take ? dds_take_instance(from, buffers.data(), infos.data(), max, n32, instance)
               : dds_read_instance(from, buffers.data(), infos.data(), max, n32, instance);
    } else {
      n = take ? dds_take(from, buffers.data(), infos.data(), max, n32)
               : dds_read(from, buffers.data(), infos.data(), max, n32);
    }
    if (n < 0) return make_error_code(n);
    const auto count = static_cast<std::size_t>(n);
    samples.resize(count);  // the unused ones are still all zero: nothing to free
    for (std::size_t i = 0; i < count; ++i) samples[i].info_ = SampleInfo(infos[i]);
    return samples;
  }
};

}  // namespace dnbridge::dds
