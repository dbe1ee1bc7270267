#pragma once
// A topic typed by the C struct idlc generated for it. TopicTraits<T> ties the
// struct to its type descriptor and topic name; the product's
// specialisations are in topics.hpp.
#include <dds/dds.h>

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
};

}  // namespace dnbridge::dds
