#pragma once
/// The replay page's parts (recording/viewer/), embedded at build time (viewer_assets.cpp.in).
namespace bw::viewer {
extern const char* const kPageTemplate;  ///< viewer.html: {{STYLE}}, {{THREE}}, {{DATA}}, {{SCRIPT}} are filled in
extern const char* const kScript;        ///< viewer.js
extern const char* const kStyle;         ///< viewer.css
}  // namespace bw::viewer
