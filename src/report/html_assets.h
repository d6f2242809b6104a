// The HTML report's page template and viewer script, compiled in from web/ at build time
// (src/report/CMakeLists.txt generates their definitions with cmake/embed_file.cmake).
#pragma once

#include <string_view>

namespace vertexflow::html_assets {

/// web/src/report.html: the page, with the markers @VF_TITLE@, @VF_DATA@ and @VF_SCRIPT@.
std::string_view page_template();

/// web/src/report.js bundled with three.js by esbuild (one minified IIFE, ASCII).
std::string_view viewer_script();

}  // namespace vertexflow::html_assets
