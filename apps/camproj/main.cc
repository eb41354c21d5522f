// camproj: the command line. Each subcommand parses, reads, calls one library function and
// prints or writes; exit codes: 0 ok, 1 usage, 2 bad input, 3 the scene cannot determine the
// requested camera.
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "camproj/camera_file.h"
#include "camproj/errors.h"
#include "camproj/export.h"

namespace {

constexpr int kExitUsage = 1;
constexpr int kExitBadInput = 2;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "camproj: make an OpenGL camera see exactly what a real camera or projector sees.\n"
      "Conventions: docs/conventions.md. Exit codes: 0 ok, 1 usage, 2 bad input, 3 the scene\n"
      "cannot determine the requested camera."};
  app.require_subcommand(1);

  std::string camera_path;
  std::string to = "gl";
  std::string depth = "no";
  bool reversed_z = false;
  bool row_major = false;
  CLI::App* export_cmd = app.add_subcommand(
      "export", "Print a camera's GL projection and view matrices.\n"
                "Example: camproj export data/projector/camera.json --to gl --depth zo");
  export_cmd->add_option("CAMERA", camera_path, "camera file (JSON, docs/camera-file.md)")
      ->required();
  export_cmd->add_option("--to", to, "output format")->check(CLI::IsMember({"gl"}));
  export_cmd->add_option("--depth", depth, "clip depth: no = [-1,1] (GL default), zo = [0,1]")
      ->check(CLI::IsMember({"no", "zo"}));
  export_cmd->add_flag("--reversed-z", reversed_z, "near maps to 1, far to 0 (or -1 for no)");
  export_cmd->add_flag("--row-major", row_major, "print rows instead of GL's column-major order");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitUsage;
  }

  try {
    if (*export_cmd) {
      const camproj::Camera camera = camproj::ReadCameraFile(camera_path);
      camproj::GlExportOptions options;
      options.depth.clip_depth = camproj::ClipDepthFromString(depth);
      options.depth.reversed_z = reversed_z;
      options.row_major = row_major;
      std::cout << camproj::ExportGl(camera, options);
    }
  } catch (const camproj::InputError& e) {
    std::cerr << "camproj: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::cerr << "camproj: error: " << e.what() << '\n';
    return kExitBadInput;
  }
  return 0;
}
