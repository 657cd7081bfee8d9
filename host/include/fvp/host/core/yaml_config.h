// The one reader of fvp's YAML config files (world, arm, map, planner, RVP, perception): a
// file is a mapping of known keys, each read by its entry in the config's key table
// (YamlKey); unknown keys, wrong types and non-finite numbers are errors naming the source
// (e.g. "arm config 'F'") and the key, and what was expected. Range checks are the config's
// own validate().
#pragma once

#include <yaml-cpp/depthguard.h>  // YAML::DeepRecursion
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "fvp/host/core/number_text.h"
#include "fvp/host/core/regular_file.h"

namespace fvp::host {

/// The largest config file read (docs/reliability.md, "Memory bounds").
inline constexpr std::uint64_t kMaxConfigFileBytes = std::uint64_t{1} << 20;

/// Throws std::invalid_argument "SOURCE: key 'K' appears twice (lines A and B)" for a mapping,
/// at any depth, that holds a key twice: yaml-cpp keeps both, and a reader would silently
/// take the first or the last.
inline void checkNoDuplicateKeys(const YAML::Node& node, const std::string& source) {
  if (node.IsSequence())
    for (const auto& item : node) checkNoDuplicateKeys(item, source);
  if (!node.IsMap()) return;
  std::vector<std::pair<std::string, int>> seen;  // scalar keys and their lines
  for (const auto& item : node) {
    if (item.first.IsScalar()) {
      const std::string key = item.first.Scalar();
      const int line = item.first.Mark().line + 1;
      for (const auto& [k, l] : seen)
        if (k == key)
          throw std::invalid_argument(source + ": key '" + key + "' appears twice (lines " +
                                      std::to_string(l) + " and " + std::to_string(line) +
                                      "); expected each key once");
      seen.emplace_back(key, line);
    }
    checkNoDuplicateKeys(item.second, source);
  }
}

namespace detail {

/// Parses a YAML stream document by document without building nodes (the count is all
/// loadOneYamlDocument needs of the documents after the first).
class YamlDocumentCounter : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

}  // namespace detail

/// The one YAML document of a file (null when the file is empty), with no key twice in any
/// mapping. Throws std::invalid_argument naming source when the file is not a regular file
/// of at most max_bytes (a bound keeps a 100 MB list from exhausting memory in the parser,
/// whose nodes take ~50 times the text), cannot be read as YAML, holds more than one
/// document (a later `---` document would be ignored), or nests deeper than yaml-cpp reads
/// (whose own message is "bad file").
inline YAML::Node loadOneYamlDocument(const std::filesystem::path& path, const std::string& source,
                                      const std::string& what = "config file",
                                      std::uint64_t max_bytes = kMaxConfigFileBytes) {
  std::string text;
  try {
    text = readRegularFile(path, what, max_bytes);
  } catch (const std::runtime_error& e) {
    // The reader's message starts with the path; source names the file already.
    std::string why = e.what();
    const std::string path_prefix = path.string() + ": ";
    if (why.rfind(path_prefix, 0) == 0) why.erase(0, path_prefix.size());
    throw std::invalid_argument(source + ": " + why);
  }
  YAML::Node root;
  int documents = 0;
  try {
    // YAML::LoadAll loops forever on some inputs (yaml-cpp 0.7, e.g. ","): count at most two
    // documents with the parser itself, then load the first.
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    detail::YamlDocumentCounter counter;
    while (documents < 2 && parser.HandleNextDocument(counter)) ++documents;
    if (documents == 1) root = YAML::Load(text);
  } catch (const YAML::DeepRecursion&) {
    throw std::invalid_argument(source +
                                ": cannot read YAML: lists or mappings nested too deeply "
                                "(expected a flat file of key: value)");
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": cannot read YAML: " + e.what());
  }
  if (documents > 1)
    throw std::invalid_argument(source +
                                ": expected one YAML document, got 2 or more (a '---' line "
                                "starts another; remove it or the later ones)");
  checkNoDuplicateKeys(root, source);
  return root;
}

/// The file's top-level node: null for an empty file, else a mapping. Throws
/// std::invalid_argument when the file cannot be read as YAML (loadOneYamlDocument) or is
/// not a mapping.
inline YAML::Node readYamlMapping(const std::filesystem::path& path, const std::string& source) {
  // yaml-cpp reads a directory as an empty document, which would mean "all defaults".
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::invalid_argument(source + ": not a readable file" +
                                (std::filesystem::is_directory(path, ec) ? " (a directory)" : ""));
  const YAML::Node root = loadOneYamlDocument(path, source);
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
  if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
    // yaml-cpp reads 012 as 10 and 0x05 as 5; fvp's numbers are decimal, as on the CLI.
    if (!isDecimalNumberText(node.Scalar(), std::is_integral_v<T>))
      throw std::invalid_argument(where + ": expected " + expected +
                                  " (decimal, without a leading zero, '+' or 0x), got '" +
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

/// A list of 3 finite numbers [x, y, z].
inline Eigen::Vector3d readVector3(const YAML::Node& node, const std::string& where) {
  const std::string expected = "a list of 3 numbers [x, y, z]";
  if (!node.IsSequence() || node.size() != 3)
    throw std::invalid_argument(where + ": expected " + expected);
  return {readScalar<double>(node[0], where, expected),
          readScalar<double>(node[1], where, expected),
          readScalar<double>(node[2], where, expected)};
}

/// One key of a config file: its name, how its value is read into the config (`where` names
/// the source and the key for errors) and how the config's value is written as JSON (the
/// config's toJson: each config lists its keys once, for both).
template <typename Config>
struct YamlKey {
  const char* name;
  std::function<void(Config& config, const YAML::Node& value, const std::string& where)> read;
  std::function<nlohmann::json(const Config& config)> write;
};

/// A config value as JSON: 3-vectors as [x, y, z], an unset optional as null.
template <typename T>
nlohmann::json yamlValueJson(const T& value) {
  if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
    return nlohmann::json::array({value.x(), value.y(), value.z()});
  } else if constexpr (std::is_same_v<T, std::optional<Eigen::Vector3d>>) {
    return value ? yamlValueJson(*value) : nlohmann::json(nullptr);
  } else {
    return value;
  }
}

/// A value of type T from a node: integers, finite numbers, booleans, strings, 3-vectors and
/// optional 3-vectors.
template <typename T>
T readYamlValue(const YAML::Node& node, const std::string& where) {
  if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
    return readVector3(node, where);
  } else if constexpr (std::is_same_v<T, std::optional<Eigen::Vector3d>>) {
    return readVector3(node, where);
  } else if constexpr (std::is_same_v<T, std::string>) {
    return readScalar<T>(node, where, "a string");
  } else if constexpr (std::is_same_v<T, bool>) {
    return readScalar<T>(node, where, "true or false");
  } else if constexpr (std::is_floating_point_v<T>) {
    return readScalar<T>(node, where, "a number");
  } else {
    static_assert(std::is_integral_v<T>, "readYamlValue: no reader for this type");
    return readScalar<T>(node, where, "an integer");
  }
}

/// The key that reads its value into config.*member.
template <typename Config, typename T>
YamlKey<Config> yamlField(const char* name, T Config::*member) {
  return {name,
          [member](Config& c, const YAML::Node& n, const std::string& where) {
            c.*member = readYamlValue<T>(n, where);
          },
          [member](const Config& c) { return yamlValueJson(c.*member); }};
}

/// The key that reads its value into field(config), a member of a member.
template <typename Config, typename Field>
YamlKey<Config> yamlField(const char* name, Field field) {
  return {name,
          [field](Config& c, const YAML::Node& n, const std::string& where) {
            auto& target = field(c);
            target = readYamlValue<std::decay_t<decltype(target)>>(n, where);
          },
          // field only selects a member: reading through it changes nothing.
          [field](const Config& c) { return yamlValueJson(field(const_cast<Config&>(c))); }};
}

/// Reads the file's keys into config (missing keys keep config's values): each key by its
/// entry in keys, an unknown key an error listing the known ones. Checking the values is
/// the caller's (validate()).
template <typename Config>
void readYamlConfig(const std::filesystem::path& path, const std::string& source,
                    const std::vector<YamlKey<Config>>& keys, Config& config) {
  const YAML::Node root = readYamlMapping(path, source);
  if (root.IsNull()) return;
  for (const auto& item : root) {
    const std::string key = keyString(item.first, source);
    findKeySpec(keys, key, source).read(config, item.second, source + ": key '" + key + "'");
  }
}

/// The config as JSON, one member per key of its table, in the table's order (a config's
/// toJson; result.json's config); an unset optional is left out, as a file leaves it out, so
/// that the JSON read as the config's YAML gives the config. Throws std::logic_error for a key
/// with no writer.
template <typename Config>
nlohmann::ordered_json yamlConfigJson(const std::vector<YamlKey<Config>>& keys,
                                      const Config& config) {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  for (const auto& key : keys) {
    if (!key.write) throw std::logic_error(std::string("config key '") + key.name + "': no writer");
    nlohmann::json value = key.write(config);
    if (!value.is_null()) json[key.name] = std::move(value);
  }
  return json;
}

/// The names of a key table, in its order.
template <typename Config>
std::vector<std::string> yamlKeyNames(const std::vector<YamlKey<Config>>& keys) {
  std::vector<std::string> names;
  for (const auto& key : keys) names.emplace_back(key.name);
  return names;
}

/// For validate(): throws std::invalid_argument "SOURCE: key 'KEY': expected EXPECTED" unless ok.
inline void requireKey(bool ok, const std::string& source, const char* key,
                       const std::string& expected) {
  if (!ok) throw std::invalid_argument(source + ": key '" + key + "': expected " + expected);
}

/// A number as an error message shows it (shortest stream form).
inline std::string formatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace fvp::host
