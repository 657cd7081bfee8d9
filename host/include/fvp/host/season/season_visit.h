// One visit of a season as fvp's results hold it (docs/season.md): each cluster's sized
// fruitlets in its tag's frame, with their sizes and standard errors, read from a trial's
// result.json (one cluster or a tree) or `fvp size`'s fruitlets.json.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fvp/host/season/fruitlet_association.h"

namespace fvp::host::season {

/// A fruitlet one visit sized: where (tag frame) and how large, the sizing's own standard
/// error (NaN where the result has none) and how many well-seen images it came from (-1
/// where the result does not say).
struct SizedFruitlet {
  VisitFruitlet at;
  double standard_error_mm = std::numeric_limits<double>::quiet_NaN();
  int well_seen_images = -1;
};

/// A cluster on one visit, by its tag's id (0 for a result of one cluster without one).
/// tag_seen false: the visit never saw the tag, so its fruitlets cannot be placed in the
/// tag's frame and are not read (an expected outcome, counted, not an error).
struct VisitCluster {
  int tag_id = 0;
  bool tag_seen = true;
  /// The visit looked at the cluster until its own stop held ("stop_reason" "cluster_done", or
  /// "budget" under the paper's budget rule, or none given): a fruitlet it did not find is
  /// gone. False when the visit was cut short (the budget under the automatic stop, no
  /// reachable view, a view cap, no region): not found there is not evidence of gone.
  bool searched = true;
  /// The tag's pose in the visit's world ("T_world_tag" with "translation_m" and
  /// "quaternion_wxyz", as fvp's results write it); none when the file gives no pose.
  std::optional<Eigen::Isometry3d> T_world_tag;
  std::vector<SizedFruitlet> fruitlets;
};

struct SeasonVisit {
  double day = 0.0;    ///< days from any origin
  std::string source;  ///< the file it was read from
  std::vector<VisitCluster> clusters;
};

/// A visit from the text of a result.json or fruitlets.json; `source` names it in errors.
/// Throws std::runtime_error naming the source, the field and what was expected.
SeasonVisit parseSeasonVisit(const std::string& json_text, const std::string& source, double day);

/// A visit from a file, or from a directory holding result.json or fruitlets.json.
SeasonVisit readSeasonVisit(const std::filesystem::path& path, double day);

}  // namespace fvp::host::season
