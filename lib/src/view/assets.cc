#include "view/assets.h"

// Each file is placed in .rodata by the assembler's .incbin (the paths come from
// lib/CMakeLists.txt, which also makes this object depend on them), followed by a terminating
// zero that the views below leave out.
#define CAMPROJ_EMBED(name, path)                                       \
  asm(".pushsection .rodata\n"                                          \
      ".balign 16\n"                                                    \
      ".global camproj_asset_" #name "\n"                               \
      "camproj_asset_" #name ":\n"                                      \
      ".incbin \"" path "\"\n"                                          \
      ".global camproj_asset_" #name "_end\n"                           \
      "camproj_asset_" #name "_end:\n"                                  \
      ".byte 0\n"                                                       \
      ".popsection\n");                                                 \
  extern "C" const char camproj_asset_##name[];                         \
  extern "C" const char camproj_asset_##name##_end[];

CAMPROJ_EMBED(three_core, CAMPROJ_THREE_DIR "/build/three.core.js")
CAMPROJ_EMBED(three_module, CAMPROJ_THREE_DIR "/build/three.module.js")
CAMPROJ_EMBED(orbit_controls, CAMPROJ_THREE_DIR "/examples/jsm/controls/OrbitControls.js")
CAMPROJ_EMBED(page_template, CAMPROJ_WEB_DIR "/view.html")
CAMPROJ_EMBED(page_script, CAMPROJ_WEB_DIR "/view.js")

namespace camproj::internal {

namespace {

std::string_view Span(const char* begin, const char* end) {
  return std::string_view(begin, static_cast<size_t>(end - begin));
}

}  // namespace

const ViewAssets& EmbeddedViewAssets() {
  static const ViewAssets assets{
      Span(camproj_asset_three_core, camproj_asset_three_core_end),
      Span(camproj_asset_three_module, camproj_asset_three_module_end),
      Span(camproj_asset_orbit_controls, camproj_asset_orbit_controls_end),
      CAMPROJ_THREE_VERSION,
      Span(camproj_asset_page_template, camproj_asset_page_template_end),
      Span(camproj_asset_page_script, camproj_asset_page_script_end),
  };
  return assets;
}

}  // namespace camproj::internal
