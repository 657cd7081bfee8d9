#include "fvp/trials/sensitivity_report.h"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/gnuplot.h"
#include "fvp/host/core/output_directory.h"
#include "fvp/host/planner/planner_registry.h"
#include "fvp/trials/experiment.h"
#include "fvp/trials/experiment_directory.h"
#include "number_text.h"

namespace fvp::trials {
namespace fs = std::filesystem;
namespace {

std::string seriesName(const SensitivityPoint& p) {
  const auto& planners = host::planner::PlannerRegistry::instance();
  std::string name = planners.contains(p.planner) ? planners.at(p.planner).label : p.planner;
  return name + (p.registered ? " + registration" : "");
}

/// One column of panels per error group (MAE above, MP below), a line per planner and
/// registration setting in each.
std::string figureScript(const std::vector<SensitivityPoint>& points) {
  std::map<std::string, std::map<std::string, std::vector<const SensitivityPoint*>>> groups;
  for (const auto& p : points)
    if (p.planner.find("-paper-sizing") == std::string::npos)
      groups[p.group][seriesName(p)].push_back(&p);
  std::ostringstream gp;
  const std::size_t columns = std::max<std::size_t>(groups.size(), 1);
  gp << "set terminal pngcairo size " << 120 + 330 * columns << ",640 font 'DejaVu Sans,10'\n"
     << "set multiplot layout 2," << columns
     << " title 'Sizing against the magnitude of each simulated error (1 = the world config)'\n"
     << "set grid\nset offsets graph 0, 0, 0.05, 0.05\nset key top left font ',8'\n";
  double max_factor = 1.0;  // one x range for every panel, so that the groups compare
  for (const auto& p : points) max_factor = std::max(max_factor, p.factor);
  gp << "set xrange [" << -0.05 * max_factor << ":" << 1.05 * max_factor << "]\n";
  int k = 0;
  std::map<std::string, std::vector<int>> blocks;  // group -> data block per series
  for (const auto& [group, series] : groups)
    for (const auto& [name, ps] : series) {
      gp << "$s" << k << " << EOD\n";
      for (const auto* p : ps)
        gp << p->factor << " " << p->mae_mm << " " << p->match_percent << "\n";
      gp << "EOD\n";
      blocks[group].push_back(k++);
    }
  for (const auto& [column, label] : {std::pair{2, "MAE (mm)"}, std::pair{3, "MP (%)"}})
    for (const auto& [group, series] : groups) {
      gp << "set title " << host::gnuplotQuoted(group) << "\nset ylabel "
         << host::gnuplotQuoted(label) << "\nset xlabel 'x the world config'\nplot ";
      int i = 0;
      for (const auto& [name, ps] : series) {
        gp << (i ? ", " : "") << "$s" << blocks[group][std::size_t(i)] << " using 1:" << column
           << " with linespoints lw 2 title " << host::gnuplotQuoted(name);
        ++i;
      }
      gp << "\n";
    }
  gp << "unset multiplot\n";
  return gp.str();
}

}  // namespace

std::vector<SensitivityPoint> readSensitivityPoints(const std::vector<fs::path>& experiments) {
  std::vector<SensitivityPoint> points;
  for (const fs::path& dir : experiments) {
    const ExperimentManifest m = readManifest(dir / "manifest.json");
    if (m.error_scale.empty())
      throw std::runtime_error(dir.string() +
                               ": its manifest has no error scale (make each sweep point with "
                               "fvp experiment --error-scale GROUP=FACTOR)");
    const std::vector<nlohmann::json> trials = readTrials(dir / "trials.jsonl", nullptr);
    if (trials.empty()) throw std::runtime_error(dir.string() + ": no trials in trials.jsonl");
    const auto [group, factor] = parseErrorScale(m.error_scale);
    const nlohmann::json summary = summarize(trials);
    for (const auto& [planner, row] : summary.items()) {
      SensitivityPoint p;
      p.group = group;
      p.factor = factor;
      p.registered = m.settings.register_views.value_or(false);
      p.planner = planner;
      p.trials = row.value("trials", 0);
      p.match_percent = row.value("match_percent", 0.0);
      p.mae_mm = row.value("mae_mm", 0.0);
      p.precision_percent = row.value("precision_percent", 0.0);
      p.experiment = dir.string();
      points.push_back(p);
    }
  }
  // Factor 1 of any group is the world config itself: one such experiment stands for
  // factor 1 of every group in the sweep that has no factor-1 point of its own.
  std::set<std::string> groups;
  for (const auto& p : points) groups.insert(p.group);
  const std::vector<SensitivityPoint> measured = points;
  for (const auto& unscaled : measured) {
    if (unscaled.factor != 1.0) continue;
    for (const auto& group : groups) {
      // points holds every measured point and those added so far.
      if (std::any_of(points.begin(), points.end(), [&](const auto& q) {
            return q.group == group && q.factor == 1.0 && q.planner == unscaled.planner &&
                   q.registered == unscaled.registered;
          }))
        continue;
      SensitivityPoint shared = unscaled;
      shared.group = group;
      points.push_back(shared);
    }
  }
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) {
    return std::tie(a.group, a.planner, a.registered, a.factor) <
           std::tie(b.group, b.planner, b.registered, b.factor);
  });
  return points;
}

bool writeSensitivityReport(const std::vector<fs::path>& experiments, const fs::path& out_dir,
                            const std::function<void(const std::string&)>& warning) {
  const std::vector<SensitivityPoint> points = readSensitivityPoints(experiments);
  host::prepareOutputDirectory(out_dir, "sensitivity: --out");
  const host::OutputDirectoryLock lock(out_dir, "sensitivity: --out");
  nlohmann::json json = nlohmann::json::array();
  std::ostringstream md;
  md << "# Sensitivity to the simulated errors\n\n"
     << "Each row is one experiment (`fvp experiment --error-scale GROUP=FACTOR`): the world "
        "config's errors of that group times the factor.\n\n"
     << "| group | factor | planner | registration | trials | MP (%) | MAE (mm) | precision (%) "
        "| experiment |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& p : points) {
    json.push_back({{"group", p.group},
                    {"factor", p.factor},
                    {"planner", p.planner},
                    {"register_views", p.registered},
                    {"trials", p.trials},
                    {"match_percent", p.match_percent},
                    {"mae_mm", p.mae_mm},
                    {"precision_percent", p.precision_percent},
                    {"experiment", p.experiment}});
    md << "| " << p.group << " | " << fmt(p.factor, 2) << " | " << p.planner << " | "
       << (p.registered ? "yes" : "no") << " | " << p.trials << " | " << fmt(p.match_percent, 1)
       << " | " << fmt(p.mae_mm, 2) << " | " << fmt(p.precision_percent, 1) << " | " << p.experiment
       << " |\n";
  }
  host::writeFileAtomically(out_dir / "sensitivity.json", "sensitivity report",
                            json.dump(2) + "\n");
  host::writeFileAtomically(out_dir / "sensitivity.md", "sensitivity report", md.str());
  try {
    host::plotWithGnuplot(figureScript(points), out_dir / "sensitivity.png", "sensitivity.png");
    return true;
  } catch (const std::exception& e) {
    if (warning) warning(std::string("sensitivity.png not drawn: ") + e.what());
    return false;
  }
}

}  // namespace fvp::trials
