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
  std::string labels_path;
  double magnify = 0.0;
  std::string pixel_origin = "center";
};

}  // namespace

Command AddOverlayCommand(CLI::App& root) {
  auto args = std::make_shared<OverlayArgs>();
  CLI::App* app = root.add_subcommand(
      "overlay",
      "Draw which click is wrong on IMAGE (PNG or JPEG, at most 8192 x 8192 pixels), or on a\n"
      "blank canvas of the camera's size: each observed pixel as a ring coloured by its residual\n"
      "(viridis, colour-blind safe), its reprojection as a cross, the residual magnified so that\n"
      "the largest is 8 % of the image (the factor is in the legend), the point's id beside it,\n"
      "the fit's outliers (the camera file's fit.outliers) as crossed vermillion rings with how\n"
      "far off they are, observed pixels outside the image as arrows at the border.\n\n"
      "Example:\n"
      "  camproj overlay camera.json points.csv photo.jpg -o check.png --labels labels.csv");
  app->add_option("CAMERA", args->camera_path, "camera file")->required();
  app->add_option("POINTS", args->points_path, "correspondences CSV")->required();
  app->add_option("IMAGE", args->image_path, "image to draw on (optional)");
  app->add_option("-o,--output", args->output_path,
                  "image to write: PNG or JPEG by the extension (.png, .jpg, .jpeg)")->required();
  app->add_option("--magnify", args->magnify,
                  "residual magnification (default: the largest residual drawn 8 % of the image)")
      ->check(PositiveFinite());
  app->add_option("--labels", args->labels_path,
                  "also write where each id was written, as CSV: id,kind,u,v,left,top,width,"
                  "height,residual_px");
  const CLI::Option* pixel_origin =
      app->add_option("--pixel-origin", args->pixel_origin, "convention of the CSV's pixels")
          ->check(CLI::IsMember({"center", "corner"}));
  return {app, [args, pixel_origin]() {
            RequireDistinctOptionOutputs({{"-o", args->output_path}, {"--labels", args->labels_path}});
            RequireOutputIsNotAnInput(args->output_path,
                                      {args->camera_path, args->points_path, args->image_path});
            if (!args->labels_path.empty()) {
              RequireOutputIsNotAnInput(args->labels_path, {args->camera_path, args->points_path,
                                                            args->image_path, args->output_path});
            }
            try {
              ImageFormatOfPath(args->output_path);
            } catch (const std::invalid_argument& e) {
              throw UsageError(std::string("-o: ") + e.what());
            }
            // Read once (ReadCameraFile's 1 MB bound) for the camera and its fit's outliers.
            const std::string camera_text = ReadWholeFile(args->camera_path, size_t{1} << 20);
            const Camera camera = CameraFromJsonText(camera_text, args->camera_path);
            Correspondences points = ReadCorrespondencesFile(args->points_path);
            const PixelOrigin origin = PixelOriginOfOption(
                pixel_origin, args->pixel_origin,
                CameraFilePixelOrigin(camera_text, args->camera_path), args->camera_path,
                args->points_path + "'s pixels are read");
            for (auto& p : points.pixels) p = ConvertPixelOrigin(p, origin, PixelOrigin::kCenter);
            OverlayOptions options;
            options.magnify = args->magnify;
            options.background_path = args->image_path;
            options.outliers = OutlierIndicesFromJsonText(camera_text, args->camera_path);
            options.pixel_origin = origin;
            OverlayPicture picture;
            try {
              picture = DrawOverlayImage(camera, points, options, ImageFormatOfPath(args->output_path));
            } catch (const std::invalid_argument& e) {
              throw InputError(args->camera_path + ": " + e.what());
            }
            const OverlayStats& stats = picture.stats;
            std::vector<OutputFile> outputs = {{args->output_path, picture.encoded, "-o"}};
            if (!args->labels_path.empty()) {
              outputs.push_back({args->labels_path, OverlayLabelsCsv(stats, origin), "--labels"});
            }
            WriteFilesAtomically(outputs);
            std::cout << "wrote " << args->output_path << " (" << stats.drawn << " points";
            if (stats.outliers > 0) std::cout << ", " << stats.outliers << " outliers";
            if (stats.behind > 0) std::cout << ", " << stats.behind << " behind the camera";
            if (stats.no_pixel > 0) {
              std::cout << ", " << stats.no_pixel << " in front with a pixel beyond a double";
            }
            if (stats.outside > 0) std::cout << ", " << stats.outside << " outside the image";
            std::cout << "; residuals x " << stats.magnify << ")\n";
            return kExitOk;
          }};
}

}  // namespace camproj::cli
