// camproj overlay: observed points, reprojections and residuals drawn on the image.
#include <iostream>
#include <memory>

#include "camproj/camera_file.h"
#include "camproj/errors.h"
#include "camproj/file_io.h"
#include "camproj/image_header.h"
#include "camproj/overlay.h"
#include "camproj/points_file.h"
#include "cli.h"

namespace camproj::cli {

namespace {

struct OverlayArgs {
  std::string camera_path;
  std::string points_path;
  std::string image_path;
  std::string output_path;
  double magnify = 10.0;
  std::string pixel_origin = "center";
};

}  // namespace

Command AddOverlayCommand(CLI::App& root) {
  auto args = std::make_shared<OverlayArgs>();
  CLI::App* app = root.add_subcommand(
      "overlay",
      "Draw observed points (circles), reprojected points (crosses) and the residual vectors\n"
      "(magnified, stated in the legend) on IMAGE (PNG or JPEG, at most 8192 x 8192 pixels), or\n"
      "on a blank canvas of the camera's size.\n\n"
      "Example:\n"
      "  camproj overlay camera.json points.csv photo.jpg -o check.png --magnify 20");
  app->add_option("CAMERA", args->camera_path, "camera file")->required();
  app->add_option("POINTS", args->points_path, "correspondences CSV")->required();
  app->add_option("IMAGE", args->image_path, "image to draw on (optional)");
  app->add_option("-o,--output", args->output_path,
                  "image to write: PNG or JPEG by the extension (.png, .jpg, .jpeg)")->required();
  app->add_option("--magnify", args->magnify, "residual magnification")->check(CLI::PositiveNumber);
  app->add_option("--pixel-origin", args->pixel_origin, "convention of the CSV's pixels")
      ->check(CLI::IsMember({"center", "corner"}));
  return {app, [args]() {
            RequireOutputIsNotAnInput(args->output_path,
                                      {args->camera_path, args->points_path, args->image_path});
            try {
              ImageFormatOfPath(args->output_path);
            } catch (const std::invalid_argument& e) {
              throw UsageError(std::string("-o: ") + e.what());
            }
            const Camera camera = ReadCameraFile(args->camera_path);
            Correspondences points = ReadCorrespondencesFile(args->points_path);
            const PixelOrigin origin = PixelOriginFromString(args->pixel_origin);
            for (auto& p : points.pixels) p = ConvertPixelOrigin(p, origin, PixelOrigin::kCenter);
            OverlayOptions options;
            options.magnify = args->magnify;
            options.background_path = args->image_path;
            OverlayStats stats;
            try {
              stats = WriteOverlayImage(camera, points, options, args->output_path);
            } catch (const std::invalid_argument& e) {
              throw InputError(args->camera_path + ": " + e.what());
            }
            std::cout << "wrote " << args->output_path << " (" << stats.drawn << " points";
            if (stats.behind > 0) std::cout << ", " << stats.behind << " behind the camera";
            std::cout << ")\n";
            return kExitOk;
          }};
}

}  // namespace camproj::cli
