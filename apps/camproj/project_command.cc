// camproj project: world points -> pixels (and depth) through a camera file.
#include <iostream>
#include <memory>

#include "camproj/camera_file.h"
#include "camproj/file_io.h"
#include "camproj/number_text.h"
#include "camproj/points_file.h"
#include "camproj/terminal_text.h"
#include "cli.h"

namespace camproj::cli {

namespace {

struct ProjectArgs {
  std::string camera_path;
  std::string view;  // a calibration file's view, by name
  std::string points_path;
  std::string pixel_origin = "center";
};

}  // namespace

Command AddProjectCommand(CLI::App& root) {
  auto args = std::make_shared<ProjectArgs>();
  CLI::App* app = root.add_subcommand(
      "project",
      "Project world points through a camera: prints id,X,Y,Z,u,v,depth as CSV (depth = z in the\n"
      "camera frame, world units; u, v empty for points behind the camera (or whose pixel is beyond a double); control characters in ids\n"
      "printed escaped, as \\x1b). POINTS.csv needs\n"
      "X,Y,Z; u,v columns are ignored.\n\n"
      "Example:\n"
      "  camproj project camera.json points.csv\n"
      "  camproj project calib.json --view left03 left03.csv   # one view of a calibration");
  app->add_option("CAMERA", args->camera_path, "camera file")->required();
  app->add_option("--view", args->view,
                  "CAMERA is a calibration file (camproj calibrate): project through this view's "
                  "camera");
  app->add_option("POINTS", args->points_path, "CSV with X,Y,Z")->required();
  const CLI::Option* pixel_origin =
      app->add_option("--pixel-origin", args->pixel_origin, "convention of the printed pixels")
          ->check(CLI::IsMember({"center", "corner"}));
  return {app, [args, pixel_origin]() {
            // Read once for the camera and its pixel convention, under the readers' bounds:
            // ReadCameraFile's 1 MB, ReadCalibrationView's 16 MB (hundreds of views).
            const std::string camera_text = ReadWholeFile(
                args->camera_path, args->view.empty() ? size_t{1} << 20 : size_t{16} << 20);
            const Camera camera =
                args->view.empty()
                    ? CameraFromJsonText(camera_text, args->camera_path)
                    : CalibrationViewFromJsonText(camera_text, args->camera_path, args->view);
            CorrespondencesLimits limits;
            limits.read_pixels = false;
            const Correspondences points = ReadCorrespondencesFile(args->points_path, limits);
            const PixelOrigin origin = PixelOriginOfOption(
                pixel_origin, args->pixel_origin,
                CameraFilePixelOrigin(camera_text, args->camera_path, args->view),
                args->camera_path, "the pixels are printed");
            std::cout << "id,X,Y,Z,u,v,depth\n";
            for (size_t i = 0; i < points.points_in_world.size(); ++i) {
              const Eigen::Vector3d& x = points.points_in_world[i];
              const double depth = (camera.cam_from_world * x).z();
              const std::optional<Eigen::Vector2d> pixel = PixelFromWorld(camera, x);
              std::cout << TerminalSafe(points.ids[i]) << ',' << ShortestDouble(x.x()) << ',' << ShortestDouble(x.y()) << ','
                        << ShortestDouble(x.z()) << ',';
              if (pixel) {
                const Eigen::Vector2d p = ConvertPixelOrigin(*pixel, PixelOrigin::kCenter, origin);
                std::cout << ShortestDouble(p.x()) << ',' << ShortestDouble(p.y());
              } else {
                std::cout << ',';
              }
              std::cout << ',' << ShortestDouble(depth) << '\n';
            }
            return kExitOk;
          }};
}

}  // namespace camproj::cli
