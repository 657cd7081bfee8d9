// Checked reads of the JSON fields a season's files hold, each error naming the file, the field
// and what was expected (season_visit.cpp, remembered_visit.cpp).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fvp::host::season {
struct SeasonVisit;
}

namespace fvp::host::season::json_fields {

/// JSON text parsed, or an error naming the source.
inline nlohmann::json parsed(const std::string& json_text, const std::string& source) {
  try {
    return nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(source + ": not JSON: " + e.what());
  }
}

/// parseSeasonVisit on a parsed document, for readers that go on to read more of it
/// (season_visit.cpp).
SeasonVisit seasonVisitOf(const nlohmann::json& root, const std::string& source, double day);

inline constexpr double kMaxPoseDistanceM = 1e4;

[[noreturn]] inline void fail(const std::string& source, const std::string& field,
                              const std::string& expected) {
  throw std::runtime_error(source + ": " + field + ": expected " + expected);
}

inline double finiteNumber(const nlohmann::json& j, const std::string& source,
                           const std::string& field) {
  if (!j.is_number() || !std::isfinite(j.get<double>())) fail(source, field, "a finite number");
  return j.get<double>();
}

inline Eigen::Vector3d vector3(const nlohmann::json& j, const std::string& source,
                               const std::string& field) {
  if (!j.is_array() || j.size() != 3) fail(source, field, "an array of 3 numbers");
  return {finiteNumber(j[0], source, field + "[0]"), finiteNumber(j[1], source, field + "[1]"),
          finiteNumber(j[2], source, field + "[2]")};
}

inline Eigen::Quaterniond quaternionWxyz(const nlohmann::json& j, const std::string& source,
                                         const std::string& field) {
  if (!j.is_array() || j.size() != 4) fail(source, field, "an array of 4 numbers (w, x, y, z)");
  const Eigen::Quaterniond q(
      finiteNumber(j[0], source, field + "[0]"), finiteNumber(j[1], source, field + "[1]"),
      finiteNumber(j[2], source, field + "[2]"), finiteNumber(j[3], source, field + "[3]"));
  if (!(std::abs(q.norm() - 1.0) < 1e-3)) fail(source, field, "a unit quaternion");
  return q.normalized();
}

/// A pose as results write it: {translation_key: [x, y, z], "quaternion_wxyz": [w, x, y, z]}.
inline Eigen::Isometry3d poseOf(const nlohmann::json& j, const char* translation_key,
                                const std::string& source, const std::string& field) {
  if (!j.is_object()) fail(source, field, "an object");
  const auto t = j.find(translation_key);
  if (t == j.end()) fail(source, field + "." + translation_key, "a position in metres");
  const auto q = j.find("quaternion_wxyz");
  if (q == j.end()) fail(source, field + ".quaternion_wxyz", "an orientation");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = quaternionWxyz(*q, source, field + ".quaternion_wxyz").toRotationMatrix();
  pose.translation() = vector3(*t, source, field + "." + translation_key);
  // A robot's poses lie within metres of its base; far beyond, composing them overflows.
  if (!(pose.translation().norm() <= kMaxPoseDistanceM))
    fail(source, field + "." + translation_key, "a position within 10 km");
  return pose;
}

/// A result's cluster's tag id ("tag_id"; 0 when absent: a result of one cluster without one).
inline int tagIdOf(const nlohmann::json& object, const std::string& source,
                   const std::string& field) {
  const auto id = object.find("tag_id");
  if (id == object.end()) return 0;
  if (!id->is_number_integer() || id->get<long long>() < 0 || id->get<long long>() > 1 << 20)
    fail(source, field + "tag_id", "a tag id (an integer >= 0)");
  return id->get<int>();
}

/// A visit's file: `path` itself, or the result.json (else fruitlets.json) in the directory.
inline std::filesystem::path visitFile(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path))
    throw std::runtime_error(path.string() +
                             ": no such file or directory (expected a result.json, a "
                             "fruitlets.json or a directory holding one)");
  if (!std::filesystem::is_directory(path)) return path;
  std::filesystem::path file = path / "result.json";
  if (!std::filesystem::exists(file)) file = path / "fruitlets.json";
  if (!std::filesystem::exists(file))
    throw std::runtime_error(path.string() +
                             ": expected a result.json or fruitlets.json in the directory");
  return file;
}

inline std::string fileText(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace fvp::host::season::json_fields
