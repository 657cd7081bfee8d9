// An earlier visit's result read as the memory a later visit starts from (docs/season.md,
// "Visits remembered"; host/nbv/visit_memory.h): each cluster's fruitlets in its tag's frame and
// the fewest of its views that showed each fruitlet well.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "fvp/host/nbv/visit_memory.h"

namespace fvp::host::season {

/// What a remembered fruitlet needs from the views chosen for it: the automatic stop's
/// evidence (ClusterCompletionConfig: min_well_seen_images, min_view_span_deg).
struct RememberedViewRule {
  int min_images = 2;
  double min_span_deg = 30.0;
};

/// The views to remember, as indices into camera_positions: a greedy cover that adds, each
/// time, the view that moves the most fruitlets towards rule.min_images well-seen images from
/// directions rule.min_span_deg apart (seen from the fruitlet), until every fruitlet has them
/// or no view adds any. seen_well[f] lists the views that showed fruitlet f well. In the order
/// chosen; ties go to the earlier view.
std::vector<std::size_t> chooseRememberedViews(
    const std::vector<Eigen::Vector3d>& camera_positions,
    const std::vector<Eigen::Vector3d>& fruitlet_centers,
    const std::vector<std::vector<std::size_t>>& seen_well, const RememberedViewRule& rule = {});

/// Each cluster's memory by its tag id, from the text of a result.json (a tree's or one
/// cluster's) or a fruitlets.json (fruitlets only: it holds no views). A cluster whose tag the
/// visit never saw is left out. `source` names the file in errors; throws std::runtime_error
/// naming the field and what was expected.
std::map<int, nbv::ClusterMemory> parseVisitMemory(const std::string& json_text,
                                                   const std::string& source,
                                                   const RememberedViewRule& rule = {});

/// The same from a file, or a directory holding result.json or fruitlets.json.
std::map<int, nbv::ClusterMemory> readVisitMemory(const std::filesystem::path& path,
                                                  const RememberedViewRule& rule = {});

}  // namespace fvp::host::season
