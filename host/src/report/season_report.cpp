#include "fvp/host/report/season_report.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "fvp/host/core/atomic_file.h"
#include "fvp/host/core/gnuplot.h"
#include "fvp/host/perception/apriltag_detector.h"
#include "fvp/host/report/viewer_page.h"
#include "fvp/host/report/viewer_scene.h"

namespace fvp::host::report {
namespace {

using season::Fate;
using season::FruitletTrack;
using season::rateIntervalHalfWidth;

/// What a track's fate reads as in the report: gone first (its fate is known).
const char* fateWord(const FruitletTrack& t) {
  if (t.unconfirmed) return "unconfirmed";
  return t.gone ? "gone" : season::toString(t.fate.fate);
}

const char* fateColour(const FruitletTrack& t) {
  if (t.gone) return "#7f7f7f";
  switch (t.fate.fate) {
    case Fate::kPersists:
      return "#2ca02c";
    case Fate::kAbscises:
      return "#d62728";
    case Fate::kUnknown:
      break;
  }
  return "#000000";
}

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string fruitSetText(const season::FruitSet& set) {
  return std::isfinite(set.percent)
             ? fixed(set.percent, 1) + " % +- " + fixed(set.standard_error_percent, 1)
             : std::string("-");
}

}  // namespace

std::string seasonMarkdown(const season::SeasonAnalysis& s, const std::string& figure,
                           const std::vector<std::string>& viewers,
                           const std::string& season_viewer) {
  std::ostringstream md;
  md << "# Season\n\n"
     << s.days.size() << " visits. Reference growth (the fastest fruitlets) "
     << fixed(s.reference_mm_per_day, 3) << " mm/day; a fruitlet growing slower than "
     << fixed(s.threshold_mm_per_day, 3)
     << " mm/day is predicted to drop (docs/season.md). Predicted fruit set of the sample: "
     << fruitSetText(s.fruit_set) << ".\n\n";
  if (!figure.empty()) md << "![size against day, by predicted fate](" << figure << ")\n\n";
  if (!season_viewer.empty())
    md << "[3-D viewer: the fruitlets by predicted fate](" << season_viewer << ")\n\n";
  md << "| visit | day | source | viewer |\n|---|---|---|---|\n";
  for (std::size_t v = 0; v < s.days.size(); ++v) {
    const bool viewer = v < viewers.size() && !viewers[v].empty();
    md << "| " << v + 1 << " | " << s.days[v] << " | `" << s.sources[v] << "` | "
       << (viewer ? "[3-D viewer](" + viewers[v] + ")" : std::string("-")) << " |\n";
  }
  for (const season::ClusterSeason& c : s.clusters) {
    md << "\n## Tag " << c.tag_id << "\n\nPredicted fruit set " << fruitSetText(c.fruit_set)
       << "; visits with the tag seen " << c.visits_with_tag << ", without " << c.visits_without_tag
       << ".\n\n| fruitlet | sizes (day: mm) | growth mm/day (+- 95 %) | fate | "
       << "P(persists) |\n|---|---|---|---|---|\n";
    for (std::size_t k = 0; k < c.tracks.size(); ++k) {
      const FruitletTrack& t = s.tracks[c.tracks[k]];
      md << "| " << k + 1 << " | ";
      for (std::size_t i = 0; i < t.sizes.size(); ++i)
        md << (i ? ", " : "") << t.sizes[i].day << ": " << fixed(t.sizes[i].sized.at.size_mm, 2);
      const double se = t.rate.standard_error_mm_per_day;
      const double half_width_95 =
          std::isfinite(se) ? rateIntervalHalfWidth(0.95, t.rate.degrees_of_freedom) * se : se;
      md << " | " << fixed(t.rate.mm_per_day, 3) << " +- " << fixed(half_width_95, 3) << " | "
         << fateWord(t) << " | " << fixed(t.fate.persist_probability, 2) << " |\n";
    }
  }
  return md.str();
}

std::string seasonFigureScript(const season::SeasonAnalysis& s) {
  const std::size_t panels = std::min<std::size_t>(s.clusters.size(), 8);
  const std::size_t columns = panels <= 1 ? 1 : 2, rows = (panels + columns - 1) / columns;
  std::ostringstream gp;
  gp << "set terminal pngcairo size " << 520 * columns << ","
     << 360 * std::max<std::size_t>(rows, 1) << " font 'DejaVu Sans,10'\nset multiplot layout "
     << std::max<std::size_t>(rows, 1) << "," << columns << " title "
     << gnuplotQuoted("size against day: green persists / red abscises / grey gone / black unknown")
     << "\nset xlabel 'day'\nset ylabel 'size (mm)'\nset grid\nunset key\n";
  for (std::size_t p = 0; p < panels; ++p) {
    const season::ClusterSeason& c = s.clusters[p];
    gp << "set title " << gnuplotQuoted("tag " + std::to_string(c.tag_id)) << "\n";
    std::ostringstream plot;
    for (std::size_t k = 0; k < c.tracks.size(); ++k) {
      const FruitletTrack& t = s.tracks[c.tracks[k]];
      const std::string block = "$c" + std::to_string(p) + "t" + std::to_string(k);
      gp << block << " << EOD\n";
      for (const season::TrackedSize& size : t.sizes)
        gp << size.day << " " << size.sized.at.size_mm << "\n";
      gp << "EOD\n";
      plot << (k ? ", " : "") << block << " using 1:2 with linespoints lw 2 pt 7 lc rgb '"
           << fateColour(t) << "'";
    }
    if (c.tracks.empty()) gp << "$empty << EOD\n0 NaN\nEOD\n", plot << "$empty using 1:2";
    gp << "plot " << plot.str() << "\n";
  }
  gp << "unset multiplot\n";
  return gp.str();
}

nlohmann::json seasonViewerScene(const season::SeasonAnalysis& season) {
  std::ostringstream subtitle;
  subtitle << "days";
  for (std::size_t v = 0; v < season.days.size(); ++v)
    subtitle << (v ? ", " : " ") << season.days[v];
  subtitle << "; predicted fruit set " << fruitSetText(season.fruit_set)
           << "; green persists, red drops, grey gone";
  ViewerScene scene("fvp season: fruitlets by predicted fate", subtitle.str());
  for (std::size_t c = 0; c < season.clusters.size(); ++c) {
    const season::ClusterSeason& cluster = season.clusters[c];
    if (!cluster.T_world_tag) continue;
    const int index = static_cast<int>(c);
    scene.addTag(*cluster.T_world_tag, kDefaultTagSizeM, cluster.tag_id, index);
    for (std::size_t k = 0; k < cluster.tracks.size(); ++k) {
      const FruitletTrack& t = season.tracks[cluster.tracks[k]];
      const season::TrackedSize& last = t.sizes.back();
      // Labelled as season.md numbers them: tag, then the track's place in its cluster.
      std::ostringstream label;
      label << "T" << cluster.tag_id << "." << k + 1;
      scene.addSeasonFruitlet(*cluster.T_world_tag * last.sized.at.center_tag_m,
                              last.sized.at.size_mm, label.str(), fateWord(t), t.rate.mm_per_day,
                              index);
    }
  }
  return scene.toJson();
}

bool writeSeasonReport(const season::SeasonAnalysis& season, const std::filesystem::path& dir,
                       const std::function<void(const std::string&)>& warning) {
  bool drawn = false;
  std::filesystem::remove(dir / "season.png");  // never a stale figure beside new text
  if (!season.clusters.empty()) {
    try {
      plotWithGnuplot(seasonFigureScript(season), dir / "season.png", "season figure");
      drawn = true;
    } catch (const std::exception& e) {
      if (warning) warning(std::string("season.png not drawn: ") + e.what());
    }
  }
  std::vector<std::string> viewers;
  for (const std::string& source : season.sources) {
    const std::filesystem::path viewer =
        std::filesystem::path(source).parent_path() / "viewer.html";
    std::error_code ec;
    const std::filesystem::path link =
        std::filesystem::exists(viewer, ec) ? std::filesystem::relative(viewer, dir, ec) : "";
    viewers.push_back(ec ? std::string() : link.generic_string());
  }
  const bool any_pose = std::any_of(season.clusters.begin(), season.clusters.end(),
                                    [](const auto& c) { return c.T_world_tag.has_value(); });
  std::filesystem::remove(dir / "season_viewer.html");  // never a stale one
  if (any_pose) writeViewerPage(seasonViewerScene(season), dir / "season_viewer.html");
  writeFileAtomically(dir / "season.md", "season report",
                      seasonMarkdown(season, drawn ? "season.png" : "", viewers,
                                     any_pose ? "season_viewer.html" : ""));
  return drawn;
}

}  // namespace fvp::host::report
