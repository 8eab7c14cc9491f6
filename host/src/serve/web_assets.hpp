// The page's files (web/), compiled into the binary so that `pathstream serve` works offline
// and from wherever it is installed (the build generates web_assets.cpp from web/).
#pragma once

#include <cstddef>
#include <string>

namespace pathstream::host::serve {

/// One file of the page.
struct WebAsset {
    const char* path;          ///< URL path: "/", "/app.js", ...
    const char* content_type;  ///< "text/html; charset=utf-8", ...
    const unsigned char* data;
    std::size_t size;
};

/// The asset served at `path`, or null. Static data; any thread.
const WebAsset* find_web_asset(const std::string& path);

}  // namespace pathstream::host::serve
