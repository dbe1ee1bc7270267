#pragma once
// A port's scan list as the rack file gives it: the nodes' configurations,
// one list per profile, whatever the profiles are. A profile's
// configuration type names its rack (`using Rack = ...`), and the rack says
// what the configuration means:
//
//   class Rack : public NodeRack<Profile> {
//     // The master's scan-list entry for one node; throws
//     // std::invalid_argument, naming the node, for one the profile refuses.
//     static devicenet::NodeConfig scan_entry(const Config&);
//     // The settings the master brings to the device are the same (a
//     // difference means releasing the node and configuring it again).
//     static bool same_device_settings(const Config&, const Config&);
//   };
//
// so that the port (RackPort) makes, compares and changes its racks
// without knowing which profiles it has.
#include <cstddef>
#include <memory>
#include <optional>
#include <typeindex>
#include <typeinfo>
#include <utility>
#include <vector>

#include "bridge/common/time.hpp"
#include "bridge/devicenet/master/scanner.hpp"
#include "bridge/rack/profile_nodes.hpp"

namespace dnbridge::rack {

// The nodes of one profile in a scan list.
class NodeList {
 public:
  NodeList() = default;
  NodeList(const NodeList&) = delete;
  NodeList& operator=(const NodeList&) = delete;
  virtual ~NodeList() = default;

  virtual std::unique_ptr<NodeList> clone() const = 0;
  // The profile's configuration type: two lists of one type are one profile.
  virtual std::type_index type() const = 0;
  virtual std::size_t size() const = 0;
  // The scan-list entry as configured (MAC, name, timings; no profile yet).
  virtual const devicenet::NodeConfig& node(std::size_t i) const = 0;
  virtual Duration command_refresh(std::size_t i) const = 0;
  // The master's scan-list entry (scan_entry above).
  virtual devicenet::NodeConfig scan_entry(std::size_t i) const = 0;
  // Node `i` here and node `j` of `other` (a list of the same profile) have
  // the same device settings, or the same handling by the bridge (name,
  // no-commander and resume policies, command refresh).
  virtual bool same_device_settings(std::size_t i, const NodeList& other, std::size_t j) const = 0;
  virtual bool same_handling(std::size_t i, const NodeList& other, std::size_t j) const = 0;

  // The profile's rack, with no nodes yet, and the changes to one made so.
  virtual std::unique_ptr<ProfileNodes> make_rack() const = 0;
  virtual void add(ProfileNodes& rack, std::size_t i) const = 0;
  virtual void replace(ProfileNodes& rack, std::size_t i) const = 0;
  virtual void update(ProfileNodes& rack, std::size_t i, TimePoint now) const = 0;
};

template <class Config>
class NodeListOf final : public NodeList {
 public:
  using Rack = typename Config::Rack;

  explicit NodeListOf(std::vector<Config> configs = {}) : configs_(std::move(configs)) {}

  std::vector<Config>& configs() { return configs_; }
  const std::vector<Config>& configs() const { return configs_; }

  std::unique_ptr<NodeList> clone() const override {
    return std::make_unique<NodeListOf>(configs_);
  }
  std::type_index type() const override { return typeid(Config); }
  std::size_t size() const override { return configs_.size(); }
  const devicenet::NodeConfig& node(std::size_t i) const override { return configs_[i].node; }
  Duration command_refresh(std::size_t i) const override { return configs_[i].command_refresh; }
  devicenet::NodeConfig scan_entry(std::size_t i) const override {
    return Rack::scan_entry(configs_[i]);
  }
  bool same_device_settings(std::size_t i, const NodeList& other, std::size_t j) const override {
    const auto* o = dynamic_cast<const NodeListOf*>(&other);
    return o != nullptr && Rack::same_device_settings(configs_[i], o->configs_[j]);
  }
  bool same_handling(std::size_t i, const NodeList& other, std::size_t j) const override {
    const auto* o = dynamic_cast<const NodeListOf*>(&other);
    return o != nullptr && Rack::same_handling(configs_[i], o->configs_[j]);
  }

  std::unique_ptr<ProfileNodes> make_rack() const override {
    return std::make_unique<Rack>(std::vector<Config>{});
  }
  void add(ProfileNodes& rack, std::size_t i) const override {
    dynamic_cast<Rack&>(rack).add(configs_[i]);
  }
  void replace(ProfileNodes& rack, std::size_t i) const override {
    dynamic_cast<Rack&>(rack).replace(configs_[i]);
  }
  void update(ProfileNodes& rack, std::size_t i, TimePoint now) const override {
    dynamic_cast<Rack&>(rack).update(configs_[i], now);
  }

 private:
  std::vector<Config> configs_;
};

// The nodes of a port's scan list, by profile, in the order the profiles
// were first given. A MAC is in one list at most (RackPort checks).
class PortNodes {
 public:
  PortNodes() = default;
  // One list per profile: PortNodes(pumps), PortNodes(pumps, devices).
  template <class... Configs>
  explicit PortNodes(std::vector<Configs>... lists) {
    ((of<Configs>() = std::move(lists)), ...);
  }
  PortNodes(const PortNodes& other) { *this = other; }
  PortNodes& operator=(const PortNodes& other) {
    if (this == &other) return *this;
    lists_.clear();
    for (const auto& l : other.lists_) lists_.push_back(l->clone());
    return *this;
  }
  PortNodes(PortNodes&&) noexcept = default;
  PortNodes& operator=(PortNodes&&) noexcept = default;
  ~PortNodes() = default;

  // The nodes of the profile whose configuration is `Config`; the list is
  // made (empty) when the port has none yet.
  template <class Config>
  std::vector<Config>& of() {
    if (auto* l = find<Config>()) return l->configs();
    auto l = std::make_unique<NodeListOf<Config>>();
    auto& configs = l->configs();
    lists_.push_back(std::move(l));
    return configs;
  }
  // Empty when the port has none.
  template <class Config>
  const std::vector<Config>& of() const {
    static const std::vector<Config> none;
    const auto* l = find<Config>();
    return l != nullptr ? l->configs() : none;
  }

  const std::vector<std::unique_ptr<NodeList>>& lists() const { return lists_; }

  // Where the node at `mac` is: its list and its place in it.
  struct At {
    const NodeList* list = nullptr;
    std::size_t index = 0;
    explicit operator bool() const { return list != nullptr; }
  };
  At at(devicenet::MacId mac) const {
    for (const auto& l : lists_) {
      for (std::size_t i = 0; i < l->size(); ++i) {
        if (l->node(i).mac == mac) return {l.get(), i};
      }
    }
    return {};
  }

  std::size_t size() const {
    std::size_t n = 0;
    for (const auto& l : lists_) n += l->size();
    return n;
  }

 private:
  template <class Config>
  NodeListOf<Config>* find() const {
    for (const auto& l : lists_) {
      if (auto* of = dynamic_cast<NodeListOf<Config>*>(l.get())) return of;
    }
    return nullptr;
  }

  std::vector<std::unique_ptr<NodeList>> lists_;
};

}  // namespace dnbridge::rack
