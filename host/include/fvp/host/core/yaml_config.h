// What the YAML config readers (world, arm) share: reading the file as a mapping, finding a
// key in a table of key specs, and printing numbers in error messages. Errors name the
// source (e.g. "arm config 'F'") and what was expected.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace fvp::host {

/// The file's top-level node: null for an empty file, else a mapping. Throws
/// std::invalid_argument when the file cannot be read as YAML or is not a mapping.
inline YAML::Node readYamlMapping(const std::filesystem::path& path, const std::string& source) {
  // yaml-cpp reads a directory as an empty document, which would mean "all defaults".
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::invalid_argument(source + ": not a readable file" +
                                (std::filesystem::is_directory(path, ec) ? " (a directory)" : ""));
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": cannot read YAML: " + e.what());
  }
  if (!root.IsNull() && !root.IsMap())
    throw std::invalid_argument(source + ": expected a mapping of key: value");
  return root;
}

/// A mapping key as text. Throws std::invalid_argument naming the source when the key is no
/// scalar (`[a]: 1`, `{}: 1`), where yaml-cpp's as<std::string>() throws its own exception.
inline std::string keyString(const YAML::Node& key, const std::string& source) {
  if (key.IsScalar()) return key.Scalar();
  if (key.IsNull()) return "null";  // what as<std::string>() gives: `~: 1` is an unknown key
  throw std::invalid_argument(source + ": expected keys that are names, got a " +
                              (key.IsSequence() ? "list" : "mapping") + " as a key");
}

/// node as T: a scalar that converts to T and, for floating point, is finite (yaml-cpp
/// reads .nan and .inf). Throws std::invalid_argument "WHERE: expected EXPECTED, got 'X'".
template <typename T>
T readScalar(const YAML::Node& node, const std::string& where, const std::string& expected) {
  if (!node.IsScalar()) throw std::invalid_argument(where + ": expected " + expected);
  T value{};
  try {
    value = node.as<T>();
  } catch (const YAML::Exception&) {
    throw std::invalid_argument(where + ": expected " + expected + ", got '" + node.Scalar() + "'");
  }
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value))
      throw std::invalid_argument(where + ": expected " + expected + " (finite), got '" +
                                  node.Scalar() + "'");
  }
  return value;
}

/// The spec whose `name` is key; throws std::invalid_argument listing the known keys.
template <typename KeySpec>
const KeySpec& findKeySpec(const std::vector<KeySpec>& specs, const std::string& key,
                           const std::string& source) {
  for (const KeySpec& spec : specs)
    if (key == spec.name) return spec;
  std::string known;
  for (const KeySpec& spec : specs) known += (known.empty() ? "" : ", ") + std::string(spec.name);
  throw std::invalid_argument(source + ": unknown key '" + key + "' (known keys: " + known + ")");
}

/// A number as an error message shows it (shortest stream form).
inline std::string formatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace fvp::host
