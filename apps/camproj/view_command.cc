// camproj view: a self-contained HTML page to look at a camera and its points (camproj/view.h).
#include <filesystem>
#include <iostream>
#include <memory>

#include "camproj/camera_file.h"
#include "camproj/file_io.h"
#include "camproj/points_file.h"
#include "camproj/view.h"
#include "cli.h"

namespace camproj::cli {

namespace {

struct ViewArgs {
  std::string camera_path;
  std::string points_path;
  std::string image_path;
  std::string mesh_path;
  std::string output_path;
  std::string title;
  std::string pixel_origin = "center";
};

}  // namespace

Command AddViewCommand(CLI::App& root) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* app = root.add_subcommand(
      "view",
      "Write one self-contained HTML page (three.js inlined: it opens from disk, fetches\n"
      "nothing) showing the camera in 3D: the points, the frustum with the image plane (and the\n"
      "photo on it), rays from the eye through each observed pixel, residuals coloured by size,\n"
      "the fit's outliers; orbit controls; a button to look through the camera, rendered with the\n"
      "camera `camproj export --to three` writes (the points must land on the observed pixels);\n"
      "the fit report beside it.\n\n"
      "Example:\n"
      "  camproj fit points.csv --image-size 1920x1080 -o camera.json\n"
      "  camproj view camera.json points.csv --image photo.jpg --mesh building.obj -o view.html");
  app->add_option("CAMERA", args->camera_path, "camera file")->required();
  app->add_option("POINTS", args->points_path, "correspondences CSV (optional)");
  app->add_option("--image", args->image_path,
                  "photo of the camera's image size (PNG or JPEG), on the image plane and behind "
                  "the view through the camera");
  app->add_option("--mesh", args->mesh_path, "Wavefront OBJ model in world units");
  app->add_option("--title", args->title, "page title");
  app->add_option("-o,--output", args->output_path, "the page to write (.html)")->required();
  const CLI::Option* pixel_origin =
      app->add_option("--pixel-origin", args->pixel_origin, "convention of the CSV's pixels")
          ->check(CLI::IsMember({"center", "corner"}));
  return {app, [args, pixel_origin]() {
            const std::string extension =
                std::filesystem::path(args->output_path).extension().string();
            if (extension != ".html" && extension != ".htm") {
              throw UsageError("-o: the page must end in .html or .htm, got \"" +
                               args->output_path + "\"");
            }
            RequireOutputIsNotAnInput(args->output_path, {args->camera_path, args->points_path,
                                                          args->image_path, args->mesh_path});
            // The camera file as ReadCameraFile reads it (its 1 MB bound), kept for its `fit` record.
            const std::string camera_text = ReadWholeFile(args->camera_path, size_t{1} << 20);
            const Camera camera = CameraFromJsonText(camera_text, args->camera_path);
            std::optional<Correspondences> points;
            if (!args->points_path.empty()) {
              points = ReadCorrespondencesFile(args->points_path);
              const PixelOrigin origin = PixelOriginOfOption(
                  pixel_origin, args->pixel_origin,
                  CameraFilePixelOrigin(camera_text, args->camera_path), args->camera_path,
                  args->points_path + "'s pixels are read");
              for (auto& p : points->pixels) p = ConvertPixelOrigin(p, origin, PixelOrigin::kCenter);
            }
            ViewOptions options;
            options.image_path = args->image_path;
            options.mesh_path = args->mesh_path;
            options.title = args->title;
            const ViewStats stats =
                WriteViewPage(camera, camera_text, args->camera_path, points ? &*points : nullptr,
                              options, args->output_path);
            std::cout << "wrote " << args->output_path << " (" << stats.points << " points";
            if (stats.outliers > 0) std::cout << ", " << stats.outliers << " outliers";
            if (stats.behind > 0) std::cout << ", " << stats.behind << " behind the camera";
            if (stats.no_pixel > 0) {
              std::cout << ", " << stats.no_pixel << " in front with a pixel beyond a double";
            }
            if (stats.outside_image > 0) {
              std::cout << ", " << stats.outside_image << " outside the image";
            }
            if (stats.mesh_triangles > 0) std::cout << ", " << stats.mesh_triangles << " triangles";
            std::cout << ", " << (stats.page_bytes + 512 * 1024) / (1024 * 1024) << " MB)\n";
            return kExitOk;
          }};
}

}  // namespace camproj::cli
