// Entries looked up by name (the planner and map engine registries): added once, found by
// name, listed in the order they were added. Entry needs a std::string `name`.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace fvp::host {

template <typename Entry>
class NamedRegistry {
 public:
  /// what: the kind of entry, for messages ("planner", "map engine").
  explicit NamedRegistry(std::string what) : what_(std::move(what)) {}

  /// Throws std::invalid_argument when the name is empty or taken.
  void add(Entry entry) {
    if (entry.name.empty()) throw std::invalid_argument(what_ + " registry: an entry needs a name");
    if (contains(entry.name))
      throw std::invalid_argument(what_ + " registry: '" + entry.name + "' is already registered");
    entries_.push_back(std::move(entry));
  }
  /// Throws std::invalid_argument "unknown WHAT 'x' (known: a, b)".
  const Entry& at(std::string_view name) const {
    for (const Entry& e : entries_)
      if (e.name == name) return e;
    throw std::invalid_argument("unknown " + what_ + " '" + std::string(name) +
                                "' (known: " + knownNames() + ")");
  }
  bool contains(std::string_view name) const {
    for (const Entry& e : entries_)
      if (e.name == name) return true;
    return false;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const Entry& e : entries_) out.push_back(e.name);
    return out;
  }
  /// "a, b": the names for messages.
  std::string knownNames() const {
    std::string known;
    for (const Entry& e : entries_) known += (known.empty() ? "" : ", ") + e.name;
    return known;
  }

 private:
  std::string what_;
  std::vector<Entry> entries_;
};

}  // namespace fvp::host
