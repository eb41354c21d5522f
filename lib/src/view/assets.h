// The files `camproj view` builds its page from, embedded in the library at build time
// (lib/CMakeLists.txt): three.js as web/package-lock.json pins it (npm ci into web/node_modules by
// scripts/install-deps.sh) and the page's own template and script (web/view.html, web/view.js).
#ifndef CAMPROJ_SRC_VIEW_ASSETS_H_
#define CAMPROJ_SRC_VIEW_ASSETS_H_

#include <string_view>

namespace camproj::internal {

struct ViewAssets {
  std::string_view three_core;       // three/build/three.core.js (ES module)
  std::string_view three_module;     // three/build/three.module.js, imports './three.core.js'
  std::string_view orbit_controls;   // three/examples/jsm/controls/OrbitControls.js, imports 'three'
  std::string_view three_version;    // three/package.json's "version"
  std::string_view page_template;    // web/view.html
  std::string_view page_script;      // web/view.js (ES module, imports 'three' and the controls)
};

const ViewAssets& EmbeddedViewAssets();

}  // namespace camproj::internal

#endif  // CAMPROJ_SRC_VIEW_ASSETS_H_
