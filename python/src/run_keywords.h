// Python keywords generated from a run's settings (host/nbv/run_fields.h,
// trials/trial_fields.h): each setting's key is its keyword, its type decides the conversion,
// and choices are taken by name. An unknown keyword is a TypeError, a bad value a ValueError
// naming the keyword and what was expected.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "fvp/accel/backend_choice.h"
#include "fvp/host/nbv/run_fields.h"
#include "fvp/host/nbv/stop_rule.h"
#include "fvp/robot/sim/sim_clock.h"

namespace fvp::python {

namespace py = pybind11;

/// Reads the keywords of a settings list into its options (visit it with this object), and
/// any extra keywords the caller takes itself (take()); then finish() refuses the rest.
class RunKeywords {
 public:
  RunKeywords(py::kwargs keywords, std::string owner)
      : keywords_(std::move(keywords)), owner_(std::move(owner)) {}

  template <typename T>
  void operator()(const host::nbv::RunField& field, T& member) {
    take(std::string(field.key), member);
  }

  /// A keyword that is not a setting (out_dir), read as a setting of its type.
  template <typename T>
  void take(const std::string& key, T& member) {
    if (auto value = takeObject(key)) read(key, *value, member);
  }

  /// A keyword that is not a setting (perception): the value, if given.
  std::optional<py::object> takeObject(const std::string& key) {
    known_.insert(key);
    if (!keywords_.contains(key.c_str())) return std::nullopt;
    return py::object(keywords_[key.c_str()]);
  }

  /// TypeError for a keyword that is neither a setting nor taken.
  void finish() const {
    for (const auto& [key, value] : keywords_) {
      const std::string name = py::str(key);
      if (!known_.count(name)) {
        std::string expected;
        for (const std::string& k : known_) expected += (expected.empty() ? "" : ", ") + k;
        throw py::type_error(owner_ + ": unexpected keyword argument '" + name +
                             "' (expected one of " + expected + ")");
      }
    }
  }

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& expected,
                         const py::object& value) const {
    throw py::value_error(owner_ + ": " + key + ": expected " + expected + ", got " +
                          std::string(py::repr(value)));
  }
  template <typename T>
  T cast(const std::string& key, const py::object& value, const char* expected) const {
    try {
      return value.cast<T>();
    } catch (const py::cast_error&) {
      fail(key, expected, value);
    }
  }
  template <typename Enum, typename Choices, typename NameOf>
  Enum choice(const std::string& key, const py::object& value, const Choices& choices,
              NameOf nameOf) const {
    std::string names;
    for (const Enum c : choices) names += (names.empty() ? "" : ", ") + std::string(nameOf(c));
    if (py::isinstance<py::str>(value)) {
      const std::string text = value.cast<std::string>();
      for (const Enum c : choices)
        if (std::string(nameOf(c)) == text) return c;
    }
    fail(key, "one of " + names, value);
  }

  void read(const std::string& key, const py::object& v, std::string& out) const {
    out = cast<std::string>(key, v, "a string");
  }
  void read(const std::string& key, const py::object& v, std::filesystem::path& out) const {
    if (!py::isinstance<py::str>(v) && !py::hasattr(v, "__fspath__")) fail(key, "a path", v);
    out = py::str(py::module_::import("os").attr("fspath")(v)).cast<std::string>();
  }
  void read(const std::string& key, const py::object& v, std::uint64_t& out) const {
    if (!py::isinstance<py::int_>(v) || py::isinstance<py::bool_>(v))
      fail(key, "a non-negative integer", v);
    out = cast<std::uint64_t>(key, v, "a non-negative integer below 2**64");
  }
  void read(const std::string& key, const py::object& v, int& out) const {
    if (!py::isinstance<py::int_>(v) || py::isinstance<py::bool_>(v)) fail(key, "an integer", v);
    out = cast<int>(key, v, "an integer that fits 32 bits");
  }
  void read(const std::string& key, const py::object& v, double& out) const {
    if (py::isinstance<py::bool_>(v) ||
        !(py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v)))
      fail(key, "a number", v);
    out = cast<double>(key, v, "a number");
  }
  void read(const std::string& key, const py::object& v, bool& out) const {
    if (!py::isinstance<py::bool_>(v)) fail(key, "True or False", v);
    out = v.cast<bool>();
  }
  template <typename T>
  void read(const std::string& key, const py::object& v, std::optional<T>& out) const {
    if (v.is_none()) {
      out.reset();
      return;
    }
    T value{};
    read(key, v, value);
    out = value;
  }
  void read(const std::string& key, const py::object& v, accel::BackendChoice& out) const {
    out = choice<accel::BackendChoice>(key, v, accel::kBackendChoices,
                                       [](accel::BackendChoice c) { return accel::toString(c); });
  }
  void read(const std::string& key, const py::object& v, host::nbv::StopRule& out) const {
    out = choice<host::nbv::StopRule>(key, v, host::nbv::kStopRules,
                                      [](host::nbv::StopRule r) { return host::nbv::toString(r); });
  }
  void read(const std::string& key, const py::object& v, robot::sim::SimClock::Mode& out) const {
    using Mode = robot::sim::SimClock::Mode;
    out = choice<Mode>(key, v, std::vector<Mode>{Mode::kWall, Mode::kFixed},
                       robot::sim::SimClock::modeName);
  }

  py::kwargs keywords_;
  std::string owner_;
  std::set<std::string> known_;
};

/// "key (default: value): help" for each setting, one per line (a generated docstring).
template <typename Options, typename Visit, typename ValueJson>
std::string keywordDoc(const Options& defaults, Visit visitFields, ValueJson valueJson) {
  std::string doc;
  visitFields(defaults, [&doc, &valueJson](const host::nbv::RunField& field, const auto& value) {
    doc += "  " + std::string(field.key) + " (default: " + valueJson(value).dump() +
           "): " + std::string(field.help) + "\n";
  });
  return doc;
}

}  // namespace fvp::python
