#include "fvp/trials/experiment_directory.h"

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "fvp/accel/backend_choice.h"
#include "fvp/trials/trial_fields.h"

namespace fvp::trials {
namespace {

constexpr const char* kManifestFormat = "fvp-experiment-manifest";
constexpr const char* kPlannerExpected = "a planner name (lower-case letters, digits and _)";
constexpr const char* kEngineExpected =
    "\"\" (the planner's own) or a map engine name (lower-case letters, digits and _)";

/// A value for an error message: its JSON text, cut short.
std::string shown(const nlohmann::json& value) {
  std::string text = value.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

[[noreturn]] void fieldError(const std::string& where, const std::string& field,
                             const std::string& expected, const nlohmann::json* got) {
  std::string message = where + ": field '" + field + "': expected " + expected;
  message += got ? ", got " + shown(*got) : ", but it is missing";
  throw std::runtime_error(message);
}

bool isUnsigned(const nlohmann::json& v) {
  return v.is_number_unsigned() || (v.is_number_integer() && v.get<std::int64_t>() >= 0);
}

bool isFinite(const nlohmann::json& v) {
  return v.is_number() && std::isfinite(v.get<double>());
}

/// The member `key` of object `o`, or nullptr.
const nlohmann::json* member(const nlohmann::json& o, const char* key) {
  const auto it = o.find(key);
  return it == o.end() ? nullptr : &*it;
}

void checkFruitlets(const nlohmann::json& trial, const char* key, const std::string& where) {
  const nlohmann::json* list = member(trial, key);
  if (!list) return;
  if (!list->is_array()) fieldError(where, key, "an array of fruitlets", list);
  for (std::size_t i = 0; i < list->size(); ++i) {
    const nlohmann::json& f = (*list)[i];
    const std::string name = std::string(key) + "[" + std::to_string(i) + "]";
    if (!f.is_object()) fieldError(where, name, "an object", &f);
    const nlohmann::json* gt = member(f, "gt_size_mm");
    if (!gt || !isFinite(*gt) || gt->get<double>() <= 0)
      fieldError(where, name + ".gt_size_mm", "a finite positive number", gt);
    const nlohmann::json* matched = member(f, "matched");
    if (!matched || !matched->is_boolean())
      fieldError(where, name + ".matched", "true or false", matched);
    if (matched->get<bool>()) {
      const nlohmann::json* est = member(f, "est_size_mm");
      if (!est || !isFinite(*est))
        fieldError(where, name + ".est_size_mm", "a finite number (the fruitlet is matched)", est);
    }
  }
}

bool isIdentifier(const nlohmann::json& v) {
  if (!v.is_string() || v.get_ref<const std::string&>().empty()) return false;
  const std::string& s = v.get_ref<const std::string&>();
  return s.size() <= 64 && s.find_first_not_of("abcdefghijklmnopqrstuvwxyz_") == std::string::npos;
}

/// The map engine the planners of trials written before result.json had "settings" ran on
/// by default (a frozen record of those versions: later trials say what they asked for).
std::string legacyDefaultEngineOf(const std::string& planner) {
  return planner == "rvp" ? "octomap" : "grid";
}

/// A registry name (a planner's or a map engine's): lower-case letters, digits and _, safe in
/// file names and figure text. Whether a planner is registered is the runner's check.
bool isRegistryName(const nlohmann::json& v) {
  if (!v.is_string() || v.get_ref<const std::string&>().empty()) return false;
  const std::string& s = v.get_ref<const std::string&>();
  return s.size() <= 64 &&
         s.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") == std::string::npos;
}

std::string joined(const std::vector<std::string>& list) {
  std::string out;
  for (const auto& s : list) out += (out.empty() ? "" : ",") + s;
  return out;
}

std::string shownConfig(const ConfigFileStamp& c) {
  return c.path.empty() ? "built-in defaults" : c.path + " (fnv1a64 " + c.fnv1a64 + ")";
}

nlohmann::ordered_json configJson(const ConfigFileStamp& c) {
  return {{"path", c.path}, {"fnv1a64", c.fnv1a64}};
}

/// The manifest's paths are written absolute (and one line: no control bytes).
bool isAbsolutePath(const std::string& path) {
  if (path.empty() || path[0] != '/') return false;
  for (const char c : path)
    if ((unsigned char)c < 0x20 || c == 0x7f) return false;
  return true;
}

// Manifest field readers: `where` is the file.
const nlohmann::json& required(const nlohmann::json& o, const char* key, const std::string& where,
                               const std::string& expected) {
  const nlohmann::json* v = member(o, key);
  if (!v) fieldError(where, key, expected, nullptr);
  return *v;
}

std::string readString(const nlohmann::json& o, const char* key, const std::string& where) {
  const nlohmann::json& v = required(o, key, where, "a string");
  if (!v.is_string()) fieldError(where, key, "a string", &v);
  return v.get<std::string>();
}

std::uint64_t readUnsigned(const nlohmann::json& o, const char* key, const std::string& where,
                           std::uint64_t max, const std::string& expected) {
  const nlohmann::json& v = required(o, key, where, expected);
  if (!isUnsigned(v) || v.get<std::uint64_t>() > max) fieldError(where, key, expected, &v);
  return v.get<std::uint64_t>();
}

ConfigFileStamp readConfig(const nlohmann::json& o, const char* key, const std::string& where) {
  const std::string expected = "an object {\"path\": string, \"fnv1a64\": 16 hex digits or \"\"}";
  const nlohmann::json& v = required(o, key, where, expected);
  const nlohmann::json* path = v.is_object() ? member(v, "path") : nullptr;
  const nlohmann::json* hash = v.is_object() ? member(v, "fnv1a64") : nullptr;
  if (!path || !hash || !path->is_string() || !hash->is_string())
    fieldError(where, key, expected, &v);
  ConfigFileStamp c{path->get<std::string>(), hash->get<std::string>()};
  const bool hex = c.fnv1a64.size() == 16 &&
                   c.fnv1a64.find_first_not_of("0123456789abcdef") == std::string::npos;
  if (c.path.empty() ? !c.fnv1a64.empty() : !hex || !isAbsolutePath(c.path))
    fieldError(where, key, expected + " (an absolute path)", &v);
  return c;
}

/// Calls visit(field, member) for each setting a manifest records: the trial's settings but
/// the per-trial planner and seed.
template <class Options, class Visitor>
void visitManifestSettings(Options& settings, Visitor&& visit) {
  visitTrialFields(settings, [&visit](const host::nbv::RunField& field, auto& value) {
    if (!field.per_trial) visit(field, value);
  });
}

/// Settings a manifest may lack: added after format 1 began (absent: off), and in a merged
/// manifest of format 1 the run's own engine and backend.
bool mayBeAbsent(std::string_view key, bool merged) {
  for (const std::string_view k :
       {"stop", "register_views", "confirm_detections", "seek_partly_seen", "release_left_out",
        "arm_config", "size_history", "view_overhead_s", "season_day", "disparity_window",
        "guided_stereo", "known_fruitlets"})
    if (key == k) return true;
  return merged && (key == "engine" || key == "backend");
}

// A manifest setting's value by its type; `where` names the file for errors.
template <typename Enum, typename Choices, typename NameOf>
void readChoiceSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                       Enum& value, const Choices& choices, NameOf nameOf) {
  std::string names;
  for (const Enum c : choices) {
    names += (names.empty() ? "\"" : ", \"") + std::string(nameOf(c)) + "\"";
    if (v && v->is_string() && v->get<std::string>() == nameOf(c)) return void(value = c);
  }
  fieldError(where, key, "one of " + names, v);
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 double& value, bool may_be_zero) {
  // view_overhead_s 0 is a choice (the planner's order); a budget of 0 is not.
  if (!v || !isFinite(*v) || !(may_be_zero ? v->get<double>() >= 0 : v->get<double>() > 0))
    fieldError(where, key, may_be_zero ? "a finite number >= 0" : "a finite positive number", v);
  value = v->get<double>();
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 std::optional<int>& value) {
  // Format 1 wrote 0 for no limit.
  if (v && v->is_null()) return void(value.reset());
  if (!v || !isUnsigned(*v) || v->get<std::uint64_t>() > INT_MAX)
    fieldError(where, key, "a non-negative integer or null (no limit)", v);
  value = v->get<int>() > 0 ? std::optional<int>(v->get<int>()) : std::nullopt;
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 bool& value) {
  if (!v || !v->is_boolean()) fieldError(where, key, "true or false", v);
  value = v->get<bool>();
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 std::optional<double>& value) {
  // null: the world config's (season_day).
  if (v && v->is_null()) return void(value.reset());
  double x = 0.0;
  readSetting(where, key, v, x, true);
  value = x;
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 std::optional<bool>& value) {
  // null: not resolved (the runner writes register_views resolved; a hand-made manifest may
  // not).
  if (v && v->is_null()) return void(value.reset());
  bool b = false;
  readSetting(where, key, v, b);
  value = b;
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 std::string& value) {
  if (!v || !(isRegistryName(*v) || *v == "")) fieldError(where, key, kEngineExpected, v);
  value = v->get<std::string>();
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 accel::BackendChoice& value) {
  readChoiceSetting(where, key, v, value, accel::kBackendChoices,
                    [](accel::BackendChoice c) { return accel::toString(c); });
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 host::nbv::StopRule& value) {
  readChoiceSetting(where, key, v, value, host::nbv::kStopRules,
                    [](host::nbv::StopRule r) { return std::string_view(host::nbv::toString(r)); });
}
void readSetting(const std::string& where, const std::string& key, const nlohmann::json* v,
                 robot::sim::SimClock::Mode& value) {
  using Mode = robot::sim::SimClock::Mode;
  readChoiceSetting(where, key, v, value, std::array<Mode, 2>{Mode::kWall, Mode::kFixed},
                    [](Mode m) { return std::string_view(robot::sim::SimClock::modeName(m)); });
}
// Config files are read as stamps (readManifestSettings); the per-trial seed is never in a
// manifest (visitManifestSettings leaves it out).
void readSetting(const std::string&, const std::string&, const nlohmann::json*,
                 std::filesystem::path&) {}
void readSetting(const std::string&, const std::string&, const nlohmann::json*, std::uint64_t&) {}

/// Reads each setting of a manifest into m.settings (readSetting by its type) and its config
/// files' stamps into m.configs; `where` names the file for errors.
void readManifestSettings(const nlohmann::json& j, const std::string& where, bool merged,
                          ExperimentManifest& m) {
  visitManifestSettings(m.settings, [&](const host::nbv::RunField& field, auto& value) {
    using T = std::decay_t<decltype(value)>;
    const std::string key(field.key);
    const nlohmann::json* v = member(j, key.c_str());
    if (!v && mayBeAbsent(key, merged)) {
      if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, std::optional<bool>>)
        value = false;                                       // a switch added after format 1: off
      if constexpr (std::is_same_v<T, double>) value = 0.0;  // view_overhead_s 0: off
      return;
    }
    if (field.vocabulary == host::nbv::FieldVocabulary::kConfigFile) {
      m.configs[key] = readConfig(j, key.c_str(), where);
      if constexpr (std::is_same_v<T, std::filesystem::path>) value = m.configs[key].path;
      return;
    }
    if constexpr (std::is_same_v<T, double>)
      readSetting(where, key, v, value, field.may_be_zero);
    else
      readSetting(where, key, v, value);
  });
}

/// A setting of a manifest: what is compared (a config by its hash) and how it is shown.
struct SettingValue {
  std::string key;
  nlohmann::json compared;
  std::string shown;
};

std::vector<SettingValue> settingValues(const ExperimentManifest& m) {
  std::vector<SettingValue> out;
  visitManifestSettings(m.settings, [&](const host::nbv::RunField& field, const auto& value) {
    const std::string key(field.key);
    if (field.vocabulary == host::nbv::FieldVocabulary::kConfigFile) {
      const ConfigFileStamp stamp = m.configs.count(key) ? m.configs.at(key) : ConfigFileStamp{};
      out.push_back({key, stamp.fnv1a64, shownConfig(stamp)});
      return;
    }
    const nlohmann::json j = settingJson(value);
    std::string shown = j.is_string() ? j.get<std::string>() : j.dump();
    if (j.is_null()) shown = key == "season_day" ? "(the world config's)" : "none (no limit)";
    if (key == "engine" && shown.empty()) shown = "(each planner's own)";
    out.push_back({key, j, std::move(shown)});
  });
  return out;
}

/// The first setting (in the list's order) that is compared and differs.
std::optional<ManifestDifference> settingsDifference(
    const ExperimentManifest& a, const ExperimentManifest& b,
    const std::function<bool(std::string_view)>& compared) {
  const std::vector<SettingValue> va = settingValues(a), vb = settingValues(b);
  for (std::size_t i = 0; i < va.size(); ++i)
    if (compared(va[i].key) && va[i].compared != vb[i].compared)
      return ManifestDifference{va[i].key, va[i].shown, vb[i].shown};
  return std::nullopt;
}

}  // namespace

const std::vector<std::string>& errorScaleGroups() {
  static const std::vector<std::string> groups{"pose",         "stereo", "wind",
                                               "segmentation", "light",  "all"};
  return groups;
}

std::pair<int, int> parseShard(const std::string& text) {
  const auto bad = [&text](const std::string& why) {
    return std::invalid_argument("--shard: expected i/n with 0 <= i < n (e.g. 0/4), got '" + text +
                                 "': " + why);
  };
  const auto number = [&](const std::string& part) {
    if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos)
      throw bad("'" + part + "' is not a decimal integer");
    if (part.size() > 1 && part[0] == '0') throw bad("'" + part + "' has a leading zero");
    if (part.size() > 9) throw bad("'" + part + "' is too large");
    return std::stoi(part);
  };
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) throw bad("no '/'");
  const int i = number(text.substr(0, slash)), n = number(text.substr(slash + 1));
  if (n < 1 || i >= n) throw bad("needs 0 <= i < n");
  return {i, n};
}

std::pair<std::string, double> parseErrorScale(const std::string& error_scale) {
  const auto bad = [&](const std::string& why) {
    std::string shown = error_scale.size() > 60 ? error_scale.substr(0, 57) + "..." : error_scale;
    for (char& c : shown)
      if (c < 0x20 || c == 0x7f) c = '?';  // the message is printed: no control bytes
    return std::invalid_argument(
        "--error-scale '" + shown + "': expected GROUP=FACTOR with GROUP one of " +
        joined(errorScaleGroups()) + " and FACTOR a decimal number from 0 to " +
        std::to_string(int(kMaxErrorScaleFactor)) + ", e.g. wind=0.5" +
        (why.empty() ? "" : " (" + why + ")"));
  };
  const std::size_t eq = error_scale.find('=');
  if (eq == std::string::npos) throw bad("no '='");
  const std::string group = error_scale.substr(0, eq), text = error_scale.substr(eq + 1);
  const auto& groups = errorScaleGroups();
  if (std::find(groups.begin(), groups.end(), group) == groups.end()) throw bad("unknown group");
  // Decimal only, as every other number fvp reads: no sign, hex, inf, nan or spaces.
  static const std::regex decimal(R"((0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]{1,3})?)");
  if (!std::regex_match(text, decimal)) throw bad("'" + text + "' is not a decimal number");
  const double factor = std::strtod(text.c_str(), nullptr);
  if (!(factor <= kMaxErrorScaleFactor)) throw bad("the factor is too large");
  return {group, factor};
}

void checkTrial(const nlohmann::json& trial, const std::string& where) {
  if (!trial.is_object())
    throw std::runtime_error(where + ": expected one trial's result (a JSON object), got " +
                             shown(trial));
  const nlohmann::json* planner = member(trial, "planner");
  if (!planner || !isRegistryName(*planner))
    fieldError(where, "planner", kPlannerExpected, planner);
  const nlohmann::json* seed = member(trial, "seed");
  if (!seed || !isUnsigned(*seed)) fieldError(where, "seed", "an unsigned integer", seed);
  if (const nlohmann::json* engine = member(trial, "engine");
      engine && !(isRegistryName(*engine) || *engine == ""))
    fieldError(where, "engine", kEngineExpected, engine);
  if (const nlohmann::json* settings = member(trial, "settings")) {
    const nlohmann::json* engine = settings->is_object() ? member(*settings, "engine") : nullptr;
    if (!engine || !(isRegistryName(*engine) || *engine == ""))
      fieldError(where, "settings.engine", kEngineExpected, engine);
  }
  if (const nlohmann::json* reason = member(trial, "stop_reason"); reason && !isIdentifier(*reason))
    fieldError(where, "stop_reason", "a stop reason (lower-case letters and _)", reason);
  for (const char* key : {"views", "detections"})
    if (const nlohmann::json* v = member(trial, key); v && !isUnsigned(*v))
      fieldError(where, key, "a non-negative integer", v);
  if (const nlohmann::json* v = member(trial, "wall_time_s");
      v && (!isFinite(*v) || v->get<double>() < 0))
    fieldError(where, "wall_time_s", "a finite non-negative number", v);
  if (!member(trial, "fruitlets")) fieldError(where, "fruitlets", "an array of fruitlets", nullptr);
  checkFruitlets(trial, "fruitlets", where);
  checkFruitlets(trial, "fruitlets_paper_sizing", where);
  checkFruitlets(trial, "fruitlets_tag_frame", where);
}

std::string trialRowKey(const nlohmann::json& trial) {
  std::string key = trial.at("planner").get<std::string>();
  // The engine the trial asked for ("" : its planner's own), as its settings say.
  if (const nlohmann::json* settings = member(trial, "settings")) {
    const std::string asked = settings->at("engine").get<std::string>();
    return asked.empty() ? key : key + "-" + asked;
  }
  const nlohmann::json* engine = member(trial, "engine");
  const std::string e = engine ? engine->get<std::string>() : "";
  if (!e.empty() && e != legacyDefaultEngineOf(key)) key += "-" + e;
  return key;
}

std::optional<std::string> readFileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::vector<nlohmann::json> readTrials(const std::filesystem::path& jsonl,
                                       const std::function<void(const std::string&)>& warning) {
  std::vector<nlohmann::json> out;
  const std::optional<std::string> bytes = readFileBytes(jsonl);
  if (!bytes) return out;
  const std::string& text = *bytes;
  std::map<std::pair<std::string, std::uint64_t>, std::size_t> line_of;  // (row, seed) -> line
  std::size_t start = 0, line_no = 0;
  while (start < text.size()) {
    ++line_no;
    const std::size_t end = text.find('\n', start);
    if (end == std::string::npos) {
      if (warning)
        warning(jsonl.string() + ": line " + std::to_string(line_no) +
                " has no newline (a write cut short); ignored, its trial will run again");
      break;
    }
    const std::string_view line(text.data() + start, end - start);
    start = end + 1;
    if (line.empty()) continue;
    const std::string where = jsonl.string() + ": line " + std::to_string(line_no);
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(where + ": expected one trial's result as JSON: " + e.what());
    }
    checkTrial(j, where);
    const auto key = std::make_pair(trialRowKey(j), j.at("seed").get<std::uint64_t>());
    const auto [it, fresh] = line_of.emplace(key, line_no);
    if (!fresh)
      throw std::runtime_error(jsonl.string() + ": lines " + std::to_string(it->second) + " and " +
                               std::to_string(line_no) + " hold the same trial (row " + key.first +
                               ", seed " + std::to_string(key.second) +
                               "); remove one of them (a trial counts once)");
    out.push_back(std::move(j));
  }
  return out;
}

std::string fnv1a64Hex(std::string_view bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  static const char* digits = "0123456789abcdef";
  std::string out(16, '0');
  for (int i = 15; i >= 0; --i, h >>= 4) out[std::size_t(i)] = digits[h & 15];
  return out;
}

nlohmann::ordered_json ExperimentManifest::toJson() const {
  nlohmann::ordered_json j;
  j["format"] = kManifestFormat;
  j["version"] = kFormatVersion;
  j["kind"] = kind;
  visitManifestSettings(settings, [&](const host::nbv::RunField& field, const auto& value) {
    const std::string key(field.key);
    if (field.vocabulary == host::nbv::FieldVocabulary::kConfigFile)
      j[key] = configJson(configs.count(key) ? configs.at(key) : ConfigFileStamp{});
    else
      j[key] = settingJson(value);
  });
  j["error_scale"] = error_scale;
  j["clock_charges"] = clock_charges;
  if (kind == "merged") {
    j["sources"] = sources;
    return j;
  }
  j["planners"] = planners;
  j["trials"] = trials;
  j["first_seed"] = first_seed;
  j["shard"] = {{"index", shard_index}, {"count", shard_count}};
  return j;
}

/// The manifest's error_scale: "" or a GROUP=FACTOR that --error-scale takes (its group is
/// written into a figure's title).
static std::string readErrorScale(const nlohmann::json& j, const std::string& where) {
  const std::string text = readString(j, "error_scale", where);
  try {
    if (!text.empty()) parseErrorScale(text);
  } catch (const std::invalid_argument&) {
    fieldError(where, "error_scale",
               "\"\" or GROUP=FACTOR (GROUP one of " + joined(errorScaleGroups()) +
                   ", FACTOR a decimal number from 0 to " +
                   std::to_string(int(kMaxErrorScaleFactor)) + ")",
               &j.at("error_scale"));
  }
  return text;
}

ExperimentManifest readManifest(const std::filesystem::path& path) {
  const std::string where = path.string();
  const std::optional<std::string> bytes = readFileBytes(path);
  if (!bytes) throw std::runtime_error(where + ": cannot read the experiment manifest");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(*bytes);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(where + ": expected an experiment manifest as JSON: " + e.what());
  }
  if (!j.is_object())
    throw std::runtime_error(where + ": expected an experiment manifest (a JSON object)");
  const nlohmann::json* format = member(j, "format");
  if (!format || *format != kManifestFormat)
    fieldError(where, "format", std::string("\"") + kManifestFormat + "\"", format);
  const std::uint64_t version =
      readUnsigned(j, "version", where, INT_MAX, "a positive integer (the format version)");
  if (version == 0) fieldError(where, "version", "a positive integer", &j["version"]);
  if (version > std::uint64_t(ExperimentManifest::kFormatVersion))
    throw std::runtime_error(where + ": manifest format version " + std::to_string(version) +
                             " is newer than this fvp reads (" +
                             std::to_string(ExperimentManifest::kFormatVersion) +
                             "): use the fvp that made it");
  ExperimentManifest m;
  m.kind = readString(j, "kind", where);
  if (m.kind != "run" && m.kind != "merged")
    fieldError(where, "kind", "\"run\" or \"merged\"", &j["kind"]);
  readManifestSettings(j, where, m.kind == "merged", m);
  if (member(j, "error_scale")) m.error_scale = readErrorScale(j, where);
  m.clock_charges = member(j, "clock_charges") ? readString(j, "clock_charges", where)
                                               : ExperimentManifest::kClockChargesBeforePerception;
  if (m.kind == "merged") {
    const nlohmann::json& sources = required(j, "sources", where, "an array of directories");
    if (!sources.is_array()) fieldError(where, "sources", "an array of directories", &sources);
    for (const auto& s : sources) {
      if (!s.is_string() || !isAbsolutePath(s.get<std::string>()))
        fieldError(where, "sources", "an array of absolute directory paths", &s);
      m.sources.push_back(s.get<std::string>());
    }
    return m;
  }
  const std::string planners_expected =
      "a non-empty array of distinct planner names (lower-case letters, digits and _)";
  const nlohmann::json& planners = required(j, "planners", where, planners_expected);
  if (!planners.is_array() || planners.empty())
    fieldError(where, "planners", planners_expected, &planners);
  for (const auto& p : planners) {
    const std::string name = p.is_string() ? p.get<std::string>() : "";
    if (!isRegistryName(p) ||
        std::find(m.planners.begin(), m.planners.end(), name) != m.planners.end())
      fieldError(where, "planners", planners_expected, &planners);
    m.planners.push_back(name);
  }
  m.trials = int(readUnsigned(j, "trials", where, INT_MAX, "a positive integer"));
  if (m.trials == 0) fieldError(where, "trials", "a positive integer", &j["trials"]);
  m.first_seed = readUnsigned(j, "first_seed", where, UINT64_MAX, "an unsigned integer");
  const std::string shard_expected = "an object {\"index\": i, \"count\": n} with 0 <= i < n";
  const nlohmann::json& shard = required(j, "shard", where, shard_expected);
  const nlohmann::json* index = shard.is_object() ? member(shard, "index") : nullptr;
  const nlohmann::json* count = shard.is_object() ? member(shard, "count") : nullptr;
  if (!index || !count || !isUnsigned(*index) || !isUnsigned(*count) ||
      count->get<std::uint64_t>() > INT_MAX ||
      index->get<std::uint64_t>() >= count->get<std::uint64_t>())
    fieldError(where, "shard", shard_expected, &shard);
  m.shard_index = int(index->get<std::uint64_t>());
  m.shard_count = int(count->get<std::uint64_t>());
  return m;
}

/// The clock's charges as a difference, if they differ.
std::optional<ManifestDifference> clockDifference(const ExperimentManifest& a,
                                                  const ExperimentManifest& b) {
  if (a.clock_charges == b.clock_charges) return std::nullopt;
  return ManifestDifference{"clock_charges", "\"" + a.clock_charges + "\"",
                            "\"" + b.clock_charges + "\""};
}

std::optional<ManifestDifference> mergeDifference(const ExperimentManifest& a,
                                                  const ExperimentManifest& b) {
  if (auto d = settingsDifference(
          a, b, [](std::string_view key) { return key != "engine" && key != "backend"; }))
    return d;
  return clockDifference(a, b);
}

std::optional<ManifestDifference> resumeDifference(const ExperimentManifest& old,
                                                   const ExperimentManifest& now) {
  if (auto d = settingsDifference(old, now, [](std::string_view key) { return key != "backend"; }))
    return d;
  if (auto d = clockDifference(old, now)) return d;
  if (old.planners != now.planners)
    return ManifestDifference{"planners", joined(old.planners), joined(now.planners)};
  if (old.trials != now.trials)
    return ManifestDifference{"trials", std::to_string(old.trials), std::to_string(now.trials)};
  if (old.first_seed != now.first_seed)
    return ManifestDifference{"first_seed", std::to_string(old.first_seed),
                              std::to_string(now.first_seed)};
  if (old.shard_index != now.shard_index || old.shard_count != now.shard_count)
    return ManifestDifference{
        "shard", std::to_string(old.shard_index) + "/" + std::to_string(old.shard_count),
        std::to_string(now.shard_index) + "/" + std::to_string(now.shard_count)};
  return std::nullopt;
}

}  // namespace fvp::trials
