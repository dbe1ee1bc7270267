#pragma once
// A topic typed by the C struct idlc generated for it. TopicTraits<T> ties the
// struct to its type descriptor and topic name; the product's
// specialisations are in topics.hpp.
#include <dds/dds.h>

#include <memory>
#include <string>

#include "adapters/dds/entity.hpp"
#include "adapters/dds/participant.hpp"

namespace dnbridge::dds {

// Specialise with:
//   static constexpr const char* kName;                          // topic name
//   static constexpr const dds_topic_descriptor_t* kDescriptor;  // idlc's T_desc
template <class T>
struct TopicTraits;

template <class T>
class Topic : public Entity {
 public:
  // The type's own topic. Throws Error.
  explicit Topic(const Participant& participant) : Topic(participant, TopicTraits<T>::kName) {}
  // The type under another name (Cyclone accepts [A-Za-z0-9_/]). Throws Error.
  Topic(const Participant& participant, const std::string& name)
      : Entity(check(dds_create_topic(participant.handle(), TopicTraits<T>::kDescriptor,
                                      name.c_str(), nullptr, nullptr),
                     "creating topic \"" + name + "\" of type " +
                         TopicTraits<T>::kDescriptor->m_typename)) {}

  // Deleted before its filter goes.
  ~Topic() { reset(); }
  Topic(Topic&&) noexcept = default;
  Topic& operator=(Topic&&) noexcept = default;

  // Only the samples `accept(sample, arg)` takes reach the readers made on
  // this topic entity from then on: Cyclone's topic filter, run as each
  // sample with data arrives (a dispose or unregister still passes). For a
  // topic entity of its readers' own; `arg` must outlive them. Throws Error.
  void filter(bool (*accept)(const T& sample, const void* arg), const void* arg) {
    // The one in force is freed only once Cyclone has the new one.
    auto next = std::make_unique<Filter>(Filter{accept, arg});
    check(dds_set_topic_filter_and_arg(handle(), &Topic::call, next.get()),
          "setting a filter on a topic of type " +
              std::string(TopicTraits<T>::kDescriptor->m_typename));
    filter_ = std::move(next);
  }

 private:
  struct Filter {
    bool (*accept)(const T&, const void*) = nullptr;
    const void* arg = nullptr;
  };
  static bool call(const void* sample, void* filter) {
    const auto* f = static_cast<const Filter*>(filter);
    return f->accept(*static_cast<const T*>(sample), f->arg);
  }
  std::unique_ptr<Filter> filter_;  // where Cyclone has it: kept when the topic moves
};

}  // namespace dnbridge::dds
