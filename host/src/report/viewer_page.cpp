#include "fvp/host/report/viewer_page.h"

#include <stdexcept>
#include <string_view>

#include "fvp/host/core/atomic_file.h"

// Generated from viewer/ and libjs-three by fvp_embed_text (host/CMakeLists.txt).
extern const std::string_view kText_viewer_html;
extern const std::string_view kText_viewer_css;
extern const std::string_view kText_viewer_js;
extern const std::string_view kText_three_js;
extern const std::string_view kText_orbit_controls_js;

namespace fvp::host::report {
namespace {

/// Replaces the first occurrence of `placeholder` by `content` (the template holds each
/// once, on a line of its own; the scene, which may hold any text, goes in last); a
/// template without it is a build defect.
void replaceLine(std::string& page, std::string_view placeholder, const std::string& content) {
  const std::size_t at = page.find(placeholder);
  if (at == std::string::npos)
    throw std::logic_error("viewer.html: placeholder " + std::string(placeholder) + " missing");
  page.replace(at, placeholder.size(), content);
}

/// Inline script text may not hold "</script": "<\/" reads the same in JavaScript strings,
/// regular expressions and JSON.
std::string scriptSafe(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/') {
      out += "<\\/";
      ++i;
    } else {
      out += text[i];
    }
  }
  return out;
}

/// JSON inside a script element: every '<' as \u003c (in JSON it can only stand in a
/// string), so no "</script" or "<!--" in a title or label can end or hide the element.
std::string jsonForScript(const nlohmann::json& value) {
  const std::string text = value.dump();
  std::string out;
  out.reserve(text.size());
  for (const char c : text) out += c == '<' ? std::string("\\u003c") : std::string(1, c);
  return out;
}

}  // namespace

std::string viewerPageHtml(const nlohmann::json& scene) {
  std::string page(kText_viewer_html);
  // The scene last: text in it that looks like a placeholder is never replaced.
  replaceLine(page, "/*FVP_CSS*/", std::string(kText_viewer_css));
  replaceLine(page, "<!--FVP_SCRIPTS-->",
              "<script>" + scriptSafe(kText_three_js) + "</script>\n<script>" +
                  scriptSafe(kText_orbit_controls_js) + "</script>\n<script>" +
                  scriptSafe(kText_viewer_js) + "</script>");
  replaceLine(
      page, "<!--FVP_SCENE-->",
      "<script type=\"application/json\" id=\"fvp-scene\">" + jsonForScript(scene) + "</script>");
  return page;
}

void writeViewerPage(const nlohmann::json& scene, const std::filesystem::path& html_path) {
  writeFileAtomically(html_path, "viewer page", viewerPageHtml(scene));
}

}  // namespace fvp::host::report
