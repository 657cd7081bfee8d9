#include "experiment_index.h"

#include <cctype>
#include <iomanip>
#include <sstream>

#include "fvp/host/core/atomic_file.h"
#include "fvp/trials/experiment_directory.h"
#include "number_text.h"

namespace fvp::trials {
namespace {

namespace fs = std::filesystem;

std::string escapeHtml(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// A path as an href: relative, '/'-separated, with the characters a URL may not hold
/// percent-encoded.
std::string href(const fs::path& relative) {
  std::ostringstream out;
  for (const unsigned char c : relative.generic_string()) {
    if (std::isalnum(c) || c == '/' || c == '.' || c == '-' || c == '_' || c == '~')
      out << c;
    else
      out << '%' << std::uppercase << std::hex << std::setw(2) << std::setfill('0') << int(c)
          << std::dec;
  }
  return out.str();
}

/// The markdown table's lines ("| a | b |", the "|---|" rule skipped) as HTML rows, the
/// first as the header; the text around the table as paragraphs.
std::string tableHtml(const std::string& markdown) {
  std::ostringstream html, paragraph;
  std::istringstream lines(markdown);
  bool in_table = false, header = true;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("# ", 0) == 0) continue;  // the page has its own heading
    if (line.rfind("## ", 0) == 0) {         // a later table's heading
      if (in_table) html << "</table>\n", in_table = false;
      html << "<h2>" << escapeHtml(line.substr(3)) << "</h2>\n";
      continue;
    }
    if (line.rfind("|", 0) != 0) {
      if (in_table) html << "</table>\n", in_table = false;
      if (!line.empty()) html << "<p>" << escapeHtml(line) << "</p>\n";
      continue;
    }
    if (line.rfind("|---", 0) == 0) continue;
    if (!in_table) html << "<table>\n", in_table = true, header = true;
    html << "<tr>";
    std::istringstream cells(line.substr(1));
    for (std::string cell; std::getline(cells, cell, '|');) {
      const auto first = cell.find_first_not_of(' '), last = cell.find_last_not_of(' ');
      const std::string text =
          first == std::string::npos ? "" : cell.substr(first, last - first + 1);
      html << (header ? "<th>" : "<td>") << escapeHtml(text) << (header ? "</th>" : "</td>");
    }
    html << "</tr>\n";
    header = false;
  }
  if (in_table) html << "</table>\n";
  return html.str();
}

/// The directory's name, also when given as "runs/exp/" or ".".
std::string experimentName(const fs::path& dir) {
  const fs::path normal = fs::absolute(dir).lexically_normal();
  const std::string name = normal.filename().string();
  return name.empty() ? normal.parent_path().filename().string() : name;
}

}  // namespace

void writeIndexPage(const fs::path& dir, const std::string& table_markdown,
                    const std::vector<nlohmann::json>& trials, const TrialDirFn& trial_dir) {
  std::ostringstream html;
  html << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
       << "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; "
          "style-src 'unsafe-inline'; img-src 'self' file:\">\n"
       << "<title>fvp experiment</title>\n<style>\n"
       << "body{font:14px/1.4 sans-serif;margin:24px;max-width:1200px;color:#222}\n"
       << "table{border-collapse:collapse;margin:8px 0 16px}\n"
       << "td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}\n"
       << "th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}\n"
       << "img{max-width:100%;border:1px solid #ddd}\n</style></head><body>\n"
       << "<h1>Experiment: " << escapeHtml(experimentName(dir)) << "</h1>\n"
       << "<h2>Table 1: sizing accuracy</h2>\n"
       << tableHtml(table_markdown);
  for (const auto& [file, caption] :
       {std::pair{"sizes.png", "Figure 7: sizes of ground truth and of each planner's estimates"},
        std::pair{"accuracy_vs_time.png", "Accuracy against the time spent on a cluster"},
        std::pair{"time_split.png", "Where the simulated time went"}})
    if (fs::exists(dir / file))
      html << "<h2>" << caption << "</h2>\n<p><img src=\"" << file << "\" alt=\"" << caption
           << "\"></p>\n";
  html << "<h2>Trials</h2>\n<p>Each trial's 3-D viewer (viewer.html) and report (report.md).</p>\n"
       << "<table>\n<tr><th>row</th><th>seed</th><th>views</th><th>simulated s</th><th>stop</th>"
          "<th>MP (%)</th><th>MAE (mm)</th><th>precision (%)</th><th>viewer</th><th>report</th>"
          "</tr>\n";
  for (const auto& t : trials) {
    const fs::path trial = trial_dir(t);
    const auto link = [&](const char* file) {
      if (!fs::exists(trial / file)) return std::string("-");
      return "<a href=\"" + href(fs::relative(trial / file, dir)) + "\">" + file + "</a>";
    };
    const nlohmann::json& m = t.contains("metrics") ? t["metrics"] : nlohmann::json::object();
    html << "<tr><td>" << escapeHtml(trialRowKey(t)) << "</td><td>" << t.at("seed") << "</td><td>"
         << t.value("views", 0) << "</td><td>" << fmtOrDash(t.value("sim_time_s", 0.0), 1)
         << "</td><td>" << escapeHtml(t.value("stop_reason", "-")) << "</td><td>"
         << fmtOrDash(m.value("match_percent", nlohmann::json()), 1) << "</td><td>"
         << fmtOrDash(m.value("mae_mm", nlohmann::json()), 2) << "</td><td>"
         << fmtOrDash(m.value("precision_percent", nlohmann::json()), 1) << "</td><td>"
         << link("viewer.html") << "</td><td>" << link("report.md") << "</td></tr>\n";
  }
  html << "</table>\n</body></html>\n";
  host::writeFileAtomically(dir / "index.html", "experiment index", html.str());
}

}  // namespace fvp::trials
